// Strategy `ssn`: a semismooth Newton method on the Alart-Curnier function in the primal
// unknowns (Alart & Curnier 1991; the generalized Newton that GetFEM, 4C and others use, the
// same iterates as the primal-dual active set of Hueber, Stadler & Wohlmuth 2008). The
// displacements q (free dofs) and the contact forces p are solved together, one sparse linear
// system per iteration:
//     R(q, p) = A(q) - lambda F - T(q) p = 0                    (equilibrium, eq. 1-2)
//     F_eta = p_eta - min(0, p_eta - r s_eta(q)) = 0
//     F_xi  = p_xi - clamp(p_xi - r s_xi(q), -tau, tau) = 0,   tau = mu max(0, -(p_eta - r s_eta))
// with the same pairing, T(q) and follower-load stiffness d(T(q) p)/dq as the equilibrium
// oracle. The active, stick and slip sets come from the complementarity function at each
// iterate, and a real solve is taken once the iterate meets F = 0 and is near equilibrium
// (`balanced`). Globalized by backtracking on |R|^2/2 + |F|^2/2 (residuals in force units); where
// that finds no decrease, one equilibrium solve at the current forces and Newton again. Forces
// the function holds open are set to exactly zero before the oracle sees them (a -1e-22
// normal force at a gap counts as pressing: that stalled the beam and the sheet). r is
// the augmentation, r_i = augmentation / C_ii (each component's own contact stiffness, from
// the compliance at the step's first solve): it changes the path, not the answer. The step ends with one equilibrium solve (the oracle) at
// the forces projected onto the Coulomb cone, so that its answer is judged exactly as cev's.
#include <Eigen/SparseLU>
#include <cmath>

#include "solver/contact/coulomb_model.hpp"
#include "solver/contact/step.hpp"
#include "solver/model/number_text.hpp"

namespace grip {
namespace {

class SsnStep : public StepSolver {
 public:
  SsnStep(Equilibrium& eq, const ContactParams& params, int step, const IterationObserver& obs, const StopRequest& stop)
      : StepSolver(eq, params, step, obs, stop) {
    const int n = problem_.body->dof_count();
    // A body held by contact: its pins join the unknowns, the rigid amplitudes with them.
    std::vector<char> pin(n, 0);
    for (int d : problem_.rigid.pins) pin[d] = 1;
    free_index_.assign(n, -1);
    for (int i = 0; i < n; ++i)
      if (eq.is_free(i) || pin[i]) free_index_[i] = free_count_++;
    length_scales_ = problem_.body->dof_length_scales();
  }

