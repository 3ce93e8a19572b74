#pragma once
// cev's held real solve (`solver.contact.real_solve: held`, Equilibrium::set_held, held_contact.cpp).
#include <vector>

#include "solver/model/types.hpp"

namespace grip {

// The body under the given contact forces p, except that the obstacles hold the points the
// linear model presses or sticks: their forces are p + k (target - s(q)), springs of stiffness k
// toward the model's kinematics at p, equal to p where the model is exact. A dead load passes a
// limit point where the obstacle, holding its points, has none (docs/algorithm.md#the-held-real-solve).
struct HeldContact {
  Vector target;     // per component: the linear model's s at the given forces
  Vector stiffness;  // per component (force / length); 0: the given force, not held
  // Per candidate: +-1 where the model slips it, its tangential force then +-mu |p_eta(q)| of the
  // normal force it carries; 0 otherwise.
  std::vector<signed char> slip;
};

}  // namespace grip
