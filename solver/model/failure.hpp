#pragma once
// Why a step or a run failed, for a program to branch on: the kind beside the sentence. The
// result, the events and the service's job document carry it as failure.kind (a string: the
// enumerator's name); schemas/result.schema.json lists them.
#include <string_view>

namespace grip {

enum class FailureKind {
  none,
  friction_limit,   // the load exceeds what friction can hold (friction_limit.hpp)
  no_equilibrium,   // no static equilibrium carries the load: a free motion nothing holds
  newton_diverged,  // an equilibrium solve (Newton) diverged, stalled or met a singular tangent
  invalid_state,    // the body reached a state its model refuses (an element turned inside out)
  contact_budget,   // the contact iteration spent its budget (real solves, tau passes)
  contact_stalled,  // the contact iteration found no way to lower its error further
  check_failed,     // a converged state failed the independent step checks (step_checks.hpp)
  missed_contact,   // a node outside the contact candidates entered an obstacle
  penalty_inexact,  // penalty's answer misses its tolerance or its own law (its stiffness is too low)
  stopped,          // a stop request that gave no reason (SteppingObserver::stop_reason)
  job_limit,        // the caller's limit: contact iterations, wall time, nodes or steps
  dismissed,        // the caller withdrew the run
  invalid_scene,    // the scene cannot be read (the service's stored copy)
  exception,        // the solver threw (out of memory, an internal error)
};

constexpr std::string_view to_string(FailureKind kind) {
  switch (kind) {
    case FailureKind::none:
      return "none";
    case FailureKind::friction_limit:
      return "friction_limit";
    case FailureKind::no_equilibrium:
      return "no_equilibrium";
    case FailureKind::newton_diverged:
      return "newton_diverged";
    case FailureKind::invalid_state:
      return "invalid_state";
    case FailureKind::contact_budget:
      return "contact_budget";
    case FailureKind::contact_stalled:
      return "contact_stalled";
    case FailureKind::check_failed:
      return "check_failed";
    case FailureKind::missed_contact:
      return "missed_contact";
    case FailureKind::penalty_inexact:
      return "penalty_inexact";
    case FailureKind::stopped:
      return "stopped";
    case FailureKind::job_limit:
      return "job_limit";
    case FailureKind::dismissed:
      return "dismissed";
    case FailureKind::invalid_scene:
      return "invalid_scene";
    case FailureKind::exception:
      return "exception";
  }
  return "none";
}

}  // namespace grip
