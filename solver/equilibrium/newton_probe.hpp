#pragma once
// A test's view into Newton's loop (tests/alloc/newton_allocation_test.cpp): where set, called at
// the start of every Newton iteration with its number (1, 2, ... within a solve) and the
// symbolic analyses of Newton's and the body's factorizations so far (a new sparsity pattern
// between two calls is analysed, and its storage sized, once). Null in the solver and the
// service: one test of a pointer an iteration.
namespace grip {

using NewtonIterationProbe = void (*)(int iteration, long analyses);
extern NewtonIterationProbe newton_iteration_probe;

}  // namespace grip
