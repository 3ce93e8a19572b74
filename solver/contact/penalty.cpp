// Strategy `penalty`: the baseline of one Newton solve with a penalty law; the contact error
// of eq. 10 (with tau = nu |p_eta|) measures how far its answer is from the contact
// conditions (it falls as the penalty stiffness grows).
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
    eq_.set_penalty(law);
    EquilibriumState s = eq_.solve(q_guess, p_start);
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
    emit(1, 0, 0, 0, 0.0);
  }
};

}  // namespace

StepOutcome solve_penalty_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start,
                               const Vector& p_star, const ContactParams& params, int step,
                               const IterationObserver& observer, const StopRequest& stop) {
  return PenaltyStep(eq, params, step, observer, stop).run(q_guess, p_start, p_star);
}

}  // namespace grip
