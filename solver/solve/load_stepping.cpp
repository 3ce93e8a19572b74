#include "solver/solve/load_stepping.hpp"

#include <chrono>
#include <cmath>

namespace grip {

RunResult run_load_steps(Problem& problem, const std::vector<double>& load_factors,
                         const SteppingParams& params, const SteppingObserver& observer) {
  using Clock = std::chrono::steady_clock;
  const auto run_start = Clock::now();
  RunResult result;
  Equilibrium eq(problem, params.newton);
  const int ndof = problem.body->dof_count();
  Vector q = Vector::Zero(ndof), q_before = q;
  Vector p = Vector::Zero(problem.component_count);
  double lambda = 0.0, lambda_before = 0.0;
  eq.set_step(0.0, std::vector<double>(problem.candidates.size(), 0.0));
  std::vector<double> zeta = eq.zetas(eq.evaluate(q));

  for (size_t k = 0; k < load_factors.size(); ++k) {
    const int step = static_cast<int>(k) + 1;
    const auto step_start = Clock::now();
    if (observer.step_started) observer.step_started(step, load_factors[k]);
    StepRecord rec;
    rec.index = step;
    rec.load_factor = load_factors[k];
    // Sub-increments toward the target; a failure halves the remaining increment.
    double increment = load_factors[k] - lambda;
    int depth = 0;
    while (true) {
      const double target = std::abs(load_factors[k] - lambda) <= std::abs(increment) * (1 + 1e-12)
                                ? load_factors[k]
                                : lambda + increment;
      // Newton starts from the previous increment scaled to this one (section 9): a zero
      // guess would leave a membrane without transverse stiffness.
      const double last = lambda - lambda_before;
      const Vector guess =
          last != 0.0 ? Vector(q + (q - q_before) * ((target - lambda) / last)) : q;
      eq.set_step(target, zeta);
      StepOutcome out = solve_contact_step(eq, guess, p, p, params.contact, step,
                                           observer.iteration, observer.stop_requested);
      rec.passes += out.passes;
      rec.solves += out.solves;
      rec.newton_iterations += out.newton_iterations;
      rec.inner_iterations += out.inner_iterations;
      rec.history.insert(rec.history.end(), out.history.begin(), out.history.end());
      if (!out.epsilon_used.empty()) rec.epsilon_used = out.epsilon_used;
      if (!out.converged) {
        if (out.stopped) result.stopped = true;
        if (depth >= params.max_cuts || out.stopped) {
          rec.reason = out.reason + (depth ? " (after " + std::to_string(depth) + " cuts of the increment)" : "");
          rec.p = out.p;
          rec.tau = out.tau;
          rec.state = std::move(out.state);
          break;
        }
        increment *= 0.5;
        ++depth;
        ++rec.cuts;
        continue;
      }
      // Commit.
      q_before = q;
      lambda_before = lambda;
      q = out.state.q;
      p = out.p;
      lambda = target;
      zeta = eq.zetas(out.state);
      problem.body->commit(q);
      if (target == load_factors[k]) {
        rec.converged = true;
        rec.p = out.p;
        rec.tau = out.tau;
        rec.reactions = eq.reactions(out.state, out.p);
        rec.state = std::move(out.state);
        break;
      }
    }
    rec.seconds = std::chrono::duration<double>(Clock::now() - step_start).count();
    const bool ok = rec.converged;
    if (!ok) result.reason = "step " + std::to_string(step) + " failed: " + rec.reason;
    if (observer.step_finished) observer.step_finished(rec);
    result.steps.push_back(std::move(rec));
    if (!ok) break;
  }
  result.completed = result.reason.empty();
  result.counters = eq.counters();
  result.seconds = std::chrono::duration<double>(Clock::now() - run_start).count();
  return result;
}

}  // namespace grip
