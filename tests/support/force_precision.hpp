#pragma once
// What the contact error a converged step reached pins its forces to. The step ends at
// ||v|| <= tol, not at v = 0: to first order the exact forces (same active set) are p - dp with
// A dp_E = v_E, A the compliance block at the step's state
// (docs/algorithm.md#friction_loop-passes-the-tau-passes: the tau passes stop on C_EE^-1 v,
// StepSolver::force_precision), coupled with the slipping points where the friction bound moves
// (force_error). A check of forces against a closed form or against another run is then derived as
// (round-off) + |dp|, never a guessed number.
#include <Eigen/LU>
#include <limits>

#include "solver/contact/contact_error.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

inline constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// The first-order errors of a converged step's forces, p - p_exact (the exact answer of the same
// load path): on the active set E of its final contact error, A dp_E = r_E with A the compliance
// block C_EE at the step's state (bordered by the amplitudes' rows for a body held by contact)
// and, where the friction bound moves with p_eta (cev's default loop, ssn: friction_bound_moves),
// a slipping point's friction force sign(p_xi) mu |p_eta| moving with its normal force: column
// eta of A gets -sign(p_xi) mu C_{E,xi}. `own`: r = v, the step's own contact error. `carried`:
// r = the previous step's position error on E's tangential rows, since this step's slips are
// measured from that state (docs/algorithm.md#notation: s_xi = zeta - zeta_prev). `drift`: the
// tangential position error this step hands on, C (own + carried) on every tangential component.
// Measured on the von Karman beam pushed along a flat (tolerance 1e-8 against 1e-12): C_EE^-1 v
// alone left 3.4e-5 of cev's 9.7e-5 at the first push level (the carried part) and 3.4e-6 of 1.1e-5
// at the second (the slipping points' coupling); own + carried leave 2e-8 and 7e-9. `rounding`:
// what the rounding of s pins the forces to, ||A^-1||_inf (force rows) x 2 eps x the largest
// coordinate that a gap or slip is a difference of (positions, zeta): on the von Karman beam (zeta
// up to 100) two runs at tolerance 1e-12 still differed by 1e-8 .. 3e-8.
struct ForceError {
  Vector own, carried, drift;
  double rounding = 0.0;
};

inline ForceError force_error(const Scene& scene, const StepRecord& rec, const Vector& drift_in) {
  const Problem& problem = scene.problem;
  const ContactError e = contact_error(problem, rec.p, rec.state.s, rec.tau, rec.state.enabled);
  ForceError out{Vector::Zero(rec.p.size()), Vector::Zero(rec.p.size()), Vector::Zero(rec.p.size())};
  std::vector<int> all, position(rec.p.size(), -1);
  for (int i = 0; i < static_cast<int>(e.active.size()); ++i)
    if (e.active[i]) position[i] = static_cast<int>(all.size()), all.push_back(i);
  const int n = static_cast<int>(all.size());
  if (n == 0) return out;
  // Then the other tangential components (their drift), the slipping ones among them coupled.
  std::vector<int> tangential;
  struct Slip {
    int row, eta;  // rows of p_xi and p_eta in `all`
    double slope;  // dp_xi / dp_eta = -sign(p_xi) mu
  };
  std::vector<Slip> slips;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (c.xi < 0 || !rec.state.enabled[c.xi]) continue;
    tangential.push_back(c.xi);
    if (e.active[c.xi]) continue;
    if (friction_bound_moves(scene.params.contact) && e.active[c.eta] && rec.p[c.eta] < 0 && rec.tau[i] > 0 &&
        std::abs(rec.p[c.xi]) >= rec.tau[i] * (1 - kBoundTolerance))
      slips.push_back({static_cast<int>(all.size()), position[c.eta],
                       (rec.p[c.xi] > 0 ? -1.0 : 1.0) * problem.obstacles[c.obstacle].friction});
    position[c.xi] = static_cast<int>(all.size());
    all.push_back(c.xi);
  }
  Equilibrium eq(problem, scene.params.newton);
  eq.set_step(rec.factors, std::vector<double>(problem.candidates.size(), 0.0));
  const Matrix full = eq.compliance(rec.state, all).sub(all);
  Matrix A = full.topLeftCorner(n, n);
  for (const Slip& sl : slips) A.col(sl.eta) += sl.slope * full.block(0, sl.row, n, 1);
  const Eigen::FullPivLU<Matrix> lu(A);
  double magnitude = 0.0;
  for (const PairedPoint& pp : rec.state.points)
    magnitude = std::max({magnitude, pp.point.x.lpNorm<Eigen::Infinity>(), std::abs(pp.projection.zeta)});
  const Matrix inverse = lu.inverse();
  for (int a = 0; a < n; ++a)
    if (!problem.rigid.is_amplitude(all[a]))
      out.rounding = std::max(out.rounding, inverse.row(a).cwiseAbs().sum() * 2 * kEpsilon * magnitude);
  auto solve = [&](const Vector& r) {
    Vector rhs(n), dp = Vector::Zero(rec.p.size());
    for (int a = 0; a < n; ++a) rhs[a] = r[all[a]];
    const Vector d = lu.solve(rhs);
    for (int a = 0; a < n; ++a) dp[all[a]] = d[a];
    for (const Slip& sl : slips) dp[all[sl.row]] = sl.slope * d[sl.eta];
    return dp;
  };
  Vector drift = Vector::Zero(rec.p.size());
  for (int j : tangential) drift[j] = drift_in[j];
  out.own = solve(e.v);
  out.carried = solve(drift);
  Vector total(all.size());
  for (size_t a = 0; a < all.size(); ++a) total[a] = out.own[all[a]] + out.carried[all[a]];
  const Vector moved = full * total;
  for (int j : tangential) out.drift[j] = moved[position[j]];
  return out;
}

