#pragma once
// The penalty law of strategy `penalty` (Equilibrium::set_penalty, penalty_law.cpp).
#include "solver/model/types.hpp"

namespace grip {

// The penalty baseline (strategy `penalty`): p_eta = -k_n <s_eta>, and a tangential spring
// k_t on the incremental slip from the previous step's force, returned to the Coulomb cone.
struct PenaltyLaw {
  double normal = 0.0;      // k_n, force / length
  double tangential = 0.0;  // k_t, force / length
  Vector previous;          // the previous step's forces (the tangential springs start there)
  // A body held by contact (problem.rigid): its amplitudes are solved with the deformation (the
  // pins are free dofs), held by the springs; `pin_spring` (force / length) on each pin keeps
  // Newton non-singular while fewer points press or stick than hold every motion.
  double pin_spring = 0.0;
};

}  // namespace grip
