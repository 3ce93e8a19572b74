#include "solver/contact/strategy.hpp"

#include <Eigen/Cholesky>
#include <chrono>
#include <cmath>

#include "solver/contact/acceleration.hpp"
#include "solver/contact/contact_error.hpp"

namespace grip {
namespace {

using Clock = std::chrono::steady_clock;

std::vector<int> active_indices(const ContactError& e) {
  std::vector<int> idx;
  for (int i = 0; i < static_cast<int>(e.active.size()); ++i)
    if (e.active[i]) idx.push_back(i);
  return idx;
}


double inf_norm(const Matrix& A) {
  return A.size() ? A.cwiseAbs().rowwise().sum().maxCoeff() : 0.0;
}

// The direction d of eq. 13 (pbar = p - d) on the active block, scattered to all components.
struct Direction {
  Vector d;
  int n = 0;
  double alpha = 1.0;
  bool ok = false;
};

// One load step's state and the two loops that drive it.
class StepSolver {
 public:
  StepSolver(Equilibrium& eq, const ContactParams& params, int step, const IterationObserver& obs,
             const StopRequest& stop)
      : eq_(eq), problem_(eq.problem()), params_(params), step_(step), observer_(obs), stop_(stop),
        start_(Clock::now()) {
    tol_ = params.tolerance * problem_.body->characteristic_length();
    is_normal_.assign(problem_.component_count, 0);
    for (const Candidate& c : problem_.candidates) is_normal_[c.eta] = 1;
  }

  StepOutcome run(const Vector& q_guess, const Vector& p_start, const Vector& p_star_in) {
    couple_newton(eq_.params(), params_.tolerance, params_.newton_fraction,
                  problem_.body->characteristic_length());
    if (params_.method == ContactMethod::penalty) return run_penalty(q_guess, p_start);
    const long solves0 = eq_.counters().solves, newton0 = eq_.counters().newton_iterations;
    out_.p = p_start;
    Vector p_star = p_star_in;
    solves_at_start_ = eq_.counters().solves;
    bool frictionless = true;
    for (const Candidate& c : problem_.candidates) frictionless &= c.xi < 0;
    for (int pass = 1; pass <= params_.max_tau_passes; ++pass) {
      pass_ = pass;
      out_.passes = pass;
      out_.tau = friction_bounds(problem_, p_star);
      // Each pass restarts from one solve with p clipped to the new bounds (section 9); when
      // the clip changes nothing, the last accepted state is that solve already.
      const Vector unclipped = out_.p;
      clip_to_bounds(problem_, out_.tau, out_.p);
      if (pass > 1 && out_.p == unclipped) {
        accept(std::move(out_.state), unclipped);
        m_ = 0;
        emit(0, 0, 0, 0, 0.0);
      } else if (!fresh_solve(pass == 1 ? q_guess : out_.state.q)) {
        break;
      }
      const bool ok = params_.loop == ContactLoop::paper || params_.method == ContactMethod::uzawa
                          ? paper_pass()
                          : inner_pass();
      if (!ok) break;
      if (frictionless) break;
      double change = 0.0, scale = 0.0;
      for (const Candidate& c : problem_.candidates) {
        change = std::max(change, std::abs(out_.p[c.eta] - p_star[c.eta]));
        scale = std::max(scale, std::abs(out_.p[c.eta]));
      }
      // ||v|| <= tol pins p only to about C_EE^-1 v_E: a change of p* below that is noise
      // (section 9: a tighter test makes p* cycle).
      if (change <= params_.tau_tolerance * scale || change <= force_precision()) {
        out_.converged = true;
        break;
      }
      for (const Candidate& c : problem_.candidates) p_star[c.eta] = out_.p[c.eta];
      if (pass == params_.max_tau_passes)
        fail("the friction bound did not settle in " + std::to_string(pass) + " tau passes");
    }
    if (frictionless && out_.reason.empty()) out_.converged = true;
    if (out_.converged) final_check();
    out_.solves = static_cast<int>(eq_.counters().solves - solves0);
    out_.newton_iterations = static_cast<int>(eq_.counters().newton_iterations - newton0);
    out_.v2 = error_.norm2;
    return std::move(out_);
  }

