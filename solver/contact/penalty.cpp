// Strategy `penalty`: the baseline of one Newton solve with a penalty law; the contact error
// of eq. 10 (with tau = nu |p_eta|) measures how far its answer is from the contact
// conditions (it falls as the penalty stiffness grows). A body held by contact is held by the
// penalty springs: its rigid amplitudes are solved with the deformation (Equilibrium with the
// pins free), first with springs of 1e-2, 1e-4, 1e-6 x the largest stiffness on its pins,
// each solve from the last, then without them. Where that fails, the step is solved again with
// the law's stiffness ramped up from 1e-3 x its own (PenaltyStep::levels). Its step converges
// only where its answer meets the tolerance and obeys its law (no tension, friction within the
// cone); otherwise it fails with the error and penetration it reached.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "solver/contact/step.hpp"
#include "solver/model/number_text.hpp"

namespace grip {
namespace {

class PenaltyStep : public StepSolver {
 public:
  using StepSolver::StepSolver;

 private:
  void solve(const Vector& q_guess, const Vector& p_start, const Vector& p_previous) override {
    PenaltyLaw law;
    law.normal =
        params_.penalty_normal > 0 ? params_.penalty_normal : params_.penalty_factor * eq_.stiffness_scale(q_guess);
    law.tangential = params_.penalty_tangential > 0 ? params_.penalty_tangential : law.normal;
    law.previous = p_previous;  // the springs start from the last step's force
    Vector q0 = q_guess;
    touch(q0, p_start);
    const double pin_scale = problem_.rigid.count() ? eq_.stiffness_scale(q_guess) : 0.0;
    int solves = 0;
    EquilibriumState s = levels(law, pin_scale, q0, p_start, 1.0, solves);
    if (!s.converged && !out_.stopped) s = levels(law, pin_scale, q0, p_start, kRamp, solves);
    eq_.set_penalty(std::nullopt);
    pass_ = out_.passes = 1;
    if (!s.converged) {
      if (!out_.stopped) fail(s.failure, "equilibrium solve failed: " + s.reason);
      return;
    }
    Vector p_star = Vector::Zero(problem_.component_count);
    for (const Candidate& c : problem_.candidates) p_star[c.eta] = s.p[c.eta];
    out_.tau = friction_bounds(problem_, p_star);
    const Vector p = s.p;
    accept(std::move(s), p);
    emit(solves, 0, 0, 0, 0.0);
    if (!obeys_law()) return;
    // `converged` only where the step's tolerance is met (docs/algorithm.md#tolerance): its
    // answer's error is about |p| / k, which no cut of the increment lowers.
    if (!error_met(error_)) {
      out_.definitive = true;
      double penetration = 0.0;
      for (const Candidate& c : problem_.candidates) penetration = std::max(penetration, out_.state.s[c.eta]);
      const double raise = error_.norm2 > tol_ ? error_.norm2 / tol_ : 1.0;
      fail(FailureKind::penalty_inexact,
           "penalty: contact error " + number_text(error_.norm2) + " above the bound " + number_text(tol_) +
               " (penetration " + number_text(penetration) + ", k_n = " + number_text(law.normal) +
               "): a penalty stiffness (or a tolerance) about " + number_text(raise) + " x larger would meet it");
      return;
    }
    out_.converged = true;
  }

  // Its forces obey its own law: no tension, and friction within mu |p_n| (its regularized
  // cone). The force the strategy reports is the
  // law linearized over Newton's last correction (Equilibrium::finish_penalty); at loads tiny
  // against k that crossed the law's kink: p_n = +7.3 on an open point, |p_t| = 15.5 mu |p_n|
  // (the held block with E x 1e6).
  // A force off its law by no more than rounding (1e-9 of the largest normal force) is put on it.
  bool obeys_law() {
    double largest = 0.0;
    for (const Candidate& c : problem_.candidates) largest = std::max(largest, std::abs(out_.p[c.eta]));
    const double slack = 1e-9 * largest;
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const Candidate& c = problem_.candidates[i];
      const double pn = out_.p[c.eta], pt = c.xi >= 0 ? out_.p[c.xi] : 0.0;
      const double mu = problem_.obstacles[c.obstacle].friction;
      if (pn > slack)
        return fail(FailureKind::penalty_inexact, "penalty: its normal force pulls at contact point " +
                                                      std::to_string(i) + " (p_n = " + number_text(pn) +
                                                      "): its law gives no tension");
      if (std::abs(pt) > mu * std::abs(pn) * (1 + 1e-9) + slack)
        return fail(FailureKind::penalty_inexact, "penalty: its friction force at contact point " + std::to_string(i) +
                                                      " (|p_t| = " + number_text(std::abs(pt)) +
                                                      ") exceeds mu |p_n| = " + number_text(mu * std::abs(pn)));
    }
    for (const Candidate& c : problem_.candidates) out_.p[c.eta] = std::min(0.0, out_.p[c.eta]);
    out_.tau = friction_bounds(problem_, out_.p);
    clip_to_bounds(problem_, out_.tau, out_.p);
    return true;
  }

