#pragma once
// Load stepping: the scene's load factors in order, each solved by the contact strategy,
// with adaptive cutting of a failed increment. State (displacements, contact forces, the
// surface coordinates that slips are measured from, body history) is committed only after
// a step converges.
#include <string>
#include <vector>

#include "solver/contact/strategy.hpp"
#include "solver/stepping/step_checks.hpp"

namespace grip {

struct SteppingParams {
  ContactParams contact;
  NewtonParams newton;
  int max_cuts = 5;  // a failed increment is halved at most this many times in a row
  // An obstacle pairs with a site only if it comes this close over the load path (length;
  // 0: the body's characteristic length). Read by the scene layer when building candidates.
  double contact_reach = 0.0;
  // A boundary point outside the contact candidates that enters an obstacle (or a site that
  // comes within reach of one it was not paired with): false adds it to the candidates for the
  // rest of the run (a note in the step), true fails the step naming the node.
  bool fail_outside_candidates = false;
  // Steps whose fields (nodes, elements) are kept; empty: every step.
  std::vector<char> record_fields;
};

struct StepRecord {
  int index = 0;  // 1-based output step
  int stage = 0;
  double load_factor = 0.0;  // the first load case's factor
  LoadFactors factors;       // every load case's factor
  bool converged = false;
  std::string reason;
  FailureKind failure = FailureKind::none;  // the kind of the reason
  std::string warning;                      // the converged state lies beyond the model's accurate range
  std::vector<std::string> notes;           // candidates added; a start from the last converged state
  StepChecks checks;                        // the step checks' worst values (step_checks.hpp)
  int cuts = 0;                             // sub-increments this step needed beyond one
  int restarts = 0;                         // attempts from the extrapolated force retried from the last one
  int multiplier_updates = 0;               // moves of the body's multipliers (exact incompressibility)
  int passes = 0, solves = 0, newton_iterations = 0, inner_iterations = 0;
  double seconds = 0.0;
  std::string epsilon_used;
  // The contact error reached (||v||_2 of the last accepted state), the bound it was held to,
  // the displacement that bound is relative to, and whether round-off set it instead.
  double contact_error = 0.0, bound = 0.0, scale = 0.0;
  bool at_round_off = false;
  Vector p, tau, reactions;
  EquilibriumState state;
  FieldTable site_fields, element_fields;  // taken at the converged state, before commit
  std::vector<IterationEvent> history;
};

struct SteppingObserver {
  std::function<void(int step, double load_factor)> step_started;
  IterationObserver iteration;
  StopRequest stop_requested;  // checked before every real solve
  // After a stop: its kind and reason (a job limit, a dismissal), which the stopped step
  // records instead of "stopped on request".
  std::function<std::pair<FailureKind, std::string>()> stop_reason;
  std::function<void(const StepRecord&)> step_finished;
  // Tests only (tests/verification/j2_press_fit_cycle_test.cpp): asked of every attempt that
  // converged and passed the step checks, with the step (from 1) and the part of it the attempt
  // took (from, to: fractions of the step); true refuses the attempt as a failed one (retried,
  // then cut). Nothing else sets it.
  std::function<bool(int step, double from, double to)> refuse_attempt;
};

struct RunResult {
  std::vector<StepRecord> steps;
  bool completed = false;
  bool stopped = false;  // by the observer's stop request
  std::string reason;
  FailureKind failure = FailureKind::none;  // the kind of the reason
  int failure_step = 0;                     // the step that failed, from 1
  EquilibriumCounters counters;
  double seconds = 0.0;
  double check_seconds = 0.0;  // spent in the step checks (bench/results/robustness.md)
};

RunResult run_load_steps(Problem& problem, const std::vector<LoadStep>& steps, const SteppingParams& params,
                         const SteppingObserver& observer = {});

}  // namespace grip