 private:
  // The penalty baseline: one Newton solve with p = p(q); the contact error of eq. 10 (with
  // tau = nu |p_eta|) measures how far the penalty answer is from the contact conditions.
  StepOutcome run_penalty(const Vector& q_guess, const Vector& p_start) {
    const long solves0 = eq_.counters().solves, newton0 = eq_.counters().newton_iterations;
    PenaltyLaw law;
    law.normal = params_.penalty_normal > 0 ? params_.penalty_normal
                                            : params_.penalty_factor * eq_.stiffness_scale(q_guess);
    law.tangential = params_.penalty_tangential > 0 ? params_.penalty_tangential : law.normal;
    law.previous = p_start;
    eq_.set_penalty(law);
    EquilibriumState s = eq_.solve(q_guess, p_start);
    eq_.set_penalty(std::nullopt);
    pass_ = out_.passes = 1;
    if (!s.converged) {
      fail("equilibrium solve failed: " + s.reason);
    } else {
      Vector p_star = Vector::Zero(problem_.component_count);
      for (const Candidate& c : problem_.candidates) p_star[c.eta] = s.p[c.eta];
      out_.tau = friction_bounds(problem_, p_star);
      const Vector p = s.p;
      accept(std::move(s), p);
      out_.converged = true;
      emit(1, 0, 0, 0, 0.0);
    }
    out_.solves = static_cast<int>(eq_.counters().solves - solves0);
    out_.newton_iterations = static_cast<int>(eq_.counters().newton_iterations - newton0);
    out_.v2 = error_.norm2;
    return std::move(out_);
  }

  bool fresh_solve(const Vector& q) {
    if (!budget_left()) return false;
    EquilibriumState s = eq_.solve(q, out_.p);
    if (!s.converged) return fail("equilibrium solve failed: " + s.reason);
    accept(std::move(s), out_.p);
    m_ = 0;
    emit(1, 0, 0, 0, 0.0);
    return true;
  }

  void accept(EquilibriumState s, const Vector& p) {
    out_.state = std::move(s);
    out_.p = p;
    error_ = contact_error(problem_, out_.p, out_.state.s, out_.tau, out_.state.enabled);
  }

  bool fail(std::string reason) {
    out_.converged = false;
    if (out_.reason.empty()) out_.reason = std::move(reason);
    return false;
  }

  bool budget_left() {
    if (stop_ && stop_()) {
      out_.stopped = true;
      return fail("stopped on request");
    }
    if (eq_.counters().solves < solves_at_start_ + params_.max_iterations) return true;
    return fail("contact error " + std::to_string(error_.norm2) + " above tolerance " +
                std::to_string(tol_) + " after " + std::to_string(params_.max_iterations) +
                " contact iterations");
  }

  // Direction of eq. 13 for the active block of v: n = infinity solves with C'_EE; a finite n
  // uses the polynomial accelerator (normalized, section 8); level 1 is the multiplier update.
  Direction direction(const Compliance& C, const ContactError& err, int level, double alpha_fixed) {
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
        const double eps1 = epsilon(C1);
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

  double epsilon(const Matrix& C1) {
    if (params_.epsilon == EpsilonSource::warmup && warmup_eps_ > 0) {
      out_.epsilon_used = "warmup";
      return std::min(1.0, warmup_eps_);
    }
    out_.epsilon_used = "exact";
    return smallest_eigenvalue(C1);
  }

  // The components that can take part in this iteration: every one with a force or a
  // friction bound, and those of candidates penetrating or within a few per cent of the
  // body's length of their obstacle. The others are frozen (a far point that the real solve
  // brings into contact joins at the next iteration).
  std::vector<int> relevant_components() const {
    const double window = 0.05 * problem_.body->characteristic_length();
    std::vector<int> out;
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const Candidate& c = problem_.candidates[i];
      if (!out_.state.enabled[c.eta]) continue;
      const bool near = out_.p[c.eta] < 0 || out_.tau[i] > 0 || out_.state.s[c.eta] > -window;
      if (!near) continue;
      out.push_back(c.eta);
      if (c.xi >= 0 && out_.state.enabled[c.xi]) out.push_back(c.xi);
    }
    return out;
  }

