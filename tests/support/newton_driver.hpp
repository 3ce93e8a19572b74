#pragma once
// Newton's method on a body's free dofs with prescribed ones, for the tests of laws with
// history (j2_plasticity_test, j2_finite_test).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <functional>
#include <vector>

#include "solver/model/body.hpp"

namespace grip::testing {

// Newton's method on the free dofs of a body, the prescribed ones set in q; commits the state
// it converges to. `residuals` gets the free residual's norm at each iterate.
struct Driver {
  Body& body;
  std::vector<char> prescribed;
  Vector q;
  std::vector<double> residuals;

  Driver(Body& b, std::vector<char> held) : body(b), prescribed(std::move(held)), q(Vector::Zero(b.dof_count())) {}

  Vector force(Triplets* t) const {
    Vector f = Vector::Zero(body.dof_count());
    body.internal_force(q, f, t);
    return f;
  }

  // The free rows of the tangent at q, factorized.
  Eigen::LDLT<Matrix> free_tangent(const std::vector<int>& free, Vector* f, Matrix* full) const {
    Triplets t;
    *f = force(&t);
    Eigen::SparseMatrix<double> K(body.dof_count(), body.dof_count());
    K.setFromTriplets(t.begin(), t.end());
    *full = Matrix(K);
    Matrix Kff(free.size(), free.size());
    for (size_t i = 0; i < free.size(); ++i)
      for (size_t j = 0; j < free.size(); ++j) Kff(i, j) = (*full)(free[i], free[j]);
    return Kff.ldlt();
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
    Matrix K;
    const Eigen::LDLT<Matrix> predictor = free_tangent(free, &f, &K);
    const Vector jump = K * (target - q);
    Vector r(free.size());
    for (size_t i = 0; i < free.size(); ++i) r[i] = jump[free[i]];
    const Vector du = free.empty() ? Vector() : Vector(predictor.solve(-r));
    q = target;
    for (size_t i = 0; i < free.size(); ++i) q[free[i]] += du[i];
    residuals.clear();
    for (int it = 0; it < 30; ++it) {
      const Eigen::LDLT<Matrix> Kff = free_tangent(free, &f, &K);
      for (size_t i = 0; i < free.size(); ++i) r[i] = f[free[i]];
      residuals.push_back(r.norm());
      if (r.norm() <= tolerance || free.empty()) break;
      const Vector dq = Kff.solve(-r);
      for (size_t i = 0; i < free.size(); ++i) q[free[i]] += dq[i];
    }
    ASSERT_LE(residuals.back(), tolerance) << "Newton did not converge";
    body.commit(q);
  }

  std::vector<double> element_row(int e) const { return body.element_fields(q).rows[e]; }
};

}  // namespace grip::testing