// The errors of a run's converged steps 0..last, each step's drift carried into the next.
inline std::vector<ForceError> force_errors(const Solved& s, size_t last) {
  std::vector<ForceError> out;
  Vector drift = Vector::Zero(s.scene.problem.component_count);
  for (size_t k = 0; k <= last && k < s.run.steps.size() && s.run.steps[k].converged; ++k) {
    out.push_back(force_error(s.scene, s.run.steps[k], drift));
    drift = out.back().drift;
  }
  return out;
}

// The largest |dp| over the normal and tangential components of every candidate.
inline double largest_force(const Problem& problem, const Vector& dp) {
  return dp.head(problem.rigid.count() ? problem.rigid.first : dp.size()).lpNorm<Eigen::Infinity>();
}

// dp over every component from the step's own contact error (zero off E and the slipping points).
inline Vector force_correction(const Scene& scene, const StepRecord& rec) {
  return force_error(scene, rec, Vector::Zero(rec.p.size())).own;
}

inline double force_precision(const Scene& scene, const StepRecord& rec) {
  return largest_force(scene.problem, force_correction(scene, rec));
}

}  // namespace grip::testing

namespace grip::testing {

// The largest difference of the normal and tangential forces of two runs' steps of one scene.
inline double force_difference(const Problem& problem, const StepRecord& a, const StepRecord& b) {
  double largest = 0.0;
  for (const Candidate& c : problem.candidates) {
    largest = std::max(largest, std::abs(a.p[c.eta] - b.p[c.eta]));
    if (c.xi >= 0) largest = std::max(largest, std::abs(a.p[c.xi] - b.p[c.xi]));
  }
  return largest;
}

// How far step k of run `s` may lie from step k of a run of the same scene by cev's default loop:
// each run's first-order error (force_error: its own contact error and the one carried from its
// previous steps' positions, each bounded by its largest component, and the rounding of s), the
// forces' own rounding (1e-9 of the largest normal force), and, where tau passes hold the bound at mu |p*|, p* settled to
// max(tau_tolerance max |p_eta|, its force precision) (StepSolver::tau_passes), which moves each
// slipping point's force by mu times that and hands the sum of those moves to the sticking points:
// at most (number of points) x mu x that.
inline double agreement_bound(const Solved& s, size_t k, const Solved& cev) {
  const ContactParams& cp = s.scene.params.contact;
  const bool passes = cp.method == ContactMethod::uzawa || cp.loop == ContactLoop::paper ||
                      (cp.method == ContactMethod::cev && cp.friction_loop == FrictionLoop::passes);
  const StepRecord &rec = s.run.steps[k], &ref = cev.run.steps[k];
  double p_max = 0.0, mu = 0.0;
  for (const Candidate& c : s.scene.problem.candidates) {
    p_max = std::max(p_max, std::abs(ref.p[c.eta]));
    mu = std::max(mu, s.scene.problem.obstacles[c.obstacle].friction);
  }
  double errors = 0.0;
  for (const Solved* run : {&s, &cev}) {
    const ForceError e = force_errors(*run, k).back();
    errors += largest_force(run->scene.problem, e.own) + largest_force(run->scene.problem, e.carried) + e.rounding;
  }
  const double own = force_precision(s.scene, rec);
  const double settle =
      passes ? static_cast<double>(s.scene.problem.candidates.size()) * mu * std::max(cp.tau_tolerance * p_max, own)
             : 0.0;
  return 1e-9 * p_max + errors + settle;
}

}  // namespace grip::testing
