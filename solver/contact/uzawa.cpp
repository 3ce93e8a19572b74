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
    // Its tau passes are bounded by the step's real-solve budget, not by max_tau_passes. Once a
    // pass has reached ||v|| <= tol, the next starts just above tol (the new bound moves or frees
    // the slipping points' forces) and ends after one real solve: each pass is then one
    // fixed-alpha step with the bound a solve behind, and p* moves monotonically, each change
    // 0.81-0.94 of the one before (sliding block at tolerance 1e-6: 0.088 -> 0.0082 over passes
    // 5-30, ~77 passes to settle at 4.9e-4). That is uzawa converging on Coulomb's law at its own
    // rate, not p* cycling; the 30-pass limit failed it at 65 real solves. Pinning the forces
    // first (as the accelerated loop does) asks ||v|| thousands of times below tol, under the
    // precision of its real solves (newton_fraction x tol): "alpha halved 40 times" at 1e-4.
    passes_to_budget_ = true;
    tau_passes(q_guess, p_start, p_star, [this] { return literal_pass(1, params_.uzawa_alpha); });
  }
};

}  // namespace

StepOutcome solve_uzawa_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start, const Vector& p_star,
                             const ContactParams& params, int step, const IterationObserver& observer,
                             const StopRequest& stop) {
  return UzawaStep(eq, params, step, observer, stop).run(q_guess, p_start, p_star);
}

}  // namespace grip
