#include "solver/contact/step.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "solver/contact/acceleration.hpp"
#include "solver/contact/coulomb_model.hpp"
#include "solver/contact/friction_limit.hpp"
#include "solver/model/number_text.hpp"
#include "solver/problem/rigid_modes.hpp"

namespace grip {
namespace {

using Clock = std::chrono::steady_clock;

// Inexact real solves in cev's line search (an Eisenstat-Walker forcing term): a trial from a
// contact error v0 ends Newton once its correction is below this fraction of v0. Newton's
// residual test stays at the full precision: loosened too, it let the membrane sheet through
// at states whose error K^-1 r exceeded the contact error (the line search then found no
// decrease). A trial that ends the step is finished at the full precision, so a step ends on
// the same tests as with exact solves (the answers agree to what the contact tolerance pins
// them to). Newton iterations, paper's beam / sheet / sheet of 60 elements
// (bench/results/inexact_newton.md): exact 124 / 256 / 271; 0.01: 124 / 227 / 239; 0.05:
// 115 / 193 / 198; 0.1: 110 / 189 / 191, but the beam's kept G was then renewed 9 times
// instead of 6 and its run cost more instructions than with exact solves.
constexpr double kInexactNewton = 0.05;

// A held trial's moves of its springs' base forces (move_held): at most this many, until the
// springs stretch less than this fraction of the contact tolerance. J2Contact's plastic body
// took 19 real solves without them, 16 with them (its linear elastic body 15); on Prandtl's
// punch by contact a move left 1/3000 to 1/250 of the stretch while the block was stiff
// (bench/results/plasticity.md; near the limit load, with springs c / C_jj, more than half:
// cev.cpp's held_plan now makes them as stiff as their points with the others held).
constexpr int kHeldMoves = 4;
constexpr double kHeldStretch = 0.1;

// Newton iterations of the real solves after which a step that accepted no update since its
// last event emits one anyway (budget_left).
constexpr long kProgressNewton = 200;

// Accepted states over which a crawl of the contact error is measured (accept).
constexpr size_t kCrawlUpdates = 10;

// The round-off of a gap or slip, in units of eps x the size of the coordinates it is a
// difference of, per contact component (bound_at).
constexpr double kRoundOffGaps = 4.0;

// The gaps within which a candidate joins the linear model (relevant_components), in units of
// the body's length L: before the step has a gap change of its own (its first update, from the
// extrapolated start: on the 150 x 4 strip points 0.03 L away close within it), and the least
// once it has; and the multiple of a point's last gap change that it may move in the next
// update (the changes shrink from update to update where the loop converges).
constexpr double kFirstWindow = 0.05;
constexpr double kReachFloor = 1e-3;
constexpr double kReach = 3.0;

double inf_norm(const Matrix& A) { return A.size() ? A.cwiseAbs().rowwise().sum().maxCoeff() : 0.0; }

}  // namespace

std::vector<int> active_indices(const ContactError& e) {
  std::vector<int> idx;
  for (int i = 0; i < static_cast<int>(e.active.size()); ++i)
    if (e.active[i]) idx.push_back(i);
  return idx;
}

StepSolver::StepSolver(Equilibrium& eq, const ContactParams& params, int step, const IterationObserver& obs,
                       const StopRequest& stop)
    : eq_(eq), problem_(eq.problem()), params_(params), step_(step), observer_(obs), stop_(stop), start_(Clock::now()),
      newton_emitted_(eq.counters().newton_iterations) {
  tol_ = params.tolerance * problem_.body->characteristic_length();
  length_scales_ = problem_.body->dof_length_scales();
  strict_balance_ = rigid_modes_follow_state(problem_);
  is_normal_.assign(problem_.component_count, 0);
  for (const Candidate& c : problem_.candidates) is_normal_[c.eta] = 1;
}

StepOutcome StepSolver::run(const Vector& q_guess, const Vector& p_start, const Vector& p_star) {
  const double newton_tolerance = newton_coupling_tolerance(params_);
  couple_newton(eq_.params(), newton_tolerance, params_.newton_fraction, problem_.body->characteristic_length());
  // Newton's displacement test at the precision of the step's contact bound, from the guess's
  // displacement (the last state's, extrapolated) until a state is accepted (accept).
  const double guess_scale = displacement_size(q_guess);
  newton_floor_ = 10 * std::numeric_limits<double>::epsilon() * problem_.body->characteristic_length();
  if (guess_scale > 0)
    eq_.params().displacement_tolerance = std::max(
        params_.newton_fraction * newton_tolerance * std::min(guess_scale, problem_.body->characteristic_length()),
        newton_floor_);
  newton_base_ = eq_.params();
  eq_.set_compliance_reuse(params_.reuse_compliance && params_.method == ContactMethod::cev &&
                           params_.loop == ContactLoop::inner);
  eq_.set_indefinite_turning(params_.method == ContactMethod::cev && params_.loop == ContactLoop::inner &&
                             params_.friction_loop == FrictionLoop::inner);
  const long solves0 = eq_.counters().solves, newton0 = eq_.counters().newton_iterations;
  solves_at_start_ = solves0;
  solve(q_guess, p_start, p_star);
  out_.solves = static_cast<int>(eq_.counters().solves - solves0);
  // One count of contact iterations: the real solves, each reported in an event's trials. The
  // trials that a failure cut short before their update was accepted (a line search or an
  // alpha halving without a decrease, a stop) go in one closing event, at the state the
  // attempt ended on: a cut step's attempts and the job's limit count them as well.
  int reported = 0;
  for (const IterationEvent& ev : out_.history) reported += ev.trials;
  if (out_.solves > reported) {
    m_ = 0;  // no update: like a pass's starting solve, it is no step of the pass's descent
    emit(out_.solves - reported, 0, 0, 0, 0.0);
  }
  out_.newton_iterations = static_cast<int>(eq_.counters().newton_iterations - newton0 + own_newton_iterations_);
  out_.v2 = error_.norm2;
  out_.bound = tol_;
  out_.scale = scale_;
  out_.at_round_off = at_round_off_;
  return std::move(out_);
}

double StepSolver::displacement_size(const Vector& q) const {
  double d = 0.0;
  for (int j = 0; j < q.size() && j < length_scales_.size(); ++j) d = std::max(d, std::abs(q[j]) * length_scales_[j]);
  return d;
}

double StepSolver::coordinate_size(const EquilibriumState& s) const {
  double size = problem_.body->characteristic_length();
  for (const PairedPoint& pp : s.points)
    size = std::max({size, pp.point.x.cwiseAbs().maxCoeff(), pp.projection.point.cwiseAbs().maxCoeff(),
                     std::abs(pp.projection.zeta)});
  return size;
}

double StepSolver::bound_at(const EquilibriumState& s, double* scale, bool* round_off) const {
  const double L = problem_.body->characteristic_length();
  const double d = std::min(displacement_size(s.q), L);
  // The gaps and slips are differences of coordinates (the point's, its pairing's, the
  // surface coordinate zeta): each carries their rounding, eps x their size, whatever the
  // displacement. Never looser than tolerance x L, the bound before it moved with D.
  const double rounding = kRoundOffGaps * std::numeric_limits<double>::epsilon() * coordinate_size(s) *
                          std::sqrt(static_cast<double>(std::max(1, problem_.component_count)));
  const double relative = params_.tolerance * d;
  if (scale) *scale = d;
  if (round_off) *round_off = rounding > relative;
  return std::min(std::max(relative, rounding), ceiling());
}

double StepSolver::unbalance(const ContactError& e) const {
  double largest = 0.0;
  for (int k = 0; k < problem_.rigid.count(); ++k) largest = std::max(largest, std::abs(e.v[problem_.rigid.first + k]));
  return largest;
}

bool StepSolver::frictionless() const {
  for (const Candidate& c : problem_.candidates)
    if (c.xi >= 0) return false;
  return true;
}

void StepSolver::tau_passes(const Vector& q_guess, const Vector& p_start, const Vector& p_star_in,
                            const std::function<bool()>& pass) {
  // The passes start from the previous step's force, as the paper's loop does; a body turned by
  // finite rotations (rigid_modes_at) from the extrapolated one instead (p_start): a disc turned
  // between two flats (65 x 65 nodes, the couple raised from 0 to half what friction holds)
  // started at ||v|| 2.1e-4 from the previous force, unturned, and the linear model's step to
  // the turn (9e-4 rad), mispredicted by 7e-4 over that distance, was refused by the monotone
  // test at every length: the step failed after 5 cuts. From the extrapolated force it starts at
  // ||v|| 0.1, as cev's default loop does, and converges.
  out_.p = strict_balance_ ? p_start : p_star_in;
  Vector p_star = p_star_in;
  const bool no_friction = frictionless();
  for (int pass_index = 1; passes_to_budget_ || pass_index <= params_.max_tau_passes; ++pass_index) {
    pass_ = pass_index;
    out_.passes = pass_index;
    out_.tau = friction_bounds(problem_, p_star);
    accepted_errors_.clear();  // a crawl is measured within a pass: new bounds, a new error
    // Each pass restarts from one solve with p clipped to the new bounds (section 9); when
    // the clip changes nothing, the last accepted state is that solve already.
    const Vector unclipped = out_.p;
    clip_to_bounds(problem_, out_.tau, out_.p);
    if (pass_index > 1 && out_.p == unclipped) {
      accept(std::move(out_.state), unclipped);
      m_ = 0;
      emit(0, 0, 0, 0, 0.0);
    } else if (!fresh_solve(pass_index == 1 ? q_guess : out_.state.q) || (pass_index == 1 && !approach_contact())) {
      break;
    }
    if (pass_index == 1 && !no_friction && problem_.rigid.count() && !presses(p_star) && !bound_from_model(p_star))
      break;
    if (!pass()) break;
    if (no_friction) break;
    double change = 0.0, scale = 0.0;
    for (const Candidate& c : problem_.candidates) {
      change = std::max(change, std::abs(out_.p[c.eta] - p_star[c.eta]));
      scale = std::max(scale, std::abs(out_.p[c.eta]));
    }
    // ||v|| <= tol pins p only to about C_EE^-1 v_E: a change of p* below that is noise
    // (section 9: a tighter test makes p* cycle). The paper's literal loop and uzawa end a pass
    // as soon as ||v|| <= tol, where that is up to 8e-2 of a largest normal force of 11 (the free
    // beam on a flat): there a small change says only that the last pass stopped early, not
    // that p* settled, and accepting it left |p_t| = mu |p*| up to 4e-3 mu max |p_n| above
    // mu |p_n|. Their passes go on until p* settles to tau_tolerance; the accelerated loop then
    // pins the forces of its passes to that precision (literal_pass), uzawa's settle without
    // (within its budget, not max_tau_passes: uzawa.cpp).
    const double settled = params_.tau_tolerance * scale;
    if (change <= settled || (!literal_ && change <= force_precision())) {
      out_.converged = true;
      break;
    }
    if (literal_ && change <= force_precision()) pin_forces_ = 0.1 * settled;
    for (const Candidate& c : problem_.candidates) p_star[c.eta] = out_.p[c.eta];
    if (!passes_to_budget_ && pass_index == params_.max_tau_passes)
      fail(FailureKind::contact_budget,
           "the friction bound did not settle in " + std::to_string(pass_index) + " tau passes");
  }
  if (no_friction && out_.reason.empty()) out_.converged = true;
  if (out_.converged) final_check();
}

bool StepSolver::presses(const Vector& p) const {
  for (const Candidate& c : problem_.candidates)
    if (p[c.eta] < 0) return true;
  return false;
}

CoulombModelSolution StepSolver::solve_model(const Compliance& C, double target) const {
  CoulombModelParams mp;
  mp.target = target;
  mp.augmentation = params_.augmentation;
  mp.max_iterations = params_.max_inner_iterations;
  mp.max_halvings = params_.max_halvings;
  return solve_coulomb_model(problem_, C, out_.p, out_.state.s, out_.state.enabled, mp);
}

bool StepSolver::bound_from_model(Vector& p_star) {
  const Compliance& C = eq_.compliance(out_.state, relevant_components());
  const CoulombModelSolution model = solve_model(C, 0.1 * tol_);
  out_.inner_iterations += model.iterations;
  if (!presses(model.p))
    return fail(FailureKind::no_equilibrium, "the linear model at the step's first state presses no point");
  for (const Candidate& c : problem_.candidates) p_star[c.eta] = model.p[c.eta];
  out_.tau = friction_bounds(problem_, p_star);
  return true;
}

bool StepSolver::fresh_solve(const Vector& q, double v_scale) {
  if (!budget_left()) return false;
  if (at_rest_) {  // the step's first state: the last converged one, where only obstacles moved
    at_rest_ = false;
    if (std::optional<EquilibriumState> s = eq_.at_rest(q, out_.p)) {
      accept(std::move(*s), out_.p);
      m_ = 0;
      emit(0, 0, 0, 0, 0.0);
      return true;
    }
  }
  const bool loose = loosen_newton(v_scale);
  EquilibriumState s = eq_.solve(q, out_.p);
  tighten_newton();
  if (!s.converged) return fail(s.failure, "equilibrium solve failed: " + s.reason);
  if (loose) {
    // v_scale was another state's error. Newton is finished to the precision this state's
    // error asks for where that one is within the tolerance (the full precision), or far below
    // v_scale (a line-search trial ends at a correction of kInexactNewton x the error its update
    // starts from, 30-1000x the error it reaches: up to 10x is as loose as that).
    const double v = error_at(out_.p, s.s, s.enabled).norm2, bound = bound_at(s);
    if (v <= bound || v < 0.1 * v_scale) {
      if (v > bound) loosen_newton(v);
      eq_.continue_solve(s, out_.p);
      tighten_newton();
      if (!s.converged) return fail(s.failure, "equilibrium solve failed: " + s.reason);
    }
  }
  accept(std::move(s), out_.p);
  m_ = 0;
  emit(1, 0, 0, 0, 0.0);
  return true;
}

// How contact point i's gap (eta) and slip (xi) change along rigid mode k.
Vec2 StepSolver::mode_rates(size_t i, int k) const {
  const PairedPoint& pp = out_.state.points[i];
  Vec2 rates = Vec2::Zero();
  for (const auto& j : pp.point.jacobian) {
    rates[0] += j.dx.dot(pp.eta) * problem_.rigid.modes(j.dof, k);
    rates[1] += j.dx.dot(pp.xi) * problem_.rigid.modes(j.dof, k);
  }
  return rates;
}

// Some pressing point resists rigid mode k: across its obstacle, or along it with friction.
bool StepSolver::mode_held(int k) const {
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    if (out_.p[c.eta] >= 0) continue;
    const Vec2 rates = mode_rates(i, k);
    const bool frictional = c.xi >= 0 && problem_.obstacles[c.obstacle].friction > 0;
    if (std::abs(rates[0]) > 1e-12 || (frictional && std::abs(rates[1]) > 1e-12)) return true;
  }
  return false;
}

