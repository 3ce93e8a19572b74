#pragma once
// Whether contact can hold a body whose supports leave rigid motions free (ALGORITHM.md 7):
// the contact forces must balance the applied load on those motions, pressing and inside
// Coulomb's cone. Checked before a step is solved, so that a load no static equilibrium can
// carry fails its step with the reason in words instead of a drifting solve.
#include <string>

#include "solver/solve/equilibrium.hpp"

namespace grip {

// Why the applied load at the step's factors cannot be held, or "" where it may be. Decided
// where every contact point faces one direction n (a flat, or obstacles parallel to it): the
// contact resultant N n + Q t must equal minus the load's resultant on the free translations,
// with N > 0 where translation along n is free and |Q| < mu N where translation along t is.
// Other arrangements are left to the solve.
std::string unreachable_equilibrium(const Problem& problem, const EquilibriumState& paired,
                                    const LoadFactors& factors);

// The change of the rigid amplitudes (problem.rigid, in their unit) that follows the supports
// from load factors `from` to `to`: for each body with free rigid motions, the rigid motion that
// fits the change of its prescribed values by least squares and has the least norm over its dofs
// (no part along the motions the supports leave free), read at its pins. A step then starts
// with a held body where its supports take it, not turned about them.
Vector amplitudes_following_supports(const Problem& problem, const LoadFactors& from, const LoadFactors& to);

// The rigid motion fitted to q by least squares over the body's translations and rotation
// (about the origin): (x, y, rotation in radians; no rotation for a body without one).
Vector rigid_amplitudes(const Body& body, const Vector& q);

}  // namespace grip
