#pragma once
// Newton's method on a body's free dofs with prescribed ones, for the tests of laws with
// history (j2_plasticity_test, j2_finite_test).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "solver/model/body.hpp"

namespace grip::testing {

// Newton's method on the free dofs of a body, the prescribed ones set in q; commits the state
// it converges to. `residuals` gets the free residual's norm at each iterate. With
// `line_search`, a step (and the predictor) that does not lower the residual's norm, or
// leaves a state without one (an inverted element), is halved up to 30 times.
struct Driver {
  Body& body;
  std::vector<char> prescribed;
  Vector q;
  std::vector<double> residuals;
  bool line_search = false;

  Driver(Body& b, std::vector<char> held) : body(b), prescribed(std::move(held)), q(Vector::Zero(b.dof_count())) {}

  Vector force(Triplets* t) const {
    Vector f = Vector::Zero(body.dof_count());
    if (!t) {
      body.internal_force(q, f, nullptr);
      return f;
    }
    TripletSink sink(*t);
    body.internal_force(q, f, &sink);
    return f;
  }

  using Sparse = Eigen::SparseMatrix<double>;
  using Factor = Eigen::SimplicialLDLT<Sparse>;

  // The free rows and columns of the tangent at q, factorized (sparse: refined meshes too).
  void free_tangent(const std::vector<int>& free, Vector* f, Sparse* full, Factor& factor) const {
    Triplets t;
    *f = force(&t);
    full->resize(body.dof_count(), body.dof_count());
    full->setFromTriplets(t.begin(), t.end());
    std::vector<int> index(body.dof_count(), -1);
    for (size_t i = 0; i < free.size(); ++i) index[free[i]] = static_cast<int>(i);
    Triplets tf;
    for (const auto& e : t)
      if (index[e.row()] >= 0 && index[e.col()] >= 0) tf.emplace_back(index[e.row()], index[e.col()], e.value());
    Sparse Kff(free.size(), free.size());
    Kff.setFromTriplets(tf.begin(), tf.end());
    if (!free.empty()) factor.compute(Kff);
  }

  // The prescribed values move first with the free dofs that the tangent at the converged
  // state predicts (a jump of the prescribed dofs alone would strain their elements by the
  // whole increment); then Newton's method from there.
  void solve(const std::function<void(Vector&)>& set_prescribed, double tolerance) {
    std::vector<int> free;
    for (int i = 0; i < body.dof_count(); ++i)
      if (!prescribed[i]) free.push_back(i);
    Vector target = q, f;
    set_prescribed(target);
    Sparse K;
    Factor factor;
    free_tangent(free, &f, &K, factor);
    const Vector jump = K * (target - q);
    Vector r(free.size());
    for (size_t i = 0; i < free.size(); ++i) r[i] = jump[free[i]];
    const Vector du = free.empty() ? Vector() : Vector(factor.solve(-r));
    q = target;
    step(free, du, std::numeric_limits<double>::infinity());
    residuals.clear();
    for (int it = 0; it < 40; ++it) {
      free_tangent(free, &f, &K, factor);
      for (size_t i = 0; i < free.size(); ++i) r[i] = f[free[i]];
      residuals.push_back(r.norm());
      if (r.norm() <= tolerance || free.empty()) break;
      step(free, factor.solve(-r), r.norm());
    }
    ASSERT_LE(residuals.back(), tolerance) << "Newton did not converge";
    body.commit(q);
  }

  // q += s dq on the free dofs, s = 1 or (line search) halved until the residual's norm is
  // finite and below `norm`.
  void step(const std::vector<int>& free, const Vector& dq, double norm) {
    for (int halvings = 0;; ++halvings) {
      const double s = std::ldexp(1.0, -halvings);
      Vector trial = q;
      for (size_t i = 0; i < free.size(); ++i) trial[free[i]] += s * dq[i];
      if (!line_search || halvings == 30) {
        q = trial;
        return;
      }
      Vector f = Vector::Zero(body.dof_count());
      body.internal_force(trial, f, nullptr);
      double trial_norm = 0.0;
      for (int i : free) trial_norm += f[i] * f[i];
      if (std::isfinite(trial_norm) && std::sqrt(trial_norm) < norm) {
        q = trial;
        return;
      }
    }
  }

  std::vector<double> element_row(int e) const { return body.element_fields(q).rows[e]; }
};

// Newton's quadratic rate on the residuals r of one solve, relative to the first: every
// iterate near the solution (e_k < 1e-2) whose successor is above round-off (1e-12) is checked
// for e_{k+1} <= 10 e_k^2. Returns how many were checked.
inline int expect_quadratic(const std::vector<double>& r) {
  int checked = 0;
  for (size_t k = 1; k + 1 < r.size(); ++k) {
    const double ek = r[k] / r[0], next = r[k + 1] / r[0];
    if (ek < 1e-2 && next > 1e-12) {
      EXPECT_LE(next, 10 * ek * ek) << "iteration " << k;
      ++checked;
    }
  }
  return checked;
}

// The residuals relative to the first, as printed beside each test's line (" 1.0e+00 8.6e-02 ...").
inline std::string relative_residuals(const std::vector<double>& r) {
  std::string line;
  char buffer[32];
  for (double v : r) {
    std::snprintf(buffer, sizeof buffer, " %.1e", v / r[0]);
    line += buffer;
  }
  return line;
}

}  // namespace grip::testing
