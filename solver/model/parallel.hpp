#pragma once
// How the solver runs independent tasks (the bodies' own factorizations and solves): the
// caller's choice, passed in with the solve's parameters. The library creates no threads:
// `grip solve` passes one that uses the machine's cores; the service's workers already share
// the cores between jobs and keep the default, one task after another.
#include <functional>

namespace grip {

// Runs task(0) .. task(count - 1), in any order or at once, and returns when all are done.
using ParallelFor = std::function<void(int count, const std::function<void(int)>& task)>;

inline void run_each(const ParallelFor& parallel, int count, const std::function<void(int)>& task) {
  if (parallel && count > 1) {
    parallel(count, task);
    return;
  }
  for (int k = 0; k < count; ++k) task(k);
}

}  // namespace grip
