#pragma once
// The contact error vector v (eq. 10) and the Coulomb projection of eq. 13, shared by every
// strategy. Signs (docs/algorithm.md#notation): p_eta <= 0 presses; s_eta > 0 is penetration;
// s_xi is the incremental slip; tau = nu |p*_eta| is the friction bound of the current pass.
#include <vector>

#include "solver/problem/problem.hpp"

namespace grip {

// |p_xi| counts as at its bound tau when |p_xi| >= tau (1 - kBoundTolerance): a slipping
// point left a hair inside its bound by rounding must still count as slipping.
inline constexpr double kBoundTolerance = 1e-10;

struct ContactError {
  Vector v;                  // eq. 10
  std::vector<char> active;  // E(v) of (C.2): 1 where v was not identically defined as zero
  double norm2 = 0.0;
  double norm_inf = 0.0;
};

// `enabled` marks components with a non-zero column of T; the others are never active.
ContactError contact_error(const Problem& problem, const Vector& p, const Vector& s, const Vector& tau,
                           const std::vector<char>& enabled);

// eq. 13's projection of pbar = p - step, given the branches of the error at p.
Vector project_forces(const Problem& problem, const Vector& p, const Vector& pbar, const ContactError& error,
                      const Vector& tau);

// The friction bound per candidate: tau = nu |p*_eta| (eq. 14).
Vector friction_bounds(const Problem& problem, const Vector& p_star);

// Clip p_xi into [-tau, tau] (and zero it where tau is zero).
void clip_to_bounds(const Problem& problem, const Vector& tau, Vector& p);

enum class ContactState { open, stick, slip };
ContactState contact_state(const Problem& problem, size_t candidate, const Vector& p, const Vector& tau);
const char* to_string(ContactState state);

}  // namespace grip
