#pragma once
// Coulomb's law on the linear model s(p) = s0 + C (p - p0) of one contact iteration, with the
// friction bound mu |p_eta| moving with p_eta (no tau passes): a semismooth Newton method on
// the Alart-Curnier function (Alart & Curnier 1991; signs of docs/algorithm.md#notation)
//     F_eta = p_eta - min(0, p_eta - r s_eta)
//     F_xi  = p_xi - clamp(p_xi - r s_xi, -tau, tau),   tau = mu max(0, -(p_eta - r s_eta))
// whose zeros are the contact conditions with the Coulomb cone. Globalized by backtracking on
// |F|^2 / 2; where that stalls (the stick/slip set cycles), the model's own tau passes finish
// the job (Tresca problems on the model, no real solves). r is the augmentation: it changes
// the path, not the zeros; r = augmentation / C_ii, each component's own contact stiffness.
#include <vector>

#include "solver/contact/contact_error.hpp"
#include "solver/equilibrium/equilibrium.hpp"

namespace grip {

struct CoulombModelParams {
  double target = 0.0;        // ||v|| on the model (length) that ends the solve
  double augmentation = 1.0;  // r_i times C_ii
  int max_iterations = 100;
  int max_halvings = 30;
};

struct CoulombModelSolution {
  Vector p, s;         // full component vectors; p in the cone exactly
  ContactError error;  // on the model, with tau = mu |p_eta|
  int iterations = 0;  // Newton iterations on the model
  int halvings = 0;
  int factorizations = 0;  // of reduced Newton systems or of C's active block (newton_rows.hpp)
  int capacitances = 0;    // low-rank corrections of a kept factorization
  bool converged = false;  // error.norm2 <= target
};

// Over the components of C (the others keep p0 and s0). `enabled` as for contact_error.
CoulombModelSolution solve_coulomb_model(const Problem& problem, const Compliance& C, const Vector& p0,
                                         const Vector& s0, const std::vector<char>& enabled,
                                         const CoulombModelParams& params);

// p_eta clipped to <= 0 and p_xi into [-mu |p_eta|, mu |p_eta|].
void project_to_cone(const Problem& problem, Vector& p);

}  // namespace grip