bool StepSolver::approach_contact() {
  Vector dq;
  if (!approach_motion(dq)) return true;
  return fresh_solve(Vector(out_.state.q + dq));
}

bool StepSolver::approach_motion(Vector& dq) {
  const RigidModes& rigid = problem_.rigid;
  Vector p = out_.p;
  dq = Vector::Zero(out_.state.q.size());
  bool moved = false;
  for (int k = 0; k < rigid.count(); ++k) {
    const double push = out_.state.s[rigid.first + k];
    if (push == 0.0 || mode_held(k)) continue;
    double reach = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const double along = mode_rates(i, k)[0];
      if (along * push > 1e-12 * std::abs(push))
        reach = std::min(reach, std::max(0.0, -out_.state.s[problem_.candidates[i].eta]) / std::abs(along));
    }
    if (!std::isfinite(reach)) continue;
    const double move = (push > 0 ? 1.0 : -1.0) * (reach + tol_);
    p[rigid.first + k] += move / rigid.scale;
    dq += move * rigid.modes.col(k);
    moved = true;
  }
  out_.p = p;
  return moved;
}

void StepSolver::accept(EquilibriumState s, const Vector& p) {
  if (out_.state.s.size() == s.s.size()) s_before_ = std::move(out_.state.s);
  out_.state = std::move(s);
  out_.p = p;
  tol_ = bound_at(out_.state, &scale_, &at_round_off_);
  // A correction below the rounding of the positions (10 eps x their size) is noise: Newton's
  // correction test no tighter (a strip with finite kinematics under loads x 1e-6 otherwise
  // ran its 40 iterations at that floor, which its residual test does not see).
  newton_floor_ = 10 * std::numeric_limits<double>::epsilon() * coordinate_size(out_.state);
  newton_base_.displacement_tolerance = std::max(params_.newton_fraction * tol_, newton_floor_);
  eq_.params().displacement_tolerance = newton_base_.displacement_tolerance;
  if (coulomb_) out_.tau = friction_bounds(problem_, p);
  error_ = error_at(out_.p, out_.state.s, out_.state.enabled);
  if (problem_.rigid.count()) {
    // A body held by contact balances its loads to the tolerance of the size of the forces (the
    // sum of the load's and the contact forces' magnitudes), in the amplitudes' unit
    // (s = scale R^T (F + T p)), whatever its displacement: its rows in ||v|| are a length, and
    // under loads small against its stiffness (E x 1e6) the step's starting forces were within
    // tolerance x length while 28 % out of balance. Where its free motions follow its state
    // (finite kinematics) the linear model's rows are not exact: Newton's share of it there.
    double size = problem_.load(eq_.factors()).cwiseAbs().sum();
    for (const Candidate& c : problem_.candidates) size += std::hypot(p[c.eta], c.xi >= 0 ? p[c.xi] : 0.0);
    balance_tol_ = problem_.rigid.scale * (strict_balance_ ? params_.newton_fraction : 1.0) * params_.tolerance * size;
  }
  // A crawl: over the last kCrawlUpdates accepted states ||v|| fell at a rate that reaches its
  // bound only far beyond the budget left (4 x). Such an attempt ends at the next budget check:
  // spending the budget only delays the cut. Only for cev's default loop and ssn, whose updates
  // converge superlinearly where they converge (uzawa is linear by design; the paper's loop and
  // the tau passes legitimately take long stretches: LinearBeamCheck's paper counts). (A plastic block
  // pressed by a load onto a rigid punch past its limit: ||v|| 8.87e-5 -> 8.84e-5 in 2 updates of
  // 3 s each, the bound 4e-10; before, each attempt spent its 500 real solves, 835 s in all.)
  const auto crawl_watched = [this] {
    return params_.method == ContactMethod::ssn ||
           (params_.method == ContactMethod::cev && params_.loop == ContactLoop::inner &&
            params_.friction_loop == FrictionLoop::inner);
  };
  accepted_errors_.push_back(error_.norm2);
  if (const size_t n = accepted_errors_.size();
      crawl_watched() && n > kCrawlUpdates && !error_met(error_) && error_.norm2 > tol_) {
    const double from = accepted_errors_[n - 1 - kCrawlUpdates];
    const double rate = std::pow(error_.norm2 / from, 1.0 / kCrawlUpdates);
    const long left = solves_at_start_ + params_.max_iterations - eq_.counters().solves;
    const double needed = rate < 1 ? std::log(tol_ / error_.norm2) / std::log(rate) : HUGE_VAL;
    if (needed > 4.0 * static_cast<double>(left))
      crawl_ = "contact error " + number_text(error_.norm2) + " above its bound " + number_text(tol_) +
               ": it fell from " + number_text(from) + " over the last " + std::to_string(kCrawlUpdates) +
               " updates, a rate that needs about " + (needed < 1e9 ? number_text(std::round(needed)) : "unbounded") +
               " more against the " + std::to_string(left) + " contact iterations left";
  }
  // A load beyond what friction holds (friction_limit.hpp), shown at two accepted states in a
  // row, ends the step at the next budget check: the paper's loop otherwise spends its whole
  // budget turning a disc about its squeezed shape (500 real solves, 26 s of CPU on 33 x 33).
  if (problem_.rigid.count() && !error_met(error_)) {
    std::string why = friction_limit_exceeded(problem_, out_.state, out_.p, out_.tau, eq_.factors());
    if (why.empty()) beyond_friction_ = 0;
    else if (++beyond_friction_ >= 2) friction_limit_ = std::move(why);
  }
}

