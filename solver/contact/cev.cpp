// Strategy `cev`: the contact error vector scheme. Default: each iteration solves the
// contact conditions with Coulomb's cone on the linear model s(p) = s + C (p - p0)
// (coulomb_model.hpp), then makes one real solve at the prediction with its line search; the
// friction bound moves with p_eta, so there are no tau passes. Options: the tau passes of
// eq. 14 around the same inner loop with eq. 13 on the model (`friction_loop: passes`,
// docs/algorithm.md#friction_loop-passes-the-tau-passes), or around the paper's literal loop
// (`loop: paper`).
#include <optional>

#include <Eigen/LU>

#include "solver/contact/acceleration.hpp"
#include "solver/contact/coulomb_model.hpp"
#include "solver/contact/step.hpp"

namespace grip {
namespace {

// A compliance from an earlier state (ContactParams::reuse_compliance) whose update lowered
// the real contact error by less than this factor is formed afresh for the next update
// (beam: 0.1 renewed too rarely, 61 -> 81 real solves; 0.01 too often, 6 -> 12 forms).
constexpr double kStaleContraction = 0.03;

class CevStep : public StepSolver {
 public:
  CevStep(Equilibrium& eq, const ContactParams& params, int step, const IterationObserver& obs, const StopRequest& stop,
          double v_previous, bool at_rest, const Vector* model_at)
      : StepSolver(eq, params, step, obs, stop), v_previous_(v_previous) {
    at_rest_ = at_rest;
    if (model_at) model_q_ = *model_at;
  }

 private:
  void solve(const Vector& q_guess, const Vector& p_start, const Vector& p_star) override {
    if (params_.loop == ContactLoop::inner && params_.friction_loop == FrictionLoop::inner)
      return coulomb_loop(q_guess, p_start);
    tau_passes(q_guess, p_start, p_star, [this] {
      if (needs_warmup() && !warmup()) return false;
      return params_.loop == ContactLoop::paper ? literal_pass(params_.acceleration, 0.0) : inner_pass();
    });
  }

  // The default: Coulomb's law on the linear model, one real solve per iteration.
  void coulomb_loop(const Vector& q_guess, const Vector& p_start) {
    coulomb_ = true;
    pass_ = out_.passes = 1;
    out_.p = p_start;
    project_to_cone(problem_, out_.p);
    const bool rested = at_rest_;
    if (!fresh_solve(q_guess, v_previous_) || !approach_contact()) return;
    if (!rested || eq_.counters().solves != solves_at_start_) model_q_.reset();
    while (!error_met(error_)) {
      if (!budget_left()) return;
      // Held solves leave no factorization of the body's own tangent (their springs are in
      // Newton's): its G is formed afresh at each update, where a solve under given forces hands
      // over its own (J2Contact: 46 real solves with the kept G, 24 fresh).
      if (held() || model_q_) eq_.refresh_compliance();
      EquilibriumState model_state;
      if (model_q_) model_state = eq_.evaluate(*model_q_);
      const Compliance& C =
          eq_.compliance(model_q_ ? model_state : out_.state, relevant_components(), params_.sparse_compliance_from);
      model_q_.reset();
      int inner = 0, halvings = 0;
      const Vector pl = predict_coulomb(C, inner, halvings);
      out_.inner_iterations += inner;
      const Vector du = eq_.predicted_change(C, pl - out_.p);
      int trials = 0;
      const std::optional<HeldPlan> held = held_plan(C, pl);
      const Update u = real_update(pl, du, trials, held ? &*held : nullptr);
      if (u == Update::failed) return;
      if (u == Update::retry) continue;
      ++m_;
      emit(trials, inner, halvings, 0, 1.0);
    }
    out_.converged = true;
    final_check();
  }

