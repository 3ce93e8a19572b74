#pragma once
// A test's view into Newton's loop (tests/unit/newton_allocation_test.cpp): where set, called at
// the start of every Newton iteration with its number (1, 2, ... within a solve). Null in the
// solver and the service: one test of a pointer an iteration.
namespace grip {

using NewtonIterationProbe = void (*)(int iteration);
extern NewtonIterationProbe newton_iteration_probe;

}  // namespace grip