 private:
  // Starts from the previous step's force (p_previous): from the extrapolated one, small
  // augmentations led it to other equilibria of the beam's steps.
  void solve(const Vector& q_guess, const Vector&, const Vector& p_previous) override {
    coulomb_ = true;
    pass_ = out_.passes = 1;
    out_.p = p_previous;
    project_to_cone(problem_, out_.p);
    // A body that no force held yet (its first contact) is brought to touch instead: a
    // restoring step from one touching point would press it far in (Hertz by a force).
    bool held = false;
    for (const Candidate& c : problem_.candidates) held = held || out_.p[c.eta] < 0;
    if (!fresh_solve(q_guess) || !approach_contact() || !(held ? restore_equilibrium() : start_from_model())) return;
    Vector q = out_.state.q, p = out_.p;
    augmentations(out_.state);
    const int components = problem_.component_count;
    int restarts = 0;
    previous_error_ = error_.norm2;
    // Only a state from the oracle ends the loop: the step is judged on a real solve.
    for (int it = 1; !error_met(error_); ++it) {
      if (!budget_left()) return;
      if (it > params_.max_iterations) {
        return void(fail(FailureKind::contact_budget,
                         "semismooth Newton did not converge in " + std::to_string(params_.max_iterations) +
                             " iterations (contact error " + number_text(error_.norm2) + ")"));
      }
      Triplets tangent;
      const EquilibriumState paired = eq_.evaluate(q);
      const Vector R = eq_.residual(q, p, &tangent);
      Triplets jacobian;
      const Vector F = complementarity(paired, p, &jacobian);
      const double phi = merit(R, F);
      // The system [dR/dq  -T; dF/ds T^T  dF/dp] [dq; dp] = -[R; F] on the free dofs and p.
      for (const auto& t : tangent)
        if (free_index_[t.row()] >= 0 && free_index_[t.col()] >= 0)
          jacobian.emplace_back(free_index_[t.row()], free_index_[t.col()], t.value());
      add_t_columns(paired, jacobian);
      Eigen::SparseMatrix<double> J(free_count_ + components, free_count_ + components);
      J.setFromTriplets(jacobian.begin(), jacobian.end());
      Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
      lu.compute(J);
      if (lu.info() != Eigen::Success)
        return void(fail(FailureKind::contact_stalled,
                         "semismooth Newton: singular system in iteration " + std::to_string(it)));
      Vector rhs(free_count_ + components);
      for (int i = 0; i < R.size(); ++i)
        if (free_index_[i] >= 0) rhs[free_index_[i]] = -R[i];
      rhs.tail(components) = -F;
      const Vector x = lu.solve(rhs);
      if (!x.allFinite())
        return void(fail(FailureKind::contact_stalled, "semismooth Newton produced a non-finite correction"));
      Vector dq = Vector::Zero(q.size());
      for (int i = 0; i < q.size(); ++i)
        if (free_index_[i] >= 0) dq[i] = x[free_index_[i]];
      const Vector dp = x.tail(components);
      // Backtracking on the merit function (its slope along the Newton direction is -2 phi).
      double a = problem_.body->newton_step_fraction(q, dq);
      int halvings = 0;
      bool decreased = false;
      for (; halvings <= params_.max_halvings; ++halvings, a *= 0.5) {
        const Vector qt = q + a * dq, pt = p + a * dp;
        const EquilibriumState pt_paired = eq_.evaluate(qt);
        const double phi_t = merit(eq_.residual(qt, pt, nullptr), complementarity(pt_paired, pt, nullptr));
        if (std::isfinite(phi_t) && phi_t <= (1 - 1e-4 * a) * phi) {
          decreased = true;
          break;
        }
      }
      if (!decreased) {
        // Back onto equilibrium: the oracle at the current forces (projected onto the cone),
        // then Newton again from there.
        if (++restarts > kMaxRestarts)
          return void(fail(FailureKind::contact_stalled,
                           "semismooth Newton: no decrease of the residual along the Newton direction"));
        Vector p_cone = p;
        project_to_cone(problem_, p_cone);
        if (!budget_left()) return;
        EquilibriumState solved = eq_.solve(q, p_cone);
        if (!solved.converged) return void(fail(solved.failure, "equilibrium solve failed: " + solved.reason));
        q = solved.q;
        p = p_cone;
        accept(std::move(solved), p_cone);
        ++m_;
        emit(1, 0, halvings, 0, 0.0);
        if (drifting()) return;
        continue;
      }
      restarts = 0;
      q += a * dq;
      p += a * dp;
      ++own_newton_iterations_;
      // Close enough on the complementarity function and on equilibrium: the oracle solves
      // equilibrium at the forces projected onto the cone, and the contact error judges that state.
      const EquilibriumState now = eq_.evaluate(q);
      const Vector F_now = complementarity(now, p, nullptr);
      Vector p_cone = p;
      release_open(now, p_cone);
      project_to_cone(problem_, p_cone);
      if (scaled_length(F_now) <= 0.1 * tol_ && balanced(q, p_cone, a, dq)) {
        if (!budget_left()) return;
        EquilibriumState solved = eq_.solve(q, p_cone);
        if (!solved.converged) return void(fail(solved.failure, "equilibrium solve failed: " + solved.reason));
        q = solved.q;
        accept(std::move(solved), p_cone);
        ++m_;
        emit(1, 0, halvings, 0, a, 1);
        if (drifting()) return;
      } else {
        // Reported in the event, not accepted: out_.state stays the last real solve's.
        const ContactError e = error_at(p_cone, now.s, now.enabled);
        const ContactError kept = error_;
        const Vector kept_p = out_.p, kept_tau = out_.tau;
        out_.p = p_cone;
        out_.tau = friction_bounds(problem_, p_cone);
        error_ = e;
        ++m_;
        emit(0, 0, halvings, 0, a, 1);
        error_ = kept;
        out_.p = kept_p;
        out_.tau = kept_tau;
      }
    }
    out_.converged = true;
    final_check();
  }

