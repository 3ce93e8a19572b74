#include "solver/contact/strategy.hpp"

#include "solver/contact/step.hpp"

namespace grip {

StepOutcome solve_contact_step(Equilibrium& equilibrium, const Vector& q_guess, const Vector& p_start,
                               const Vector& p_star, const ContactParams& params, int step,
                               const IterationObserver& observer, const StopRequest& stop, double v_previous) {
  switch (params.method) {
    case ContactMethod::uzawa:
      return solve_uzawa_step(equilibrium, q_guess, p_start, p_star, params, step, observer, stop);
    case ContactMethod::ssn:
      return solve_ssn_step(equilibrium, q_guess, p_start, p_star, params, step, observer, stop);
    case ContactMethod::penalty:
      return solve_penalty_step(equilibrium, q_guess, p_start, p_star, params, step, observer, stop);
    case ContactMethod::cev:
      break;
  }
  return solve_cev_step(equilibrium, q_guess, p_start, p_star, params, step, observer, stop, v_previous);
}

}  // namespace grip
