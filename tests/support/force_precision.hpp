#pragma once
// What the contact tolerance pins a converged step's forces to. The step ends at ||v|| <= tol,
// not at v = 0: to first order the exact forces (same active set) are p - dp with
// dp_E = C_EE^-1 v_E, C the compliance at the step's state (ALGORITHM.md 9; the tau passes
// stop on the same measure, StepSolver::force_precision). A check of forces against a closed
// form or against another run is then derived as (round-off) + |dp|, never a guessed number.
#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "solver/contact/contact_error.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

// The active set E of a converged step's final contact error, with v_E and the compliance
// block C_EE at the step's state (bordered by the amplitudes' rows for a body held by contact).
struct ActiveBlock {
  std::vector<int> idx;
  Vector v;
  Matrix C;
  bool bordered = false;
};

inline ActiveBlock active_block(const Scene& scene, const StepRecord& rec) {
  const Problem& problem = scene.problem;
  const ContactError e = contact_error(problem, rec.p, rec.state.s, rec.tau, rec.state.enabled);
  ActiveBlock out;
  for (int i = 0; i < static_cast<int>(e.active.size()); ++i)
    if (e.active[i]) out.idx.push_back(i);
  if (out.idx.empty()) return out;
  Equilibrium eq(problem, scene.params.newton);
  eq.set_step(rec.factors, std::vector<double>(problem.candidates.size(), 0.0));
  const Compliance& C = eq.compliance(rec.state, out.idx);
  out.C = C.sub(out.idx);
  out.bordered = C.bordered;
  out.v.resize(out.idx.size());
  for (size_t a = 0; a < out.idx.size(); ++a) out.v[a] = e.v[out.idx[a]];
  return out;
}

// dp over every component (zero off the active set E of the step's final contact error).
inline Vector force_correction(const Scene& scene, const StepRecord& rec) {
  const ActiveBlock E = active_block(scene, rec);
  const std::vector<int>& idx = E.idx;
  Vector dp = Vector::Zero(rec.p.size());
  if (idx.empty()) return dp;
  // A body held by contact: the bordered block [C G; G^T 0] (its amplitudes' rows), symmetric
  // but indefinite.
  const Vector d = E.bordered ? Vector(Eigen::FullPivLU<Matrix>(E.C).solve(E.v))
                              : Vector(Eigen::LLT<Matrix>(E.C).solve(E.v));
  for (size_t a = 0; a < idx.size(); ++a) dp[idx[a]] = d[a];
  return dp;
}

// The largest |dp| over the normal and tangential components of every candidate.
inline double force_precision(const Scene& scene, const StepRecord& rec) {
  const RigidModes& rigid = scene.problem.rigid;
  return force_correction(scene, rec).head(rigid.count() ? rigid.first : rec.p.size()).lpNorm<Eigen::Infinity>();
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

// How far step `rec` of run `s` may lie from step `ref` of a run of the same scene by cev's default
// loop, whose previous steps differed by `carried` (each step's slips are measured from the state
// it starts from): what each run's contact error pins its forces to (force_precision), and, where
// tau passes hold the bound at mu |p*|, p* settled to max(tau_tolerance max |p_eta|, its force
// precision) (StepSolver::tau_passes), which moves each slipping point's force by mu times that and
// hands the sum of those moves to the sticking points: at most (number of points) x mu x that.
inline double agreement_bound(const Solved& s, const StepRecord& rec, const Solved& cev, const StepRecord& ref,
                              double carried) {
  const ContactParams& cp = s.scene.params.contact;
  const bool passes = cp.method == ContactMethod::uzawa || cp.loop == ContactLoop::paper ||
                      (cp.method == ContactMethod::cev && cp.friction_loop == FrictionLoop::passes);
  double p_max = 0.0, mu = 0.0;
  for (const Candidate& c : s.scene.problem.candidates) {
    p_max = std::max(p_max, std::abs(ref.p[c.eta]));
    mu = std::max(mu, s.scene.problem.obstacles[c.obstacle].friction);
  }
  const double own = force_precision(s.scene, rec);
  const double settle =
      passes ? static_cast<double>(s.scene.problem.candidates.size()) * mu * std::max(cp.tau_tolerance * p_max, own) : 0.0;
  return 1e-9 * p_max + own + force_precision(cev.scene, ref) + settle + carried;
}

}  // namespace grip::testing

namespace grip::testing {

// Two runs whose previous steps ended at positions that differ by what their contact tolerance
// allows (dzeta of each point along its obstacle) measure this step's slips from different
// references (s_xi = zeta - zeta_previous): a sticking point then holds a different position, so
// their forces differ by C_EE^-1 dzeta on the active block of this step (rec of run s). Friction's
// history, which the previous step's force difference (agreement_bound's `carried`) does not
// cover: the paper's loop on the free beam, 1.3e-3 from cev at the first push level where step 1's
// forces differed by 8.7e-5 only.
inline double reference_shift(const Solved& s, const StepRecord& rec, const StepRecord& previous,
                              const StepRecord& previous_ref) {
  const ActiveBlock E = active_block(s.scene, rec);
  if (E.idx.empty()) return 0.0;
  const Problem& problem = s.scene.problem;
  Vector shift = Vector::Zero(E.idx.size());
  for (size_t a = 0; a < E.idx.size(); ++a)
    for (size_t i = 0; i < problem.candidates.size(); ++i)
      if (problem.candidates[i].xi == E.idx[a])
        shift[a] = previous.state.points[i].projection.zeta - previous_ref.state.points[i].projection.zeta;
  const Vector dp = E.bordered ? Vector(Eigen::FullPivLU<Matrix>(E.C).solve(shift))
                               : Vector(Eigen::LLT<Matrix>(E.C).solve(shift));
  double largest = 0.0;
  for (size_t a = 0; a < E.idx.size(); ++a)
    if (!problem.rigid.is_amplitude(E.idx[a])) largest = std::max(largest, std::abs(dp[a]));
  return largest;
}

}  // namespace grip::testing