  // The iterate (q, p) is near equilibrium at p: its relative residual within the square root of
  // Newton's residual test (one quadratic iteration of the real solve from it), or a full step's
  // correction within Newton's correction test. On a flat obstacle F is met after every full
  // step whatever R (the gaps are linear in q), and a real solve under given forces from an
  // unbalanced iterate is a dead-load problem: on a perfectly plastic block near its limit
  // (Prandtl's punch as an obstacle, bench/results/prandtl-fillet.md) the forces' small error
  // moved the state by 2-4 x the step's punch travel, each real solve undid Newton's progress,
  // and the iterates cycled (contact error 5.5e-4 <-> 6e-4, a crawl after 5 cuts: step 1
  // failed). At Newton's own test instead of its square root, ssn on the paper's beam at
  // tolerance 1e-10 took another load path (forces 0.019 from cev's).
  bool balanced(const Vector& q, const Vector& p, double a, const Vector& dq) const {
    if (eq_.relative_residual(q, p) <= std::sqrt(eq_.params().residual_tolerance)) return true;
    if (a != 1.0) return false;
    double correction = 0.0;
    for (int i = 0; i < dq.size(); ++i) correction = std::max(correction, std::abs(dq[i]) * length_scales_[i]);
    return correction <= eq_.params().displacement_tolerance;
  }

  // A load with no equilibrium near (a disc turned beyond what friction holds): Newton cannot
  // converge, and its real solves drift away, each state's contact error above the one before
  // (14 in a row there, 1.4e-3 to 6.2e-3, until its 500 iterations were spent: 20 real solves,
  // 7 of its 8 s of CPU). In tests/verification and tests/hard no ssn attempt rose more than 4
  // times in a row (the beam on a cylinder with mu 5, an attempt before a cut); twice that ends
  // the step (the disc: 13 real solves, 262 Newton), and the caller decides what it is.
  bool drifting() {
    rises_ = error_.norm2 > previous_error_ ? rises_ + 1 : 0;
    previous_error_ = error_.norm2;
    if (rises_ < kMaxRises) return false;
    return !fail(FailureKind::contact_stalled, "semismooth Newton: the contact error grew at " +
                                                   std::to_string(kMaxRises) + " real solves in a row (to " +
                                                   number_text(error_.norm2) + "): its iterates drift");
  }

  // A body held by contact starts a step unbalanced: the load grew, the forces are the last
  // step's, and the pins of the first solve carry the difference as a point reaction that
  // deforms the body around them. Linearized there, every point of the sheared block slipped, no
  // row held the slide, and the first Newton step overshot (||dq|| ~ 1e10, 86-174 real solves a
  // level, each a restart). So Newton starts from one step of the linear model instead: the
  // bordered system [C G; G^T 0] [dp; da] = [v_c; v_a] on the active components (the
  // equilibrium rows met, the gaps and slips of the active points closed), put onto the cone,
  // and solved once (3 real solves a level then).
  bool restore_equilibrium() {
    const RigidModes& rigid = problem_.rigid;
    if (!rigid.count() || error_met(error_)) return true;
    if (unbalance(error_) <= 0.1 * std::min(tol_, balance_tol_)) return true;
    const Compliance& C = eq_.compliance(out_.state, relevant_components());
    if (!C.bordered) return true;
    const Direction dir = bordered_direction(C, error_, kAccelerationInfinity, 0.0);
    if (!dir.ok) return true;
    Vector p = out_.p - dir.d;
    project_to_cone(problem_, p);
    const Vector du = eq_.predicted_change(C, p - out_.p);
    out_.p = p;
    return fresh_solve(Vector(out_.state.q + du));
  }

