#pragma once
// What the contact tolerance pins a converged step's forces to. The step ends at ||v|| <= tol,
// not at v = 0: to first order the exact forces (same active set) are p - dp with
// dp_E = C_EE^-1 v_E, C the compliance at the step's state (ALGORITHM.md 9; the tau passes
// stop on the same measure, StepSolver::force_precision). A check of forces against a closed
// form or against another run is then derived as (round-off) + |dp|, never a guessed number.
#include <Eigen/Cholesky>

#include "solver/contact/contact_error.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

// dp over every component (zero off the active set E of the step's final contact error).
inline Vector force_correction(const Scene& scene, const StepRecord& rec) {
  const Problem& problem = scene.problem;
  const ContactError e = contact_error(problem, rec.p, rec.state.s, rec.tau, rec.state.enabled);
  std::vector<int> idx;
  for (int i = 0; i < static_cast<int>(e.active.size()); ++i)
    if (e.active[i]) idx.push_back(i);
  Vector dp = Vector::Zero(rec.p.size());
  if (idx.empty()) return dp;
  Equilibrium eq(problem, scene.params.newton);
  eq.set_step(rec.factors, std::vector<double>(problem.candidates.size(), 0.0));
  const Compliance& C = eq.compliance(rec.state, idx);
  Vector v_e(idx.size());
  for (size_t a = 0; a < idx.size(); ++a) v_e[a] = e.v[idx[a]];
  const Vector d = Eigen::LLT<Matrix>(C.sub(idx)).solve(v_e);
  for (size_t a = 0; a < idx.size(); ++a) dp[idx[a]] = d[a];
  return dp;
}

// The largest |dp| over the normal and tangential components of every candidate.
inline double force_precision(const Scene& scene, const StepRecord& rec) {
  return force_correction(scene, rec).lpNorm<Eigen::Infinity>();
}

}  // namespace grip::testing
