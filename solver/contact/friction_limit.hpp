#pragma once
// Whether friction can hold a body held by contact at the normal forces its deformation gives
// (docs/algorithm.md#the-friction-limit-decision): decided after a failed attempt of a step, from a
// state on Coulomb's law that cev's default loop reached at its target (load_stepping.cpp), where
// the rigid check before solving (unreachable_equilibrium) cannot decide (the normal forces come
// from the deformation: a disc squeezed between two flats and turned by a couple).
#include <string>

#include "solver/equilibrium/equilibrium.hpp"

namespace grip {

// Why the load at `factors` exceeds what friction can hold at the state (state, p, tau) of a
// failed attempt, or "" where that is not shown. The held motion c is the rigid motion
// (rigid_modes_at the state) that fits the pressed points' slips; W = c . R^T (F + T_eta p_eta)
// is the work of the load and of the normal forces along it, D = sum mu |p_eta| |slip rate along
// c| the most that friction at these normal forces can oppose. Reported where every pressed point
// with friction slips on its bound against c and W > D: the ratio W / D, worded as a couple
// (M / (mu sum N r), the moment about the centre of the turn) or as a shear (Q / (mu N)).
std::string friction_limit_exceeded(const Problem& problem, const EquilibriumState& state, const Vector& p,
                                    const Vector& tau, const LoadFactors& factors);

}  // namespace grip