  // The semismooth Newton on the model; where it stalls, tau passes on the model (Tresca
  // problems solved by eq. 13 on the model, the bound updated from the model's p_eta).
  Vector predict_coulomb(const Compliance& C, int& inner, int& halvings) {
    const double target = model_target();
    const CoulombModelSolution sol = solve_model(C, target);
    inner = sol.iterations;
    halvings = sol.halvings;
    if (sol.converged) return sol.p;
    // A model that stalled within a tenth of the step's bound has done what the step needs: its
    // target's other term, 1e-6 x the error now, lies below the model's own rounding where the
    // step's bound is at the round-off of the gaps (the 2000-element beam on a flat, mu 0.3: step
    // 2 starts at ||v|| 7.7e-13 against its bound 6.7e-13, the model stalls at 2.8e-17 against a
    // target of 7.7e-19), and the tau passes below then factorize C's active block (4000 rows
    // there) at every inner iteration without lowering the model's error.
    if (sol.error.norm2 <= 0.1 * tol_) return sol.p;
    // The tau passes on the model work on C's entries: the dense form, formed here only.
    const Compliance& dense = C.sparse() ? eq_.compliance(out_.state, relevant_components()) : C;
    Vector pl = sol.p, sl = sol.s;
    for (int pass = 0; pass < params_.max_tau_passes; ++pass) {
      const Vector tau = friction_bounds(problem_, pl);
      int n_used = 0, k = 0, h = 0;
      double alpha_used = 1.0;
      const Vector next = predict(dense, pl, sl, tau, k, h, n_used, alpha_used);
      inner += k;
      halvings += h;
      double change = 0.0;
      for (const Candidate& c : problem_.candidates) change = std::max(change, std::abs(next[c.eta] - pl[c.eta]));
      // s moves with the projected force: the error below is the model's at what is returned
      // (with s of the unprojected force it passed the strip on a cylinder's updates whose
      // projection moved s by 2e-3, and the real solve found that error).
      Vector projected = next;
      project_to_cone(problem_, projected);
      sl += model_change(dense, projected - pl);
      pl = std::move(projected);
      if (contact_error(problem_, pl, sl, friction_bounds(problem_, pl), out_.state.enabled).norm2 <= target ||
          change == 0.0)
        break;
    }
    return pl;
  }

  // One real solve at the prediction pl with its line search. A compliance from an earlier
  // state (reuse_compliance, a changing tangent) that mispredicts is renewed: the update is
  // made again from a fresh one when no trial was accepted (retry), and the next update gets
  // a fresh one when only a shortened step was, or the error fell too little.
  enum class Update { accepted, retry, failed };
  Update real_update(const Vector& pl, const Vector& du, int& trials, const HeldPlan* held = nullptr) {
    const double v_before = error_.norm2;
    const bool stale = eq_.compliance_reused();
    if (!line_search(pl, du, trials, held)) {
      if (!stale || !budget_left()) return Update::failed;
      out_.reason.clear();
      out_.failure = FailureKind::none;
      eq_.refresh_compliance();
      return Update::retry;
    }
    if (stale && (trials > 1 || error_.norm2 > kStaleContraction * v_before)) eq_.refresh_compliance();
    return Update::accepted;
  }

  bool held() const { return params_.real_solve == RealSolve::held && problem_.rigid.count() == 0; }