  // One solve per level, each from the last. A body held by contact has springs on its pins,
  // weakened a hundredfold a level, then none (the answer carries no regularization, only the
  // penalty springs hold the body). With `ramp` < 1 the law's stiffnesses start at ramp x theirs
  // and grow geometrically to theirs at the last level (four levels): where the law's full
  // stiffness fails from a first touch (Newton's iterates press the few points that touch at
  // 15-60 x the load and crawl ring by ring: two_bodies_held_test), a soft law finds the contact
  // zone in a few iterations and each stiffer level starts next to its answer.
  EquilibriumState levels(const PenaltyLaw& law, double pin_scale, Vector q, const Vector& p_start, double ramp,
                          int& solves) {
    const bool held = problem_.rigid.count() > 0;
    const int count = held || ramp < 1.0 ? kLevels : 1;
    EquilibriumState s;
    s.reason = "no level solved";
    s.failure = FailureKind::newton_diverged;
    for (int level = 0; level < count; ++level) {
      PenaltyLaw at = law;
      const double stiffer = std::pow(ramp, static_cast<double>(count - 1 - level) / std::max(1, count - 1));
      at.normal *= stiffer;
      at.tangential *= stiffer;
      at.pin_spring = held && level + 1 < count ? kPinSpring * std::pow(1e-2, level) * pin_scale : 0.0;
      // A stop (a dismissal, a job limit) is heard before every real solve, as by the others.
      if (stop_ && stop_()) {
        out_.stopped = true;
        fail(FailureKind::stopped, "stopped on request");
        s.converged = false;
        return s;
      }
      eq_.set_penalty(at);
      s = eq_.solve(q, p_start);
      ++solves;
      if (!s.converged) return s;
      q = s.q;
    }
    return s;
  }

  // A body held by contact with no point pressing yet (its first step): nothing but the pin
  // springs would hold it in Newton's first iteration, so it is first moved rigidly along its
  // free motions, as the load pushes it, until its nearest points touch (approach_motion).
  void touch(Vector& q, const Vector& p_start) {
    const RigidModes& rigid = problem_.rigid;
    if (!rigid.count()) return;
    for (const Candidate& c : problem_.candidates)
      if (p_start[c.eta] < 0) return;
    out_.p = p_start;
    out_.state = eq_.evaluate(q);
    const Vector applied = eq_.applied_forces(out_.state, p_start);
    for (int k = 0; k < rigid.count(); ++k)
      out_.state.s[rigid.first + k] = rigid.scale * rigid.modes.col(k).dot(applied);
    Vector dq;
    if (approach_motion(dq)) q += dq;
  }

  // The first solve's pin springs, times the largest diagonal stiffness: stiff enough to keep
  // Newton's iterates bounded while points switch between stick and slip (a free slide is
  // held by sticking springs only).
  static constexpr double kPinSpring = 1e-2;
  // Levels of pin springs (a held body) or of the stiffness ramp, and the ramp's first factor.
  static constexpr int kLevels = 4;
  static constexpr double kRamp = 1e-3;
};

}  // namespace

StepOutcome solve_penalty_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start, const Vector& p_star,
                               const ContactParams& params, int step, const IterationObserver& observer,
                               const StopRequest& stop) {
  return PenaltyStep(eq, params, step, observer, stop).run(q_guess, p_start, p_star);
}

}  // namespace grip