  // The largest normal-force correction that the remaining contact error asks for.
  double force_precision() {
    if (error_.norm2 == 0.0) return 0.0;
    const std::vector<int> idx = active_indices(error_);
    const Compliance& C = eq_.compliance(out_.state, idx);
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

  // ---- the default loop (section 5): inner iterations on the linear model, one real solve
  bool inner_pass() {
    if (needs_warmup() && !warmup()) return false;
    while (error_.norm2 > tol_) {
      if (!budget_left()) return false;
      const Compliance& C = eq_.compliance(out_.state, relevant_components());
      int inner = 0, halvings = 0, n_used = 0;
      double alpha_used = 1.0;
      const Vector pl = predict(C, inner, halvings, n_used, alpha_used);
      out_.inner_iterations += inner;
      // One real solve at the prediction, then a line search along p -> pl.
      const Vector p0 = out_.p;
      // Newton starts from the model's own displacement, saving about one iteration a solve.
      const Vector du = eq_.predicted_change(C, pl - p0);
      const double v0 = error_.norm2;
      bool accepted = false;
      int trials = 0;
      for (int h = 0; h <= params_.line_search_steps && !accepted; ++h) {
        if (!budget_left()) return false;
        const double f = std::ldexp(1.0, -h);
        const Vector pt = h == 0 ? pl : Vector(p0 + f * (pl - p0));
        ++trials;
        EquilibriumState trial = eq_.solve(out_.state.q + f * du, pt);
        if (!trial.converged) continue;  // a diverging trial is a failed trial: halve
        const ContactError e = contact_error(problem_, pt, trial.s, out_.tau, trial.enabled);
        if (e.norm2 < v0) {
          accept(std::move(trial), pt);
          accepted = true;
        }
      }
      if (!accepted)
        return fail("no decrease of the contact error along the predicted force change (||v|| = " +
                    std::to_string(v0) + ")");
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

  // eq. 13 iterated on s(p) = s + C (p - p0), accepted by the decrease of
  // q(p) = p.C.p/2 + (s - C p0).p; returns the predicted force.
  Vector predict(const Compliance& C, int& inner, int& halvings, int& n_used, double& alpha_used) {
    Vector pl = out_.p, sl = out_.state.s;
    const double target = std::min(0.1 * tol_, 1e-6 * error_.norm2);
    for (inner = 0; inner < params_.max_inner_iterations; ++inner) {
      const ContactError e = contact_error(problem_, pl, sl, out_.tau, out_.state.enabled);
      if (e.norm2 <= target) break;
      Vector dp;
      bool descended = false;
      // The accelerated direction first; the plain gradient (n = 1, always a descent
      // direction for a small enough step) if the projection spoiled it.
      for (int attempt = 0; attempt < 2 && !descended; ++attempt) {
        const Direction dir = attempt == 0 ? direction(C, e, params_.acceleration, 0.0)
                                           : direction(C, e, 1, 1.0);
        if (!dir.ok) continue;
        double a = 1.0;
        for (int k = 0; k <= params_.max_halvings; ++k, a *= 0.5) {
          dp = project_forces(problem_, pl, pl - a * dir.d, e, out_.tau) - pl;
          if (decreases_q(C, sl, dp)) {
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
      for (int j = 0; j < dp.size(); ++j)  // dp is zero off the active set
        if (dp[j] != 0.0)
          for (size_t a = 0; a < C.position.size(); ++a)
            if (C.position[a] >= 0 && C.position[j] >= 0) sl[a] += C.block(C.position[a], C.position[j]) * dp[j];
    }
    return pl;
  }

  // ---- the paper's literal loop (and uzawa): one real solve per eq. 13 update
  bool paper_pass() {
    const bool uzawa = params_.method == ContactMethod::uzawa;
    if (!uzawa && needs_warmup() && !warmup()) return false;
    while (error_.norm2 > tol_) {
      if (!budget_left()) return false;
      int level = uzawa ? 1 : params_.acceleration;  // each update starts at the chosen n
      const Compliance& C = eq_.compliance(out_.state, relevant_components());
      const double v0 = error_.norm2;
      const ContactError e = error_;
      bool accepted = false;
      int trials = 0, halvings = 0;
      double a = 1.0;
      while (!accepted) {
        const Direction dir = direction(C, e, level, uzawa ? params_.uzawa_alpha : 0.0);
        if (!dir.ok) return fail("the active block of the compliance is not positive definite");
        if (!budget_left()) return false;
        const Vector pt = project_forces(problem_, out_.p, out_.p - a * dir.d, e, out_.tau);
        ++trials;
        EquilibriumState trial = eq_.solve(out_.state.q, pt);
        if (trial.converged) {
          const ContactError et = contact_error(problem_, pt, trial.s, out_.tau, trial.enabled);
          if (et.norm2 < v0) {
            accept(std::move(trial), pt);
            accepted = true;
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
        if (halvings > params_.max_halvings)
          return fail("alpha halved " + std::to_string(params_.max_halvings) +
                      " times without a decrease of the contact error");
      }
    }
    return true;
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
      const Vector pt = project_forces(problem_, out_.p, out_.p - dir.d, error_, out_.tau);
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

  void final_check() {
    // eq. 12 with the last pass's tau.
    if (error_.norm2 > tol_) {
      fail("contact error above tolerance at the end of the step");
      return;
    }
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const Candidate& c = problem_.candidates[i];
      if (out_.p[c.eta] > 0) fail("a normal contact force pulls");
      if (c.xi >= 0 && std::abs(out_.p[c.xi]) > out_.tau[i] * (1 + 1e-9) + 1e-300)
        fail("a friction force exceeds its Coulomb bound");
    }
  }

  void emit(int trials, int inner, int halvings, int n, double alpha) {
    IterationEvent ev;
    ev.step = step_;
    ev.pass = pass_;
    ev.m = m_;
    ev.trials = trials;
    ev.inner_iterations = inner;
    ev.halvings = halvings;
    ev.n = n;
    ev.alpha = alpha;
    ev.v2 = error_.norm2;
    ev.v_inf = error_.norm_inf;
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      switch (contact_state(problem_, i, out_.p, out_.tau)) {
        case ContactState::open: ++ev.open; break;
        case ContactState::stick: ++ev.stick; break;
        case ContactState::slip: ++ev.slip; break;
      }
    }
    ev.newton_iterations = trials > 0 ? out_.state.newton_iterations : 0;
    ev.elapsed_ms = std::chrono::duration<double, std::milli>(Clock::now() - start_).count();
    out_.history.push_back(ev);
    if (observer_) observer_(ev);
  }

  Equilibrium& eq_;
  const Problem& problem_;
  const ContactParams& params_;
  int step_;
  const IterationObserver& observer_;
  const StopRequest& stop_;
  Clock::time_point start_;
  double tol_ = 0.0;
  int pass_ = 0, m_ = 0;
  long solves_at_start_ = 0;
  double warmup_eps_ = 0.0;
  std::vector<char> is_normal_;
  ContactError error_;
  StepOutcome out_;
};

}  // namespace

StepOutcome solve_contact_step(Equilibrium& equilibrium, const Vector& q_guess,
                               const Vector& p_start, const Vector& p_star,
                               const ContactParams& params, int step,
                               const IterationObserver& observer, const StopRequest& stop) {
  StepSolver solver(equilibrium, params, step, observer, stop);
  return solver.run(q_guess, p_start, p_star);
}

}  // namespace grip
