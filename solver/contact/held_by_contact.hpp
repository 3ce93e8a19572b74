#pragma once
// Whether contact can hold a body whose supports leave rigid motions free
// (docs/algorithm.md#bodies-held-only-by-contact):
// the contact forces must balance the applied load on those motions, pressing and inside
// Coulomb's cone. Checked before a step is solved, so that a load no static equilibrium can
// carry fails its step with the reason in words instead of a drifting solve.
// Rigid modes themselves: solver/problem/rigid_modes.hpp; the friction limit after a failed attempt:
// friction_limit.hpp.
#include <string>

#include "solver/equilibrium/equilibrium.hpp"

namespace grip {

// Why the applied load at the step's factors cannot be held (kind none where it may be). Decided
// where every contact point faces one direction n (a flat, or obstacles parallel to it): the
// contact resultant N n + Q t must equal minus the load's resultant on the free translations,
// with N > 0 where translation along n is free and |Q| < mu N where translation along t is.
// Other arrangements are left to the solve.
struct Unreachable {
  FailureKind kind = FailureKind::none;  // friction_limit (the shear), no_equilibrium (a pull)
  std::string reason;
};
Unreachable unreachable_equilibrium(const Problem& problem, const EquilibriumState& paired, const LoadFactors& factors);

// "at load factor 1.05", or "at load factors press 1, shear 1.05" (the non-zero ones, named).
std::string load_factors_text(const Problem& problem, const LoadFactors& factors);

}  // namespace grip