bool StepSolver::fail(FailureKind kind, std::string reason) {
  out_.converged = false;
  if (out_.reason.empty()) {
    out_.reason = std::move(reason);
    out_.failure = kind;
  }
  return false;
}

bool StepSolver::budget_left() {
  if (stop_ && stop_()) {
    out_.stopped = true;
    return fail(FailureKind::stopped, "stopped on request");
  }
  if (!friction_limit_.empty()) return fail(FailureKind::friction_limit, friction_limit_);
  if (!crawl_.empty()) return fail(FailureKind::contact_stalled, crawl_);
  // A long stretch of rejected trials (halvings of alpha, a line search) still reports: an
  // event with no new update (trials 0, the accepted state's error), so that no step runs
  // thousands of Newton iterations in silence (two cylinders with uzawa: 7,000 in 118 s).
  if (eq_.counters().newton_iterations - newton_emitted_ >= kProgressNewton) emit(0, 0, 0, 0, 0.0);
  if (eq_.counters().solves < solves_at_start_ + params_.max_iterations) return true;
  // uzawa's spent budget ends the step (load_stepping.cpp); the others' budgets are cut as any
  // other failure (cev with max_iterations 4 on the beam gets through its steps by cuts).
  out_.budget_spent = params_.method == ContactMethod::uzawa;
  if (error_met(error_))  // what is left is the tau passes' p*
    return fail(FailureKind::contact_budget, "the friction bound did not settle in " +
                                                 std::to_string(params_.max_iterations) + " contact iterations (" +
                                                 std::to_string(pass_) + " tau passes; ||v|| within the tolerance)");
  std::string why = "contact error " + number_text(error_.norm2) + " above its bound " + number_text(tol_) + " after " +
                    std::to_string(params_.max_iterations) + " contact iterations";
  if (out_.budget_spent) why += " (uzawa converges linearly: raise solver.contact.max_iterations or use method cev)";
  return fail(FailureKind::contact_budget, why);
}

