#include "solver/stepping/load_stepping.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <tuple>

#include "solver/contact/friction_limit.hpp"
#include "solver/contact/held_by_contact.hpp"
#include "solver/contact/step.hpp"
#include "solver/problem/rigid_modes.hpp"
#include "solver/stepping/candidate_growth.hpp"
#include "solver/stepping/limit_load.hpp"

namespace grip {
namespace {

LoadFactors blend(const LoadFactors& from, const LoadFactors& to, double t) {
  LoadFactors out(to.size());
  for (size_t k = 0; k < to.size(); ++k) out[k] = (k < from.size() ? from[k] : 0.0) * (1 - t) + to[k] * t;
  return out;
}

// The start-up solve of a body without reference stiffness (Problem::start): returns the
// displacement to start the first step's Newton from, and sets the starting contact force.
std::optional<Vector> start_up(const Problem& problem, const SteppingParams& params, const LoadFactors& factors,
                               const std::vector<double>& zeta, Vector& p, std::string& reason, FailureKind& failure) {
  const StartUp& st = *problem.start;
  Equilibrium pre(problem, params.newton, {{st.dof, st.value, 0}});
  couple_newton(pre.params(), newton_coupling_tolerance(params.contact), params.contact.newton_fraction,
                problem.body->characteristic_length());
  pre.set_step(factors, zeta);
  const int ndof = problem.body->dof_count();
  Vector prescribed = Vector::Zero(ndof);
  std::vector<char> mask(ndof, 0);
  for (const Constraint& c : problem.constraints) mask[c.dof] = 1;
  prescribed[st.dof] = st.value;
  mask[st.dof] = 1;
  const EquilibriumState s = pre.solve(problem.body->start_guess(prescribed, mask), p);
  if (!s.converged) {
    reason = "the start-up solve failed: " + s.reason;
    failure = s.failure;
    return std::nullopt;
  }
  const Vector reaction = pre.reactions(s, p);
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (c.site != st.site || c.obstacle != st.obstacle) continue;
    Vec2 f = Vec2::Zero();
    for (const auto& j : s.points[i].point.jacobian)
      if (j.dof == st.dof) f += reaction[st.dof] * j.dx;
    p[c.eta] = std::min(0.0, f.dot(s.points[i].eta));
  }
  return s.q;
}

// cev's default loop, with the user's tolerance and budgets: Coulomb's law at every state it
// accepts (the bound mu |p_eta| moves with p). Its model's fallback solves with n = infinity.
ContactParams coulomb_loop(ContactParams c) {
  c.method = ContactMethod::cev;
  c.loop = ContactLoop::inner;
  c.friction_loop = FrictionLoop::inner;
  c.acceleration = kAccelerationInfinity;
  return c;
}

bool is_coulomb_loop(const ContactParams& c) {
  return c.method == ContactMethod::cev && c.loop == ContactLoop::inner && c.friction_loop == FrictionLoop::inner &&
         c.acceleration == kAccelerationInfinity;
}

// cev's default loop (given or held real solves) takes ssn's semismooth Newton as the last
// resort of an increment: the same tolerance, budgets and contact error, q and p moved together.
bool takes_semismooth_last_resort(const ContactParams& c) {
  return c.method == ContactMethod::cev && c.loop == ContactLoop::inner && c.friction_loop == FrictionLoop::inner;
}

ContactParams semismooth(ContactParams c) {
  c.method = ContactMethod::ssn;
  return c;
}

// Adds an attempt's counts and events to the step's record.
void count_attempt(StepRecord& rec, const StepOutcome& out) {
  rec.passes += out.passes;
  rec.solves += out.solves;
  rec.newton_iterations += out.newton_iterations;
  rec.inner_iterations += out.inner_iterations;
  rec.history.insert(rec.history.end(), out.history.begin(), out.history.end());
  if (!out.epsilon_used.empty()) rec.epsilon_used = out.epsilon_used;
  rec.contact_error = out.v2;
  rec.bound = out.bound;
  rec.scale = out.scale;
  rec.at_round_off = out.at_round_off;
}

double distance(const LoadFactors& a, const LoadFactors& b) {
  double d = 0.0;
  for (size_t k = 0; k < a.size() && k < b.size(); ++k) d += (a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(d);
}

// -1 where the increment b -> c turns back on a -> b (a load reversed: unloading), else 1.
double turn(const LoadFactors& a, const LoadFactors& b, const LoadFactors& c) {
  double dot = 0.0;
  for (size_t k = 0; k < a.size() && k < b.size() && k < c.size(); ++k) dot += (b[k] - a[k]) * (c[k] - b[k]);
  return dot < 0 ? -1.0 : 1.0;
}

using Clock = std::chrono::steady_clock;

// Updates of a body's multipliers (Body::update_multipliers) one increment may take: the exact
// incompressible continuum's shrink its volume error by about shear / bulk <= 1e-2 each.
constexpr int kMaxMultiplierUpdates = 20;

// The record of step `index` (from 1), before it is solved.
StepRecord step_record(const LoadStep& step, int index) {
  StepRecord rec;
  rec.index = index;
  rec.stage = step.stage;
  rec.factors = step.factors;
  rec.load_factor = step.factors.empty() ? 0.0 : step.factors.front();
  return rec;
}

// The steps in order into `result`, up to the first that fails.
void step_through(Problem& problem, const std::vector<LoadStep>& steps, const SteppingParams& params,
                  const SteppingObserver& observer, RunResult& result) {
  auto eq = std::make_unique<Equilibrium>(problem, params.newton);
  EquilibriumCounters spent;  // by the oracles that candidates added since replaced
  const int ndof = problem.body->dof_count();
  // The rigid amplitudes' unit: length per force of the stiffest dof (problem.hpp).
  if (problem.rigid.count()) problem.rigid.scale = 1.0 / eq->stiffness_scale(Vector::Zero(ndof));
  const size_t cases = steps.empty() ? 1 : steps.front().factors.size();
  Vector q = Vector::Zero(ndof), q_before = q;
  Vector p = Vector::Zero(problem.component_count), p_before = p;
  // Node-to-segment pairs start from the last force: from the extrapolated one, the slave
  // nodes' forces land on other master segments and the loop wanders (two cylinders of
  // unequal materials, step 2: 59 real solves and 1958 Newton iterations instead of 4 and 24).
  const bool extrapolate_forces = std::none_of(problem.obstacles.begin(), problem.obstacles.end(),
                                               [](const ObstacleInstance& o) { return o.master.has_value(); });
  // Where the load turns back, the forces extrapolated back along the last increment are the
  // answer only for a body whose state does not depend on its path: a yielding body unloads
  // elastically, not along its loading path, and starts better from the last forces (J2Contact's
  // plastic cylinder: its first release step 3 -> 2 real solves, the elastic one's stays 1).
  const bool path_dependent = problem.body->traits().plasticity;
  // A body whose elements hold the volume (mixed, F-bar) starts Newton from the last
  // converged state: the displacements extrapolated along the last increment change the volume
  // at second order, which the bulk modulus (1e3-1e4 x shear) turns into a residual hundreds of
  // times the body's stresses, and the tangent there was not positive definite (the bulging
  // block at bulk 1e4 x shear, q9 mixed: the first solve of a step 25-40 Newton iterations with
  // the correction cut to 1/256, or failed; from the converged state 3-10;
  // docs/algorithm.md#newtons-tangent-the-linearized-dilatation). The forces stay extrapolated.
  // Where every attempt of an increment failed from there, they run again from the extrapolated
  // state (the fallback below, the other way round), so that the fallback still tries another start.
  const bool extrapolate_q = !problem.body->traits().volume_constrained;
  LoadFactors current(cases, 0.0), before = current;
  eq->set_step(current, std::vector<double>(problem.candidates.size(), 0.0));
  std::vector<double> zeta = eq->zetas(eq->evaluate(q));
  std::optional<Vector> start_q;
  double v_first = 0.0;  // the contact error of the last increment's first solve
  if (problem.start) {
    start_q = start_up(problem, params, current, zeta, p, result.reason, result.failure);
    if (!start_q) {
      result.failure_step = 1;  // the start-up solve is the first step's
      result.counters = eq->counters();
      return;
    }
  }
  auto checker = std::make_unique<StepChecker>(problem, params.contact, params.contact_reach);
  LoadPathStiffness along_load(problem);
  AcceptedContact accepted = accepted_contact(eq->evaluate(q), p);

  for (size_t k = 0; k < steps.size(); ++k) {
    const LoadStep& target_step = steps[k];
    const int step = static_cast<int>(k) + 1;
    const auto step_start = Clock::now();
    for (size_t o = 0; o < target_step.friction.size() && o < problem.obstacles.size(); ++o)
      problem.obstacles[o].friction = target_step.friction[o];
    StepRecord rec = step_record(target_step, step);
    if (observer.step_started) observer.step_started(step, rec.load_factor);
    // Sub-increments toward the target; a failure halves the increment.
    const LoadFactors from = current;
    double done = 0.0, increment = 1.0;
    int depth = 0;
    bool from_previous_force = false;  // after a failure from the extrapolated force
    // A plastic body's increment starts at rest where it can (below); after a failure there, the
    // increment again from the extrapolated state.
    bool rest_failed = false;
    // The fallback: where the increment's every attempt failed from the extrapolated state, its
    // attempts again with Newton from the last converged state (`chain`: where they began).
    bool from_converged = false;
    std::tuple<double, int, bool> chain{increment, depth, from_previous_force};
    // The last resort, after those failed too: the increment's attempts by ssn's semismooth Newton
    // from the last converged state (cev's default loop only); `cev_failed` says why cev stopped.
    bool by_ssn = false;
    std::string cev_failed;
    FailureKind cev_failure = FailureKind::none;
    const ContactParams ssn_params = semismooth(params.contact);
    LoadFactors probed;  // the last target whose friction limit was decided
    // After an update of the body's multipliers: the increment again from its converged state.
    std::optional<std::pair<Vector, Vector>> again;
    int updates = 0;  // of the multipliers in this increment
    while (true) {
      const double t = std::min(1.0, done + increment);
      const LoadFactors target = t == 1.0 ? target_step.factors : blend(from, target_step.factors, t);
      // Newton starts from the previous increment scaled to this one (section 9): a zero
      // guess would leave a membrane without transverse stiffness.
      const double last = distance(current, before);
      const double ratio =
          !start_q && last > 0 ? turn(before, current, target) * distance(target, current) / last : 0.0;
      const bool repeat = again.has_value();
      eq->set_step(target, zeta);
      // A path-dependent (plastic) body starts the increment at rest: the last converged state
      // under the last forces, where that still is an equilibrium at the target (only obstacles
      // moved: Equilibrium::at_rest), which cev takes without a real solve. The forces
      // extrapolated along the last increment are a secant's: where the body yields the
      // load-penetration curve is concave, and they are a dead load beyond what the body carries
      // (Prandtl's punch as a contact obstacle: Newton diverged under them in steps 2-6, each
      // retried from the last forces, 43 real solves where the linear elastic body takes 11).
      // Where the start at rest fails, the increment again from the extrapolated state.
      bool rest = false;
      if (path_dependent && !repeat && !start_q && !rest_failed && !from_converged && !by_ssn && extrapolate_forces &&
          params.contact.method == ContactMethod::cev) {
        couple_newton(eq->params(), newton_coupling_tolerance(params.contact), params.contact.newton_fraction,
                      problem.body->characteristic_length());
        rest = eq->at_rest(q, p).has_value();
      }
      const Vector guess = repeat                            ? again->first
                           : start_q                         ? *start_q
                           : rest                            ? q
                           : from_converged == extrapolate_q ? q
                                                             : Vector(q + (q - q_before) * ratio);
      // The contact forces start from the same extrapolation (the strategies bring it back
      // into the cone): a step then starts near its answer, not a whole increment away.
      const bool turned_back = path_dependent && ratio < 0;
      Vector p_guess = repeat ? again->second
                       : rest || from_previous_force || by_ssn || !extrapolate_forces || turned_back
                           ? p
                           : Vector(p + (p - p_before) * ratio);
      const bool extrapolated = !repeat && p_guess != p;
      again.reset();
      // Rigid amplitudes not extrapolated follow the supports: a pin left where it was turns a
      // held body about its moving supports (two cylinders under displacement control: the upper
      // one by delta / L at the start, a turn of the pairing that the linear model leaves out;
      // cev stalled at ||v|| = 2e-3).
      if (!extrapolated && !repeat && problem.rigid.count())
        p_guess.segment(problem.rigid.first, problem.rigid.count()) +=
            amplitudes_following_supports(problem, current, target);
      // A load that no static equilibrium can carry: no cut of the increment can help.
      if (Unreachable why = unreachable_equilibrium(problem, eq->evaluate(guess), target); !why.reason.empty()) {
        rec.reason = std::move(why.reason);
        rec.failure = why.kind;
        break;
      }
      // An obstacle that moves farther than the body's element size or its own radius in one
      // increment can pass through the body into a state that satisfies every contact condition.
      // Such an increment is cut into as many parts as the travel asks for, up to as many as
      // max_cuts halvings make: beyond, the step fails before any solve.
      StepChecks attempt;
      std::string too_far;
      auto check_start = Clock::now();
      const double travel = checker->increment(current, target, attempt, too_far);
      result.check_seconds += std::chrono::duration<double>(Clock::now() - check_start).count();
      if (const double parts = std::ceil(travel - 1e-9); !too_far.empty()) {
        if (parts * (1.0 / increment) > std::ldexp(1.0, params.max_cuts)) {
          rec.checks.worst_of(attempt);
          rec.failure = FailureKind::check_failed;
          rec.reason = "refused by the step checks: " + too_far + " (more than " +
                       std::to_string(1 << params.max_cuts) + " parts of the step would be needed)";
          break;
        }
        increment = (t - done) / parts;
        ++rec.cuts;
        continue;
      }
      const long moved = eq->counters().multiplier_updates;
      // From rest, cev's first update takes its linear model at the displacement extrapolated along
      // the last increment (the body's tangent there, yielding where the last increment yielded),
      // not at the rest state, whose points on the yield surface answer elastically (Prandtl's
      // punch: 30 real solves and 108 Newton iterations with the model at rest, 27 and 61).
      const Vector q_ext = rest && ratio > 0 ? Vector(q + (q - q_before) * ratio) : Vector();
      StepOutcome out = rest ? solve_cev_step(*eq, guess, p_guess, p, params.contact, step, observer.iteration,
                                              observer.stop_requested, v_first, true, q_ext.size() ? &q_ext : nullptr)
                             : solve_contact_step(*eq, guess, p_guess, p, by_ssn ? ssn_params : params.contact, step,
                                                  observer.iteration, observer.stop_requested, v_first);
      count_attempt(rec, out);
      rec.multiplier_updates += static_cast<int>(eq->counters().multiplier_updates - moved);
      bool refused = false;  // converged, but the step checks refused the state
      if (out.converged) {
        std::vector<OutsidePoint> outside;
        check_start = Clock::now();
        std::string why = checker->state(*eq, out.state, out.p, accepted, attempt, outside);
        result.check_seconds += std::chrono::duration<double>(Clock::now() - check_start).count();
        if (params.fail_outside_candidates) std::erase_if(outside, [](const OutsidePoint& o) { return !o.entered; });
        if (!outside.empty()) {
          const CandidateGrowth g =
              params.fail_outside_candidates ? CandidateGrowth{} : add_candidates_for(problem, outside);
          if (g.grew()) {
            // The same increment again with the new candidates, from the last accepted state.
            rec.notes.push_back(g.note);
            spent += eq->counters();
            eq = std::make_unique<Equilibrium>(problem, params.newton);
            p = grown_components(p, g, problem);
            p_before = grown_components(p_before, g, problem);
            zeta.resize(problem.candidates.size(), 0.0);
            eq->set_step(current, zeta);
            const EquilibriumState now = eq->evaluate(q);
            for (size_t i = g.old_candidates; i < problem.candidates.size(); ++i)
              zeta[i] = now.points[i].projection.zeta;
            accepted.p = grown_components(accepted.p, g, problem);
            for (size_t i = g.old_candidates; i < problem.candidates.size(); ++i)
              accepted.eta.push_back(now.points[i].eta);
            for (StepRecord& done_step : result.steps) grow_record(done_step, g, problem);
            grow_record(rec, g, problem);
            checker = std::make_unique<StepChecker>(problem, params.contact, params.contact_reach);
            continue;
          }
          std::string nodes;
          for (const OutsidePoint& o : outside)
            if (o.entered && nodes.size() < 200) nodes += (nodes.empty() ? "" : ", ") + std::to_string(o.node);
          if (!nodes.empty()) {
            rec.checks.worst_of(attempt);
            rec.failure = FailureKind::missed_contact;
            rec.reason = "nodes " + nodes + " entered an obstacle outside the contact candidates" +
                         (params.fail_outside_candidates ? " (solver.contact.outside_candidates: fail)" : "");
            break;
          }
        }
        if (!why.empty()) {
          rec.checks.worst_of(attempt);
          out.converged = false;
          out.reason = "refused by the step checks: " + why;
          out.failure = FailureKind::check_failed;
          refused = true;
        }
        if (!refused && observer.refuse_attempt && observer.refuse_attempt(step, done, t)) {
          out.converged = false;
          out.reason = "refused by the observer (a test's forced failure)";
          out.failure = FailureKind::check_failed;
          refused = true;
        }
        // Constraints held by multipliers (exact incompressibility): where they do not hold yet,
        // the multipliers moved, and the increment is solved again from this state.
        if (!refused)
          if (std::string off = problem.body->update_multipliers(out.state.q); !off.empty()) {
            if (updates < kMaxMultiplierUpdates) {
              ++updates;
              ++rec.multiplier_updates;
              again.emplace(out.state.q, out.p);
              continue;
            }
            out.converged = false;
            out.reason = "the body's constraint does not hold after " + std::to_string(updates) +
                         " updates of its multipliers: " + off;
            out.failure = FailureKind::newton_diverged;
            out.definitive = true;
            refused = true;  // no friction limit to probe: the contact solve converged
          }
      }
      if (!out.converged) {
        if (out.stopped) result.stopped = true;
        // A load beyond what friction holds (friction_limit.hpp): no retry or cut of the
        // increment can help. Before: a disc squeezed between two flats and turned beyond the
        // limit (33 x 33) cut its increment 5 times, 443 real solves. Decided for every strategy
        // on one run: cev's default loop from this attempt's start, whose every accepted state
        // lies on Coulomb's law, with a compliance formed afresh at its first state (not the one
        // the failed attempt, or cev's previous step, left: the same run whichever strategy came
        // before). ssn's iterates lie on Coulomb's law only once they converge, penalty's Newton
        // failed before it reached a state, and the bounds of the tau passes lag p, so they found
        // the limit late or not at all, each with its own ratio (1.064-1.078 for one scene); cev
        // default's own attempt, from the compliance of its previous step, stopped 1.3e-4 away
        // in the squeeze force. Run once a target (a retry from the previous force has the same
        // target); after cev default's own attempt only where that attempt shows the limit.
        if (!refused && !out.stopped && !by_ssn && problem.rigid.count() && target != probed &&
            (!is_coulomb_loop(params.contact) ||
             !friction_limit_exceeded(problem, out.state, out.p, out.tau, target).empty())) {
          probed = target;
          eq->refresh_compliance();
          StepOutcome decided = solve_contact_step(*eq, guess, p_guess, p, coulomb_loop(params.contact), step,
                                                   observer.iteration, observer.stop_requested, v_first);
          count_attempt(rec, decided);
          if (decided.stopped) {
            out.stopped = result.stopped = true;
            out.reason = decided.reason;
            out.failure = decided.failure;
          } else if (!decided.converged) {
            if (std::string why = friction_limit_exceeded(problem, decided.state, decided.p, decided.tau, target);
                !why.empty()) {
              rec.reason = std::move(why);
              rec.failure = FailureKind::friction_limit;
              rec.p = decided.p;
              rec.tau = decided.tau;
              rec.state = std::move(decided.state);
              break;
            }
          }
        }
        // An attempt that spent the step's budget of real solves ends the step with its reason:
        // no retry or cut (uzawa's fixed alpha on two cylinders spent 7 attempts of 500 real
        // solves, over 2 minutes a step; a halved increment starts its error only 2 x lower).
        const bool spent = out.budget_spent;
        // A failed start at rest is retried from the extrapolated state before the increment is
        // cut; a poor extrapolation (after the start-up step, or where contact changes) from the
        // previous force (not after a start at rest: it started there): a cut changes the load path.
        if (!out.stopped && !out.definitive && !spent && rest) {
          rest_failed = true;
          ++rec.restarts;
          rec.notes.push_back("the start at rest failed (" + out.reason +
                              "): the increment again from the extrapolated state");
          continue;
        }
        if (!out.stopped && !out.definitive && !spent && !from_previous_force && !rest_failed && extrapolated) {
          from_previous_force = true;
          ++rec.restarts;
          rec.notes.push_back("the start from the extrapolated forces failed (" + out.reason +
                              "): the increment again from the last forces");
          continue;
        }
        // Every attempt of the increment failed from the extrapolated state: they run again from
        // the last converged state, an equilibrium under the previous forces. The extrapolation
        // can fall on the near side of a limit point of the body under given contact forces,
        // where Newton falls away (the bulging block, docs/verification.md#bulging-block). Not
        // for a body without reference stiffness (a start-up): at a zero increment its tangent
        // is singular (the rigid-plastic sheet).
        // Past a limit load under load control (limit_load.hpp) neither fallback below can help:
        // no state carries the load.
        const std::string limit =
            depth >= params.max_cuts && !out.stopped && !spent &&
                    (out.failure == FailureKind::newton_diverged || out.failure == FailureKind::contact_stalled)
                ? along_load.beyond_limit(current, target)
                : std::string();
        if (depth >= params.max_cuts && !out.stopped && !out.definitive && !spent && !from_converged &&
            !problem.start && ratio != 0 && limit.empty()) {
          rec.notes.push_back("every attempt from the extrapolated state failed (" + out.reason +
                              "): the increment again from the last converged state");
          from_converged = true;
          std::tie(increment, depth, from_previous_force) = chain;
          continue;
        }
        // Those failed too: ssn's semismooth Newton from the last converged state, the increment's
        // attempts once more (its own cuts). Its Newton moves q and p together, the plate holding
        // the pressing points, where cev's solves under given (or held) forces pass a limit point
        // of the body's own (the filleted bulging block, docs/verification.md). Only here: inside
        // cev's attempts it would take over what a cut recovers (the beam on a cylinder), and
        // where cev converges nothing changes.
        if (depth >= params.max_cuts && !out.stopped && !out.definitive && !spent && from_converged && !by_ssn &&
            takes_semismooth_last_resort(params.contact) && limit.empty()) {
          cev_failed = out.reason + " (after " + std::to_string(depth) + " cuts of the increment)";
          cev_failure = out.failure;
          rec.notes.push_back("cev failed from the last converged state as well (" + cev_failed +
                              "): the increment by ssn's semismooth Newton from the last converged state");
          by_ssn = true;
          std::tie(increment, depth, from_previous_force) = chain;
          continue;
        }
        if (depth >= params.max_cuts || out.stopped || out.definitive || spent) {
          rec.failure = out.failure;
          rec.reason = out.reason;
          // A stop names its cause where the caller gives one (the service: a job limit, a dismissal).
          if (out.stopped && observer.stop_reason) std::tie(rec.failure, rec.reason) = observer.stop_reason();
          if (depth) rec.reason += " (after " + std::to_string(depth) + " cuts of the increment)";
          if (by_ssn && !out.stopped) {  // the step's kind is cev's, ssn's reason follows
            rec.reason = cev_failed +
                         ", from the last converged state as well; ssn's semismooth Newton from there: " + rec.reason;
            rec.failure = cev_failure;
          } else if (from_converged) {
            rec.reason += ", from the last converged state as well";
          }
          // Newton's drift past a limit load is no numerical accident: the step says so.
          if (!limit.empty() &&
              (rec.failure == FailureKind::newton_diverged || rec.failure == FailureKind::contact_stalled)) {
            rec.reason = limit + " (" + rec.reason + ")";
            rec.failure = FailureKind::no_equilibrium;
          }
          rec.p = out.p;
          rec.tau = out.tau;
          rec.state = std::move(out.state);
          break;
        }
        increment *= 0.5;
        ++depth;
        ++rec.cuts;
        rest_failed = false;
        continue;
      }
      if (t == 1.0) {
        rec.converged = true;
        rec.p = out.p;
        rec.tau = out.tau;
        rec.reactions = eq->reactions(out.state, out.p);
        rec.warning = problem.body->validity_warning(out.state.q);
        if (params.record_fields.empty() || params.record_fields[k]) {
          rec.site_fields = problem.body->site_fields(out.state.q);
          rec.element_fields = problem.body->element_fields(out.state.q);
        }
      }
      // Commit.
      rec.checks.worst_of(attempt);
      accepted = accepted_contact(out.state, out.p);
      along_load.committed(current, target, out.state.q - q);
      v_first = start_q || out.history.empty() ? 0.0 : out.history.front().v2;
      start_q.reset();
      q_before = q;
      p_before = p;
      before = current;
      q = out.state.q;
      p = out.p;
      current = target;
      done = t;
      zeta = eq->zetas(out.state);
      updates = 0;
      rest_failed = false;
      from_converged = false;
      by_ssn = false;
      chain = {increment, depth, from_previous_force};
      problem.body->commit(q);
      if (t == 1.0) {
        rec.state = std::move(out.state);
        break;
      }
    }
    rec.seconds = std::chrono::duration<double>(Clock::now() - step_start).count();
    const bool ok = rec.converged;
    if (!ok) {
      result.reason = "step " + std::to_string(step) + " failed: " + rec.reason;
      result.failure = rec.failure;
      result.failure_step = step;
    }
    if (observer.step_finished) observer.step_finished(rec);
    result.steps.push_back(std::move(rec));
    if (!ok) break;
  }
  result.completed = result.reason.empty();
  result.counters = eq->counters();
  result.counters += spent;
}

}  // namespace

RunResult run_load_steps(Problem& problem, const std::vector<LoadStep>& steps, const SteppingParams& params,
                         const SteppingObserver& observer) {
  const auto run_start = Clock::now();
  RunResult result;
  try {
    step_through(problem, steps, params, observer, result);
  } catch (const std::exception& e) {
    // An exception from the solver (out of memory) or from an observer fails the step it came
    // from, and the steps before are kept: grip solve still writes a whole result, and the
    // service stores them, instead of the process ending or the job losing its steps.
    const size_t k = result.steps.size();
    StepRecord rec = step_record(k < steps.size() ? steps[k] : LoadStep{}, static_cast<int>(k) + 1);
    rec.reason = std::string("solver error: ") + e.what();
    rec.failure = FailureKind::exception;
    result.reason = "step " + std::to_string(rec.index) + " failed: " + rec.reason;
    result.failure = FailureKind::exception;
    result.failure_step = rec.index;
    result.completed = false;
    result.steps.push_back(std::move(rec));
    if (observer.step_finished) observer.step_finished(result.steps.back());
  }
  result.seconds = std::chrono::duration<double>(Clock::now() - run_start).count();
  return result;
}

}  // namespace grip
