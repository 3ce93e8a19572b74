// Strategy `penalty`: the baseline of one Newton solve with a penalty law; the contact error
// of eq. 10 (with tau = nu |p_eta|) measures how far its answer is from the contact
// conditions (it falls as the penalty stiffness grows). A body held by contact is held by the
// penalty springs: its rigid amplitudes are solved with the deformation (Equilibrium with the
// pins free), first with springs of 1e-2, 1e-4, 1e-6 x the largest stiffness on its pins,
// each solve from the last, then without them.
#include "solver/contact/step.hpp"

namespace grip {
namespace {

class PenaltyStep : public StepSolver {
 public:
  using StepSolver::StepSolver;

 private:
  void solve(const Vector& q_guess, const Vector& p_start, const Vector& p_previous) override {
    PenaltyLaw law;
    law.normal = params_.penalty_normal > 0 ? params_.penalty_normal
                                            : params_.penalty_factor * eq_.stiffness_scale(q_guess);
    law.tangential = params_.penalty_tangential > 0 ? params_.penalty_tangential : law.normal;
    law.previous = p_previous;  // the springs start from the last step's force
    Vector q0 = q_guess;
    touch(q0, p_start);
    EquilibriumState s;
    s.converged = true;
    int solves = 1;
    if (problem_.rigid.count())
      // Springs on the pins, weakened a hundredfold a solve, each solve from the last: the
      // answer carries no regularization, only the penalty springs hold the body.
      for (double spring = kPinSpring; spring > 1e-7 && s.converged; spring *= 1e-2) {
        law.pin_spring = spring * eq_.stiffness_scale(q_guess);
        eq_.set_penalty(law);
        s = eq_.solve(q0, p_start);
        if (s.converged) q0 = s.q;
        ++solves;
      }
    law.pin_spring = 0.0;
    eq_.set_penalty(law);
    if (s.converged) s = eq_.solve(q0, p_start);
    eq_.set_penalty(std::nullopt);
    pass_ = out_.passes = 1;
    if (!s.converged) {
      fail("equilibrium solve failed: " + s.reason);
      return;
    }
    Vector p_star = Vector::Zero(problem_.component_count);
    for (const Candidate& c : problem_.candidates) p_star[c.eta] = s.p[c.eta];
    out_.tau = friction_bounds(problem_, p_star);
    const Vector p = s.p;
    accept(std::move(s), p);
    out_.converged = true;
    emit(solves, 0, 0, 0, 0.0);
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
    for (int k = 0; k < rigid.count(); ++k) out_.state.s[rigid.first + k] = rigid.scale * rigid.modes.col(k).dot(applied);
    Vector dq;
    if (approach_motion(dq)) q += dq;
  }

  // The first solve's pin springs, times the largest diagonal stiffness: stiff enough to keep
  // Newton's iterates bounded while points switch between stick and slip (a free slide is
  // held by sticking springs only).
  static constexpr double kPinSpring = 1e-2;
};

}  // namespace

StepOutcome solve_penalty_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start,
                               const Vector& p_star, const ContactParams& params, int step,
                               const IterationObserver& observer, const StopRequest& stop) {
  return PenaltyStep(eq, params, step, observer, stop).run(q_guess, p_start, p_star);
}

}  // namespace grip