bool StepSolver::line_search(const Vector& pl, const Vector& du, int& trials, const HeldPlan* held) {
  const Vector p0 = out_.p;
  const double v0 = error_.norm2;
  // A held trial that left the cone is solved once more with the points that left it let go
  // (released_from_cone); the update's later trials keep them let go.
  HeldPlan plan;
  if (held) held = &(plan = *held);
  std::vector<int> let_go;
  bool let_go_once = false;
  // A held trial carries p(q) = pbar + k (target - s(q)) with k_j = c / C_jj: Newton's last
  // correction dq moves p by k dq, and the pair (p(q), s(q)) it leaves is consistent to about
  // (1 + c) times Newton's correction test, not to that test as under given forces. Its test is
  // that much tighter, so that the trial's contact error is the held solve's and not Newton's
  // (hertz-t6's plastic body at c = 100, its first release step: with the given forces' test a
  // trial left 2.3e-5 as ||v||, the next update's trials found 2.0e-4 at every length down to
  // 1/1024 of it, and the step was cut: 19 real solves; with this test, 3).
  newton_amplification_ = held ? 1.0 + params_.held_stiffness : 1.0;
  struct Restore {
    StepSolver& s;
    ~Restore() {
      s.newton_amplification_ = 1.0;
      s.tighten_newton();
    }
  } restore{*this};
  for (int h = 0; h <= params_.line_search_steps; ++h) {
    if (!budget_left()) return false;
    const double f = std::ldexp(1.0, -h);
    Vector pt = h == 0 ? pl : Vector(p0 + f * (pl - p0));
    for (int j : let_go) pt[j] = 0.0;
    ++trials;
    if (held) {
      HeldContact law = held->law;
      law.target = held->s + f * held->ds;
      eq_.set_held(std::move(law));
    }
    // The forces the trial carried: pt, or the held law's at its state.
    const auto sound = [&](const EquilibriumState& t) {
      return t.converged && (!held || held_admissible(held->law, t.p));
    };
    const bool loose = loosen_newton(v0);
    EquilibriumState trial = eq_.solve(out_.state.q + f * du, pt);
    if (held) move_held(trial, pt, held->s + f * held->ds, held->law.stiffness);
    tighten_newton();
    bool ok = sound(trial);  // a diverging trial is a failed trial: halve
    if (held && trial.converged && !ok && !let_go_once) {
      let_go_once = true;
      released_from_cone(plan, trial.p, let_go);
      eq_.set_held(std::nullopt);
      --h;  // the same trial length again
      continue;
    }
    ContactError e;
    if (ok) e = error_at(held ? trial.p : pt, trial.s, trial.enabled);
    // A loose trial that ends the step is finished at the full precision (no solve counted:
    // the same solve continued), and judged there. After an update on the exact linear model
    // (the compliance with the turning contact forces' stiffness), a trial far below v0 is
    // finished to the precision of its own error, as the step's first solve is: the next
    // update's model is taken at it (the 150 x 4 strip on a cylinder: 99 real solves and 254
    // Newton iterations without, 77 and 219 with; without that model it saved no solve and
    // cost Newton iterations: bench/results/kernels.md).
    const bool settle =
        ok && loose && improves(e, v0) && e.norm2 > tol_ && e.norm2 < 0.1 * v0 && eq_.compliance_turns();
    if (ok && loose && improves(e, v0) && (e.norm2 <= tol_ || settle)) {
      if (settle) loosen_newton(e.norm2);
      eq_.continue_solve(trial, pt);
      tighten_newton();
      ok = sound(trial);
      if (ok) e = error_at(held ? trial.p : pt, trial.s, trial.enabled);
    }
    if (held) eq_.set_held(std::nullopt);
    if (ok && improves(e, v0)) {
      const Vector carried = held ? trial.p : pt;
      accept(std::move(trial), carried);
      return true;
    }
  }
  if (reached_precision()) return true;
  return fail(FailureKind::contact_stalled,
              "no decrease of the contact error along the predicted force change (||v|| = " + number_text(v0) + ")");
}

