// Strategy `uzawa`: the paper's literal loop with n = 1 and a fixed alpha (the multiplier
// update the paper compares against), inside the tau passes of eq. 14.
#include "solver/contact/step.hpp"

namespace grip {
namespace {

class UzawaStep : public StepSolver {
 public:
  using StepSolver::StepSolver;

 private:
  void solve(const Vector& q_guess, const Vector& p_start, const Vector& p_star) override {
    tau_passes(q_guess, p_start, p_star, [this] { return literal_pass(1, params_.uzawa_alpha); });
  }
};

}  // namespace

StepOutcome solve_uzawa_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start,
                             const Vector& p_star, const ContactParams& params, int step,
                             const IterationObserver& observer, const StopRequest& stop) {
  return UzawaStep(eq, params, step, observer, stop).run(q_guess, p_start, p_star);
}

}  // namespace grip