  // real_solve held (docs/algorithm.md#the-held-real-solve): the line search's solves hold the
  // points that the prediction pl presses across their obstacle and those it sticks along it, by
  // springs of stiffness held_stiffness / C_jj (each component's own contact stiffness times that
  // factor) toward the model's s along p -> pl; a point that pl slips carries mu times the normal
  // force it carries. Not for a body held by contact (its amplitudes stay given forces).
  std::optional<HeldPlan> held_plan(const Compliance& C, const Vector& pl) const {
    if (!held() || C.bordered) return std::nullopt;
    const int n = static_cast<int>(pl.size());
    Vector z = Vector::Zero(C.size());
    for (int j = 0; j < n; ++j)
      if (C.position[j] >= 0) z[C.position[j]] = pl[j] - out_.p[j];
    const Vector cz = C.apply(z);
    HeldPlan plan{HeldContact{}, out_.state.s, Vector::Zero(n)};
    for (int j = 0; j < n; ++j)
      if (C.position[j] >= 0) plan.ds[j] = cz[C.position[j]];
    HeldContact& law = plan.law;
    law.stiffness = Vector::Zero(n);
    law.slip.assign(problem_.candidates.size(), 0);
    const auto spring = [&](int j) {
      // |C_jj|: an indefinite C can have C_jj < 0 (coulomb_model.cpp's augmentation).
      const double cjj = C.position[j] >= 0 ? std::abs(C.diagonal(C.position[j])) : 0.0;
      return cjj > 0 ? params_.held_stiffness / cjj : 0.0;
    };
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const Candidate& c = problem_.candidates[i];
      if (!(pl[c.eta] < 0) || (law.stiffness[c.eta] = spring(c.eta)) == 0.0) continue;
      const double mu = problem_.obstacles[c.obstacle].friction;
      if (c.xi < 0 || C.position[c.xi] < 0 || mu <= 0) continue;
      if (std::abs(pl[c.xi]) < mu * -pl[c.eta] * (1 - 1e-10)) law.stiffness[c.xi] = spring(c.xi);
      else law.slip[i] = pl[c.xi] > 0 ? 1 : -1;
    }
    // The springs above mark what is held and stay where the clamped stiffness below is not
    // positive. Each held component's spring against its own stiffness with the other held components
    // held, (C_HH^-1)_jj, where C_HH is positive there: near a limit load C_jj is the compliance
    // of the body's near-mechanism, springs c / C_jj are soft against the held points' other
    // modes, and the moves (StepSolver::move_held) left 0.95 of the stretch a move (Prandtl's
    // punch by contact: 17 real solves, 1.55 x its linear elastic body's, with them 11, 1.00 x).
    // One factorization of the held block, as the Coulomb model's Newton makes of its active one.
    std::vector<int> held_set;
    for (int j = 0; j < n; ++j)
      if (law.stiffness[j] > 0) held_set.push_back(j);
    if (!held_set.empty()) {
      const Matrix clamped = Eigen::PartialPivLU<Matrix>(C.sub(held_set)).inverse();
      for (size_t a = 0; a < held_set.size(); ++a)
        if (std::isfinite(clamped(a, a)) && clamped(a, a) > 0)
          law.stiffness[held_set[a]] = params_.held_stiffness * clamped(a, a);
    }
    return plan;
  }

  // The inner loop's target on the model: well below the step's tolerance and the error now.
  double model_target() const { return std::min(0.1 * tol_, 1e-6 * error_.norm2); }

  // C dp over the compliance's components.
  static Vector model_change(const Compliance& C, const Vector& dp) {
    Vector ds = Vector::Zero(dp.size());
    for (int j = 0; j < dp.size(); ++j)
      if (dp[j] != 0.0)
        for (size_t a = 0; a < C.position.size(); ++a)
          if (C.position[a] >= 0 && C.position[j] >= 0) ds[a] += C.block(C.position[a], C.position[j]) * dp[j];
    return ds;
  }

  // Inner iterations on the linear model, then one real solve and its line search.
  bool inner_pass() {
    while (!error_met(error_)) {
      if (!budget_left()) return false;
      const Compliance& C = eq_.compliance(out_.state, relevant_components());
      int inner = 0, halvings = 0, n_used = 0;
      double alpha_used = 1.0;
      const Vector pl = predict(C, out_.p, out_.state.s, out_.tau, inner, halvings, n_used, alpha_used);
      out_.inner_iterations += inner;
      // Newton starts from the model's own displacement, saving about one iteration a solve.
      const Vector du = eq_.predicted_change(C, pl - out_.p);
      int trials = 0;
      const Update u = real_update(pl, du, trials);
      if (u == Update::failed) return false;
      if (u == Update::retry) continue;
      ++m_;
      emit(trials, inner, halvings, n_used, alpha_used);
    }
    return true;
  }

  // q(p + dp) - q(p) = (s + C dp / 2) . dp < 0, over the non-zeros of dp only.
  static bool decreases_q(const Compliance& C, const Vector& s, const Vector& dp) {
    std::vector<int> nz;
    for (int j = 0; j < dp.size(); ++j)
      if (dp[j] != 0.0) nz.push_back(j);
    double change = 0.0;
    for (int a : nz) {
      double cdp = 0.0;
      for (int b : nz) cdp += C(a, b) * dp[b];
      change += (s[a] + 0.5 * cdp) * dp[a];
    }
    return change < 0;
  }

  // The bordered model (a body held by contact) is a saddle point, not a minimum of q: there a
  // step must lower ||v|| on the model instead.
  bool lowers_model_error(const Compliance& C, const Vector& p, const Vector& s, const Vector& dp, const Vector& tau,
                          const ContactError& e) const {
    return contact_error(problem_, p + dp, s + model_change(C, dp), tau, out_.state.enabled).norm2 < e.norm2;
  }