// A held trial's springs leave about 1 / (1 + c) of the model's misprediction at the points they
// hold (their stiffness c times each point's own, cev.cpp's held_plan). Their base forces are moved to the forces they carry and Newton
// goes on, chords from its last factorization first (Equilibrium::continue_held), until they
// stretch less than a tenth of the contact tolerance: the trial then holds those points at the
// model's kinematics and the update is the exact one for the active set the model predicted
// (an augmented Lagrangian inside the real solve; docs/algorithm.md#the-held-real-solve). A move
// that fails leaves the trial as it was before it.
void StepSolver::move_held(EquilibriumState& trial, Vector& base, const Vector& target, const Vector& stiffness) {
  for (int k = 0; k < kHeldMoves && trial.converged; ++k) {
    double stretch = 0.0;
    for (int j = 0; j < target.size(); ++j)
      if (stiffness[j] > 0) stretch = std::max(stretch, std::abs(target[j] - trial.s[j]));
    if (stretch <= kHeldStretch * tol_) return;
    EquilibriumState moved = trial;
    const Vector carried = trial.p;
    eq_.continue_held(moved, carried);
    if (!moved.converged) return;
    trial = std::move(moved);
    base = carried;
  }
}

void StepSolver::released_from_cone(HeldPlan& plan, const Vector& carried, std::vector<int>& let_go) const {
  HeldContact& law = plan.law;
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    const bool held_xi = c.xi >= 0 && law.stiffness[c.xi] > 0;
    if (law.stiffness[c.eta] > 0 && carried[c.eta] > 0) {
      // Pulled: no longer held, its force the given zero (across and along).
      law.stiffness[c.eta] = 0.0;
      let_go.push_back(c.eta);
      if (c.xi >= 0) {
        law.stiffness[c.xi] = 0.0;
        law.slip[i] = 0;
        let_go.push_back(c.xi);
      }
    } else if (held_xi &&
               std::abs(carried[c.xi]) > problem_.obstacles[c.obstacle].friction * -carried[c.eta] * (1 + 1e-9)) {
      // Stuck beyond its bound: it slips the way its force pointed.
      law.stiffness[c.xi] = 0.0;
      law.slip[i] = carried[c.xi] > 0 ? 1 : -1;
    }
  }
}

