#pragma once
// The heap settings of both executables (grip and grip-server), set first thing in main.
#include <malloc.h>

namespace grip {

// glibc's default 128 KiB thresholds hand each compliance's and factor's buffers back to the
// kernel when freed and fault them in again at the next real solve (on the paper's beam most
// of the CPU time went to brk and page faults). Freed heap up to 256 MiB stays with the process.
inline void tune_heap() {
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

}  // namespace grip