  // eq. 13 with the bounds tau iterated on s(p) = s0 + C (p - p0), accepted by the decrease
  // of q(p) = p.C.p/2 + (s0 - C p0).p; returns the predicted force.
  Vector predict(const Compliance& C, const Vector& p0, const Vector& s0, const Vector& tau, int& inner, int& halvings,
                 int& n_used, double& alpha_used) {
    Vector pl = p0, sl = s0;
    const double target = model_target();
    keep_bordered_factors(true);  // C stays the same through these iterations
    for (inner = 0; inner < params_.max_inner_iterations; ++inner) {
      const ContactError e = contact_error(problem_, pl, sl, tau, out_.state.enabled);
      if (e.norm2 <= target) break;
      Vector dp;
      bool descended = false;
      // The accelerated direction first; the plain gradient (n = 1, always a descent
      // direction for a small enough step) if the projection spoiled it.
      for (int attempt = 0; attempt < 2 && !descended; ++attempt) {
        const Direction dir = attempt == 0 ? direction(C, e, params_.acceleration, 0.0) : direction(C, e, 1, 1.0);
        if (!dir.ok) continue;
        double a = 1.0;
        for (int k = 0; k <= params_.max_halvings; ++k, a *= 0.5) {
          dp = project_forces(problem_, pl, pl - a * dir.d, e, tau) - pl;
          if (C.bordered ? lowers_model_error(C, pl, sl, dp, tau, e) : decreases_q(C, sl, dp)) {
            descended = true;
            n_used = dir.n;
            alpha_used = dir.alpha * a;
            break;
          }
          ++halvings;
        }
      }
      if (!descended) break;  // stationary on the model: the real solve decides
      pl += dp;
      sl += model_change(C, dp);  // dp is zero off the active set
    }
    keep_bordered_factors(false);
    return pl;
  }

  // The eq. 30 estimate is made once per step, in its first pass, and reused by later passes.
  bool needs_warmup() const {
    return params_.epsilon == EpsilonSource::warmup && params_.acceleration != kAccelerationInfinity &&
           params_.acceleration != 1 && pass_ == 1;
  }

  // eq. 30: J iterations of n = 1, alpha = 1.99, each one real solve, to estimate epsbar_1.
  bool warmup() {
    std::vector<double> norms{error_.norm2};
    for (int m = 1; m <= params_.warmup_last && error_.norm2 > tol_; ++m) {
      if (!budget_left()) return false;
      const Compliance& C = eq_.compliance(out_.state, relevant_components());
      const Direction dir = direction(C, error_, 1, params_.warmup_alpha);
      if (!dir.ok) break;
      const Vector pt = project(C, out_.p, out_.p - dir.d, error_, out_.tau);
      EquilibriumState trial = eq_.solve(out_.state.q, pt);
      if (!trial.converged) break;
      accept(std::move(trial), pt);
      norms.push_back(error_.norm2);
      ++m_;
      emit(1, 0, 0, 1, params_.warmup_alpha);
    }
    // Too short a history (the error vanished, or a trial failed) leaves the exact
    // eigenvalue in charge.
    const int last = static_cast<int>(norms.size()) - 1;
    if (last >= params_.warmup_first)
      warmup_eps_ = warmup_epsilon(norms, params_.warmup_alpha, params_.warmup_first, last);
    return true;
  }

  // The previous step's first contact error: the scale of this step's first solve.
  double v_previous_ = 0.0;
  // Where the step started at rest (load stepping: a plastic body where only obstacles moved), the
  // displacement its first update's compliance is formed at: the last increment extrapolated,
  // whose tangent yields where that increment yielded (at rest, a point on the yield surface
  // answers with the elastic tangent, and the model overpredicts the forces).
  std::optional<Vector> model_q_;
};

}  // namespace

StepOutcome solve_cev_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start, const Vector& p_star,
                           const ContactParams& params, int step, const IterationObserver& observer,
                           const StopRequest& stop, double v_previous, bool at_rest, const Vector* model_at) {
  return CevStep(eq, params, step, observer, stop, v_previous, at_rest, model_at).run(q_guess, p_start, p_star);
}

}  // namespace grip
