#pragma once
// Invariants every converged contact step must satisfy (eq. 9 and 12, equilibrium), checked
// on the solver's own output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "solver/contact/contact_error.hpp"
#include "solver/stepping/load_stepping.hpp"

namespace grip::testing {

struct InvariantTolerances {
  double length;        // absolute contact tolerance (tolerance x body length)
  double tau_relative;  // the tau-pass tolerance: the cone holds to this, relative to max |p_n|
};

// The step checks that load stepping made before accepting a converged step (issue 33.1,
// solver/stepping/step_checks.hpp) stayed within the limits docs/robustness.md states, and were
// made (a scene with obstacles has boundary points checked). `tau_relative` as above.
inline ::testing::AssertionResult step_checks_within_limits(const Problem& problem, const StepRecord& rec,
                                                            double tolerance_length, double tau_relative) {
  std::ostringstream why;
  const StepChecks& k = rec.checks;
  if (!(k.balance <= 0.1)) why << " balance " << k.balance << " > 0.1;";
  if (!(k.tension <= 1e-6)) why << " tension " << k.tension << " > 1e-6;";
  if (!(k.cone <= std::max(1e-6, 10 * tau_relative))) why << " cone " << k.cone << ";";
  if (!(k.penetration <= 10 * tolerance_length))
    why << " penetration " << k.penetration << " > " << 10 * tolerance_length << ";";
  if (!(k.normal_turn <= 90)) why << " normal turn " << k.normal_turn << " degrees;";
  if (!(k.obstacle_motion <= 1 + 1e-9)) why << " obstacle motion " << k.obstacle_motion << " of its bound;";
  if (!problem.obstacles.empty() && !problem.candidates.empty() &&
      k.boundary_points < static_cast<int>(problem.candidates.size()))
    why << " only " << k.boundary_points << " boundary points checked;";
  const std::string s = why.str();
  if (s.empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "step " << rec.index << " checks:" << s;
}

// A held body's pins carry no real support: what they hold (the reactions there) is the body's
// unbalance, at most 0.1 of the forces along that axis (the step checks' limit until the
// tolerance follows the load, issue 33.2; docs/robustness.md#limits).
inline double pin_force_share(const Problem& problem, const StepRecord& rec, int axis, double ref) {
  double pins = 0.0;
  const Vector mode = problem.body->rigid_translation(axis == 0 ? Vec2::UnitX() : Vec2::UnitY());
  for (int pin : problem.rigid.pins) pins += mode[pin] * rec.reactions[pin];
  return ref > 0 ? std::abs(pins) / ref : 0.0;
}

inline ::testing::AssertionResult step_invariants(const Problem& problem, const StepRecord& rec,
                                                  const InvariantTolerances& tol) {
  std::ostringstream why;
  if (!rec.converged) return ::testing::AssertionFailure() << "step " << rec.index << " failed: " << rec.reason;
  double max_pn = 0.0;
  for (const Candidate& c : problem.candidates) max_pn = std::max(max_pn, std::abs(rec.p[c.eta]));
  Vec2 total = Vec2::Zero();
  double scale = 0.0;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    const PairedPoint& pp = rec.state.points[i];
    const double pn = rec.p[c.eta], pt = c.xi >= 0 ? rec.p[c.xi] : 0.0;
    const double mu = problem.obstacles[c.obstacle].friction;
    const double gap = pp.projection.gap;
    if (!std::isfinite(pn) || !std::isfinite(pt) || !std::isfinite(gap))
      why << " point " << i << " has a non-finite value;";
    if (pn > 0) why << " point " << i << " pulls (p_n = " << pn << ");";
    if (-gap > tol.length) why << " point " << i << " penetrates by " << -gap << ";";
    if (pn < 0 && std::abs(gap) > tol.length) why << " point " << i << " presses with a gap " << gap << ";";
    if (c.xi >= 0) {
      if (std::abs(pt) > rec.tau[i] * (1 + 1e-9) + 1e-300)
        why << " point " << i << " exceeds its friction bound: " << pt << " vs " << rec.tau[i] << ";";
      if (std::abs(pt) > mu * (std::abs(pn) + tol.tau_relative * max_pn) * (1 + 1e-9))
        why << " point " << i << " is outside the Coulomb cone: " << pt << " vs " << mu * std::abs(pn) << ";";
      const double slip = rec.state.s[c.xi];
      const ContactState st = contact_state(problem, i, rec.p, rec.tau);
      if (st == ContactState::slip && std::abs(slip) > tol.length && pt * slip > 0)
        why << " point " << i << " slides along its friction force;";
      if (st == ContactState::stick && std::abs(slip) > tol.length)
        why << " point " << i << " sticks but slips by " << slip << ";";
    }
    const Vec2 f = pn * pp.eta + pt * pp.xi;
    // A pair of two bodies puts f on one and -f on the other: nothing on the whole.
    if (!problem.obstacles[c.obstacle].master) total += f;
    scale += f.norm();
  }
  // Equilibrium of the whole body: a rigid translation does no internal work.
  Vector applied = problem.load(rec.factors);
  problem.body->follower_load(rec.state.q, rec.factors, applied, nullptr);  // a pressure that follows the body
  double ref = scale;
  for (int axis = 0; axis < 2; ++axis) {
    const Vector mode = problem.body->rigid_translation(axis == 0 ? Vec2::UnitX() : Vec2::UnitY());
    ref += mode.cwiseAbs().dot(applied.cwiseAbs()) + mode.cwiseAbs().dot(rec.reactions.cwiseAbs());
  }
  // Axisymmetric: radial forces are held by the hoop stress, not balanced; the axial ones are.
  for (int axis = problem.body->axisymmetric() ? 1 : 0; axis < 2; ++axis) {
    const Vec2 d = axis == 0 ? Vec2::UnitX() : Vec2::UnitY();
    const Vector mode = problem.body->rigid_translation(d);
    const double sum = mode.dot(applied) + mode.dot(rec.reactions) + total.dot(d);
    if (std::abs(sum) > 1e-7 * ref)
      why << " force balance along axis " << axis << " is off by " << sum << " of " << ref << ";";
    if (const double pins = pin_force_share(problem, rec, axis, ref); pins > 0.1)
      why << " the pins of the held body carry " << pins << " of the forces along axis " << axis << ";";
  }
  if (::testing::AssertionResult checks = step_checks_within_limits(problem, rec, tol.length, tol.tau_relative);
      !checks)
    why << " " << checks.message();
  const std::string s = why.str();
  if (s.empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "step " << rec.index << ":" << s;
}

// Within each tau pass, the contact error never rises at an accepted real solve (it stays equal
// where a step ends at the precision its solves reach: StepSolver::reached_precision).
// `within`: where the step also tests the free motions' balance (StepSolver::error_met: a body
// turned by finite rotations), a real solve within the contact tolerance is accepted for a
// smaller unbalance even if ||v|| rises (StepSolver::improves): rises up to `within` (the
// tolerance) are allowed there.
inline ::testing::AssertionResult monotone_contact_error(const StepRecord& rec, double within = 0.0) {
  for (size_t k = 1; k < rec.history.size(); ++k) {
    const auto& a = rec.history[k - 1];
    const auto& b = rec.history[k];
    const bool progress = b.trials == 0 && b.m == a.m;  // no new update: the same state (budget_left)
    if (b.pass == a.pass && b.m > 0 && !progress && b.v2 > a.v2 && b.v2 > within)
      return ::testing::AssertionFailure() << "step " << rec.index << " pass " << b.pass << " m " << b.m
                                           << ": ||v|| rose from " << a.v2 << " to " << b.v2;
  }
  return ::testing::AssertionSuccess();
}

}  // namespace grip::testing