bool StepSolver::held_admissible(const HeldContact& law, const Vector& p) const {
  for (const Candidate& c : problem_.candidates) {
    if (law.stiffness[c.eta] > 0 && p[c.eta] > 0) return false;
    if (c.xi >= 0 && law.stiffness[c.xi] > 0 &&
        std::abs(p[c.xi]) > problem_.obstacles[c.obstacle].friction * -p[c.eta] * (1 + 1e-9))
      return false;
  }
  return true;
}

bool StepSolver::reached_precision() {
  if (error_.norm2 > ceiling() || unbalance(error_) > balance_tol_) return false;
  tol_ = error_.norm2;
  at_round_off_ = true;
  return true;
}

bool StepSolver::loosen_newton(double v_ref) {
  const double loose = kInexactNewton * v_ref / newton_amplification_;
  tighten_newton();
  if (!(loose > eq_.params().displacement_tolerance)) return false;
  eq_.params().displacement_tolerance = loose;
  return true;
}

void StepSolver::tighten_newton() {
  eq_.params().displacement_tolerance =
      newton_amplification_ == 1.0
          ? newton_base_.displacement_tolerance
          : std::max(newton_base_.displacement_tolerance / newton_amplification_, newton_floor_);
}

Direction StepSolver::direction(const Compliance& C, const ContactError& err, int level, double alpha_fixed) {
  if (C.bordered) return bordered_direction(C, err, level, alpha_fixed);
  Direction dir;
  const std::vector<int> idx = active_indices(err);
  dir.d = Vector::Zero(err.v.size());
  if (idx.empty()) return dir;
  const Matrix Cee = C.sub(idx);
  Vector v_e(idx.size());
  for (size_t a = 0; a < idx.size(); ++a) v_e[a] = err.v[idx[a]];
  const double norm = inf_norm(Cee);
  if (!(norm > 0)) return dir;
  Vector d_e;
  if (level == kAccelerationInfinity) {
    Eigen::LLT<Matrix> llt(Cee);
    if (llt.info() != Eigen::Success) return dir;
    d_e = llt.solve(v_e);
    dir.alpha = 1.0;
    dir.n = 0;
  } else {
    const Matrix C1 = Cee / norm;
    if (alpha_fixed > 0) {  // uzawa, or the eq. 30 warm-up
      d_e = alpha_fixed * v_e / norm;
      dir.alpha = alpha_fixed;
      dir.n = 1;
    } else {
      double eps1;
      if (params_.epsilon == EpsilonSource::warmup && warmup_eps_ > 0) {
        out_.epsilon_used = "warmup";
        eps1 = std::min(1.0, warmup_eps_);
      } else {
        out_.epsilon_used = "exact";
        eps1 = smallest_eigenvalue(C1);
      }
      const int n = level == kAccelerationAuto ? auto_level(eps1) : level;
      const AcceleratedStep step = accelerate(C1, eps1, n);
      d_e = step.step_matrix * v_e / norm;
      dir.alpha = step.alpha;
      dir.n = n;
    }
  }
  for (size_t a = 0; a < idx.size(); ++a) dir.d[idx[a]] = d_e[a];
  dir.ok = d_e.allFinite();
  return dir;
}

