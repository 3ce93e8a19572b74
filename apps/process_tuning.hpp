#pragma once
// The process settings of both executables (grip and grip-server), set first thing in main.
#include <malloc.h>
#include <omp.h>
#include <sys/mman.h>
#include <unistd.h>

#include <climits>
#include <cstdint>
#include <cstdlib>

namespace grip {

// glibc's default 128 KiB thresholds hand each compliance's and factor's buffers back to the
// kernel when freed and fault them in again at the next real solve (on the paper's beam most
// of the CPU time went to brk and page faults). Freed heap up to 256 MiB stays with the process.
//
// CHOLMOD (Debian's libcholmod3) runs parts of its supernodal factorization in OpenMP teams of
// CHOLMOD_OMP_NUM_THREADS = 4, fixed when it was compiled: OMP_NUM_THREADS does not change it.
// On 2 cores that is 3 threads more than the cores, 5,200 context switches and 26,000 futex
// calls per refined Hertz run, competing with grip solve's writer thread and the service's
// workers. Allowing no active parallel level runs each team on its calling thread (the loops
// are per column: the same numbers), and the solver starts no threads (docs/design.md#principles).
inline void tune_process() {
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  omp_set_max_active_levels(0);
}

// grip solve: the main heap on transparent huge pages, as GLIBC_TUNABLES=glibc.malloc.hugetlb=1
// does (a tunable a process cannot set for itself). Each 4 KiB page of heap costs a page fault
// on its first touch (about 10 us on this kind of virtual machine): a refined Hertz run
// touches 90 MB, 23,500 faults and 0.2-0.3 s of system time; with 2 MiB pages, 650-870, and
// the exit unmaps 512 times fewer pages. The heap grows once by kHeapReserve of address space
// (no memory: pages are given when first touched), marked for huge pages; it is never trimmed
// (the process ends after its solve), so the marked range stays mapped. Beyond it the heap
// grows as glibc's default does, in 4 KiB pages; if the address space cannot be had (a
// ulimit), nothing changes. For the service (solving on worker threads, which glibc serves
// from arenas of their own) the tunable is the way.
//
// One arena: every thread of grip solve allocates from this heap. An arena of a thread's own
// grows 4 KiB at a time, an mprotect and a page fault each: the schema validator's build took
// 100 of them; a --threads helper (apps/thread_team.hpp) took 4,700-5,000 minor faults more
// than one thread on the refined two cylinders, with one arena 540-840. Their allocations are
// coarse (factors, vectors, texts), so the shared arena's lock is rarely contended.
inline void heap_on_huge_pages() {
  constexpr size_t kHeapReserve = size_t{1} << 30;
  mallopt(M_ARENA_MAX, 1);
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
  mallopt(M_TOP_PAD, kHeapReserve);
  const auto from = (reinterpret_cast<uintptr_t>(sbrk(0)) + 4095) & ~uintptr_t{4095};
  void* volatile grow = malloc(mallinfo2().fordblks + 1);  // more than the heap has free: it grows now
  free(grow);                     // (volatile: the compiler would drop a malloc that is freed unused)
  mallopt(M_TOP_PAD, 128 << 10);  // glibc's default again: later growth asks for what it needs
  const auto to = reinterpret_cast<uintptr_t>(sbrk(0));
  if (grow && to > from) madvise(reinterpret_cast<void*>(from), to - from, MADV_HUGEPAGE);
}

}  // namespace grip