  // A body held by contact at its first contact: no force presses yet, so the function holds
  // every point open and no row of the system holds the free motions (the von Karman beam lying
  // on a flat: iterates at ||v|| ~ 1e11, singular after 92 iterations, 3 cuts of the press
  // step, and with them another load path, whose friction forces lay 1e-6 from cev's). Newton
  // starts instead from Coulomb's law on the linear model at this state (cev's first iteration,
  // no real solve), solved once.
  bool start_from_model() {
    if (!problem_.rigid.count() || error_met(error_)) return true;
    const Compliance& C = eq_.compliance(out_.state, relevant_components());
    const CoulombModelSolution model = solve_model(C, 0.1 * tol_);
    out_.inner_iterations += model.iterations;
    // Not converged on the model is still a start (the von Karman beam: 1.3e-5 after 4 iterations).
    if (!presses(model.p) || !(model.error.norm2 < error_.norm2)) return true;
    const Vector du = eq_.predicted_change(C, model.p - out_.p);
    out_.p = model.p;
    return fresh_solve(Vector(out_.state.q + du));
  }

  // The Alart-Curnier function at (q's pairing, p) and, if asked, its generalized Jacobian
  // rows (dF/dp and dF/ds ds/dq, at rows free_count_ + component).
  Vector complementarity(const EquilibriumState& paired, const Vector& p, Triplets* J) const {
    Vector F = p;  // open, free or disabled components: p = 0
    const int base = free_count_;
    auto add_ds = [&](int row, size_t candidate, bool normal, double factor) {
      const PairedPoint& pp = paired.points[candidate];
      const Vec2 dir = normal ? pp.eta : Vec2(pp.projection.zeta_rate * pp.xi);
      for (const auto& j : pp.point.jacobian)
        if (free_index_[j.dof] >= 0) J->emplace_back(row, free_index_[j.dof], factor * j.dx.dot(dir));
    };
    std::vector<char> identity(p.size(), 1);
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const Candidate& c = problem_.candidates[i];
      if (!paired.enabled[c.eta]) continue;
      const double rn = r_[c.eta];
      const double gn = p[c.eta] - rn * paired.s[c.eta];
      if (gn < 0) {  // pressing: s_eta = 0
        F[c.eta] = rn * paired.s[c.eta];
        identity[c.eta] = 0;
        if (J) add_ds(base + c.eta, i, true, rn);
      }
      if (c.xi < 0 || !paired.enabled[c.xi]) continue;
      const double tau = problem_.obstacles[c.obstacle].friction * std::max(0.0, -gn);
      if (tau <= 0) continue;
      const double rt = r_[c.xi];
      const double g = p[c.xi] - rt * paired.s[c.xi];
      identity[c.xi] = 0;
      if (std::abs(g) < tau) {  // stick: s_xi = 0
        F[c.xi] = rt * paired.s[c.xi];
        if (J) add_ds(base + c.xi, i, false, rt);
      } else {  // slip: p_xi = sign(g) tau
        const double sg = g > 0 ? 1.0 : -1.0;
        const double mu = problem_.obstacles[c.obstacle].friction;
        F[c.xi] = p[c.xi] - sg * tau;
        if (J) {
          J->emplace_back(base + c.xi, base + c.xi, 1.0);
          J->emplace_back(base + c.xi, base + c.eta, sg * mu);
          add_ds(base + c.xi, i, true, -sg * mu * rn);
        }
      }
    }
    // A rigid amplitude is its pin's displacement (in its unit): p_a - q_pin / scale = 0.
    const RigidModes& rigid = problem_.rigid;
    for (int k = 0; k < rigid.count(); ++k) {
      const int a = rigid.first + k, pin = rigid.pins[k];
      F[a] = p[a] - paired.q[pin] / rigid.scale;
      if (J) J->emplace_back(base + a, free_index_[pin], -1.0 / rigid.scale);
    }
    if (J)
      for (int k = 0; k < p.size(); ++k)
        if (identity[k]) J->emplace_back(base + k, base + k, 1.0);
    return F;
  }