bool StepSolver::literal_pass(int first_level, double alpha_fixed) {
  literal_ = true;
  // After a pass whose p* test was within its own force precision (tau_passes), the
  // accelerated loop goes on past ||v|| <= tol until its normal forces are pinned to the
  // precision the test asks (StepSolver::force_precision): stopped at ||v|| <= tol, each pass
  // of n = 3 moved p_n by 1e-3 towards its Tresca answer 2e-2 away and p* crept for 30 passes.
  // uzawa's fixed step would need ~17000 more solves for that (0.9996 a solve on the beam).
  const bool pin = pin_forces_ > 0 && alpha_fixed <= 0;
  while (!error_met(error_) || (pin && force_precision() > pin_forces_)) {
    if (!budget_left()) return false;
    int level = first_level;  // each update starts at the chosen n
    const Compliance& C = eq_.compliance(out_.state, relevant_components());
    const double v0 = error_.norm2;
    const ContactError e = error_;
    int trials = 0, halvings = 0;
    double a = 1.0;
    while (true) {
      Vector pbar, asked;
      const Direction dir = held_direction(C, e, level, alpha_fixed, a, pbar, asked);
      if (!dir.ok)
        return fail(FailureKind::contact_stalled, "the active block of the compliance is not positive definite");
      if (!budget_left()) return false;
      const Vector pt = project(C, out_.p, pbar, e, out_.tau, &asked);
      ++trials;
      EquilibriumState trial = eq_.solve(out_.state.q, pt);
      if (trial.converged) {
        const ContactError et = error_at(pt, trial.s, trial.enabled);
        if (improves(et, v0)) {
          accept(std::move(trial), pt);
          ++m_;
          emit(trials, 0, halvings, dir.n, dir.alpha * a);
          break;
        }
      }
      a *= 0.5;
      ++halvings;
      if (halvings % params_.halvings_before_fallback == 0 && level > 1) {
        --level;  // fall back to a smaller n, with a fresh alpha
        a = 1.0;
      }
      if (halvings > params_.max_halvings && reached_precision()) return true;
      if (halvings > params_.max_halvings)
        return fail(FailureKind::contact_stalled, "alpha halved " + std::to_string(params_.max_halvings) +
                                                      " times without a decrease of the contact error");
    }
  }
  return true;
}

Direction StepSolver::held_direction(const Compliance& C, const ContactError& e, int level, double alpha_fixed,
                                     double a, Vector& pbar, Vector& asked) {
  ContactError moving = e;
  pbar = out_.p;
  asked = out_.p;
  for (;;) {
    const Direction dir = direction(C, moving, level, alpha_fixed);
    if (!dir.ok) return dir;
    bool held = false;
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const Candidate& c = problem_.candidates[i];
      // The trial p - a d leaves the bound: the projection puts the force on it (keeps it there,
      // if it is on it already), whatever the others' step assumed.
      if (moving.active[c.eta] && (out_.p[c.eta] == 0.0 || level != kAccelerationInfinity) &&
          out_.p[c.eta] - a * dir.d[c.eta] > 0) {
        moving.active[c.eta] = 0;
        pbar[c.eta] = 0.0;
        held = true;
      }
      if (c.xi >= 0 && moving.active[c.xi]) {
        const double t = out_.p[c.xi] - a * dir.d[c.xi];
        const bool on_bound = std::abs(out_.p[c.xi]) >= out_.tau[i] * (1 - kBoundTolerance);
        // n = infinity keeps the held force where it is (its exact step moved to the bound broke
        // the equilibrium rows by 2e-7 of the load on the free beam; not traced).
        const bool crossing = level != kAccelerationInfinity && std::abs(t) > out_.tau[i];
        if (out_.p[c.xi] * dir.d[c.xi] < 0 && (on_bound || crossing)) {
          moving.active[c.xi] = 0;
          pbar[c.xi] = on_bound ? out_.p[c.xi] : std::copysign(out_.tau[i], t);
          held = true;
        }
      }
    }
    if (!held) {
      for (int j = 0; j < static_cast<int>(pbar.size()); ++j)
        if (moving.active[j] || !e.active[j]) asked[j] = pbar[j] = out_.p[j] - a * dir.d[j];
      return dir;
    }
  }
}