  // Where the Alart-Curnier function holds a component open (p_eta - r s_eta >= 0), its force
  // is zero to the function's tolerance, not exactly: a normal force of -1e-22 at a gap would
  // count as pressing in the contact error. Such forces are set to zero.
  void release_open(const EquilibriumState& paired, Vector& p) const {
    for (const Candidate& c : problem_.candidates)
      if (!paired.enabled[c.eta] || p[c.eta] - r_[c.eta] * paired.s[c.eta] >= 0) {
        p[c.eta] = 0.0;
        if (c.xi >= 0) p[c.xi] = 0.0;
      }
  }

  // dR/dp = -T on the free dofs.
  void add_t_columns(const EquilibriumState& paired, Triplets& J) const {
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const Candidate& c = problem_.candidates[i];
      const PairedPoint& pp = paired.points[i];
      for (const auto& j : pp.point.jacobian) {
        const int f = free_index_[j.dof];
        if (f < 0) continue;
        J.emplace_back(f, free_count_ + c.eta, -j.dx.dot(pp.eta));
        if (c.xi >= 0) J.emplace_back(f, free_count_ + c.xi, -j.dx.dot(pp.xi));
      }
    }
  }

  // |R|^2 / 2 over the free dofs (moments over their length scale) + |F|^2 / 2: force units.
  double merit(const Vector& R, const Vector& F) const {
    double sum = F.squaredNorm();
    for (int i = 0; i < R.size(); ++i)
      if (free_index_[i] >= 0) sum += (R[i] / length_scales_[i]) * (R[i] / length_scales_[i]);
    return 0.5 * sum;
  }

  // r_i = augmentation / C_ii, each component's own contact stiffness, from the compliance at
  // the step's first solve (the mean of those where a component was out of reach then).
  void augmentations(const EquilibriumState& state) {
    const Compliance& C = eq_.compliance(state, relevant_components(), params_.sparse_compliance_from);
    r_ = Vector::Zero(problem_.component_count);
    double sum = 0.0;
    int count = 0;
    for (int k = 0; k < problem_.component_count; ++k) {
      const int a = C.position[k];
      if (a >= 0 && C.diagonal(a) > 0) {
        r_[k] = params_.augmentation / C.diagonal(a);
        sum += r_[k];
        ++count;
      }
    }
    const double fallback = count ? sum / count : params_.augmentation * eq_.stiffness_scale(state.q);
    for (int k = 0; k < problem_.component_count; ++k)
      if (r_[k] == 0.0) r_[k] = fallback;
  }

  // |F / r| over the components: the complementarity residual in length units.
  double scaled_length(const Vector& F) const { return F.cwiseQuotient(r_).norm(); }

  static constexpr int kMaxRestarts = 5;
  static constexpr int kMaxRises = 8;
  int rises_ = 0;                // real solves in a row whose contact error rose (drifting)
  double previous_error_ = 0.0;  // the contact error of the loop's last real solve
  std::vector<int> free_index_;
  int free_count_ = 0;
  Vector length_scales_;
  Vector r_;
};

}  // namespace

StepOutcome solve_ssn_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start, const Vector& p_star,
                           const ContactParams& params, int step, const IterationObserver& observer,
                           const StopRequest& stop) {
  return SsnStep(eq, params, step, observer, stop).run(q_guess, p_start, p_star);
}

}  // namespace grip