// Every component with a force or a friction bound, the rigid amplitudes, and those of
// candidates that may close in the coming update: penetrating, or with a gap within
// max(kReachFloor x L, kReach x the gap's change over the last update) once the step has
// accepted two states, within kFirstWindow x L before. The others are frozen (a point that the
// real solve brings into contact anyway penetrates there, and joins at the next update).
std::vector<int> StepSolver::relevant_components() const {
  const double L = problem_.body->characteristic_length();
  const Vector& s = out_.state.s;
  const bool moved = s_before_.size() == s.size();
  std::vector<int> out;
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    if (!out_.state.enabled[c.eta]) continue;
    const double reach =
        moved ? std::max(kReachFloor * L, kReach * std::abs(s[c.eta] - s_before_[c.eta])) : kFirstWindow * L;
    const bool near = out_.p[c.eta] < 0 || out_.tau[i] > 0 || s[c.eta] > -reach;
    if (!near) continue;
    out.push_back(c.eta);
    if (c.xi >= 0 && out_.state.enabled[c.xi]) out.push_back(c.xi);
  }
  for (int k = 0; k < problem_.rigid.count(); ++k) out.push_back(problem_.rigid.first + k);
  return out;
}

double StepSolver::force_precision() {
  if (error_.norm2 == 0.0) return 0.0;
  const std::vector<int> idx = active_indices(error_);
  const Compliance& C = eq_.compliance(out_.state, idx);
  if (C.bordered) {  // a body held by contact: the bordered system's solution
    const Vector dp = bordered_direction(C, error_, kAccelerationInfinity, 0.0).d;
    double largest = 0.0;
    for (int j : idx)
      if (is_normal_[j]) largest = std::max(largest, std::abs(dp[j]));
    return largest;
  }
  Vector v_e(idx.size());
  for (size_t a = 0; a < idx.size(); ++a) v_e[a] = error_.v[idx[a]];
  Eigen::LLT<Matrix> llt(C.sub(idx));
  if (llt.info() != Eigen::Success) return 0.0;
  const Vector dp = llt.solve(v_e);
  double largest = 0.0;
  for (size_t a = 0; a < idx.size(); ++a)
    if (is_normal_[idx[a]]) largest = std::max(largest, std::abs(dp[a]));
  return largest;
}

void StepSolver::final_check() {
  if (error_.norm2 > tol_) {
    fail(FailureKind::contact_stalled, "contact error above tolerance at the end of the step");
    return;
  }
  if (!error_met(error_)) {
    fail(FailureKind::contact_stalled,
         "the load and the contact forces do not balance on the body's free motions to the tolerance at the end of "
         "the step");
    return;
  }
  // A free motion that no pressing point resists has no determined amplitude
  // (docs/algorithm.md#bodies-held-only-by-contact).
  for (int k = 0; k < problem_.rigid.count(); ++k)
    if (!mode_held(k))
      fail(FailureKind::no_equilibrium,
           "no contact holds the body's free motion (" + problem_.rigid.names[k] +
               "): no point presses against an obstacle in that direction, so its position is not determined; "
               "no static equilibrium fixes it");
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    if (out_.p[c.eta] > 0) fail(FailureKind::contact_stalled, "a normal contact force pulls");
    if (c.xi >= 0 && std::abs(out_.p[c.xi]) > out_.tau[i] * (1 + 1e-9) + 1e-300)
      fail(FailureKind::contact_stalled, "a friction force exceeds its Coulomb bound");
  }
}

void StepSolver::emit(int trials, int inner, int halvings, int n, double alpha, int own_newton) {
  IterationEvent ev;
  ev.step = step_;
  ev.pass = std::max(pass_, 1);  // 1 also for a closing event before the first pass began
  ev.m = m_;
  ev.trials = trials;
  ev.inner_iterations = inner;
  ev.halvings = halvings;
  ev.n = n;
  ev.alpha = alpha;
  ev.v2 = error_.norm2;
  ev.v_inf = error_.norm_inf;
  const bool forces =
      out_.p.size() == problem_.component_count && static_cast<size_t>(out_.tau.size()) == problem_.candidates.size();
  for (size_t i = 0; forces && i < problem_.candidates.size(); ++i) {
    switch (contact_state(problem_, i, out_.p, out_.tau)) {
      case ContactState::open:
        ++ev.open;
        break;
      case ContactState::stick:
        ++ev.stick;
        break;
      case ContactState::slip:
        ++ev.slip;
        break;
    }
  }
  // Every Newton iteration since the last event, rejected line-search trials' included, so
  // that the events of a step add up to its count (plus those made outside the oracle: ssn).
  ev.newton_iterations = static_cast<int>(eq_.counters().newton_iterations - newton_emitted_) + own_newton;
  newton_emitted_ = eq_.counters().newton_iterations;
  ev.elapsed_ms = std::chrono::duration<double, std::milli>(Clock::now() - start_).count();
  out_.history.push_back(ev);
  if (observer_) observer_(ev);
}

}  // namespace grip
