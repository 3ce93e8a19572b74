// The inner contact problem's reduced Newton systems (solver/contact/newton_rows.hpp) against
// the full generalized Jacobian solved densely, as solve_coulomb_model did before: the same dx
// on a fresh Cholesky factorization, on a kept one corrected for rows that joined, left and
// slip, and on the small systems' LU.
#include "solver/contact/newton_rows.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <random>

namespace grip {
namespace {

// A compliance-like SPD matrix with a spread spectrum, seeded.
Compliance random_compliance(int m, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  Matrix A(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) A(i, j) = normal(gen);
  Compliance C;
  C.block = A * A.transpose() / m + 1e-2 * Matrix::Identity(m, m);
  C.position.resize(m);
  for (int i = 0; i < m; ++i) C.position[i] = i;
  return C;
}

// Components 2i (normal) and 2i+1 (tangent) of m / 2 points: `pressing` points have their
// normal active, the first `slipping` of them slip, the others stick; the rest are open.
NewtonRows kinds(const std::vector<int>& pressing, int slipping, unsigned seed) {
  std::mt19937 gen(seed);
  NewtonRows rows;
  for (size_t k = 0; k < pressing.size(); ++k) {
    const int eta = 2 * pressing[k], xi = eta + 1;
    rows.active.push_back(eta);
    if (static_cast<int>(k) < slipping) rows.slip.push_back({xi, eta, (gen() % 2 ? 0.3 : -0.3)});
    else rows.active.push_back(xi);
  }
  return rows;
}

// The old way: the whole m x m Jacobian, LU. The active rows' F equals s (r = 1).
Vector dense_reference(const Matrix& C, const Vector& F, const NewtonRows& rows) {
  const int m = static_cast<int>(F.size());
  Matrix J = Matrix::Identity(m, m);
  for (int k : rows.active) J.row(k) = C.row(k);
  for (const SlipRow& r : rows.slip) {
    J.row(r.xi) = r.c * C.row(r.eta);
    J(r.xi, r.eta) -= r.c;
    J(r.xi, r.xi) += 1.0;
  }
  return J.partialPivLu().solve(-F);
}

struct Case {
  Vector F, s;
};

Case random_case(const NewtonRows& rows, int m, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  Case c{Vector(m), Vector(m)};
  for (int k = 0; k < m; ++k) c.F[k] = normal(gen), c.s[k] = normal(gen);
  for (int k : rows.active) c.F[k] = c.s[k];
  return c;
}

double relative_difference(const Vector& a, const Vector& b) { return (a - b).norm() / b.norm(); }

TEST(NewtonRows, KeptFactorizationCorrectedForChangedRowsMatchesTheDenseJacobian) {
  const int points = 300, m = 2 * points;
  const Compliance C = random_compliance(m, 7);
  std::vector<int> pressing;
  for (int i = 0; i < 250; ++i) pressing.push_back(i);
  NewtonRowStats stats;

  const NewtonRows first = kinds(pressing, 0, 1);  // 500 active rows, no slip
  const Case a = random_case(first, m, 2);
  EXPECT_LT(relative_difference(solve_newton_rows(C, a.F, a.s, first, stats), dense_reference(C.block, a.F, first)),
            1e-10);
  EXPECT_EQ(stats.factorizations, 1);

  // Ten points leave, five join, six slip: a correction of rank 10 + 2 x 5 + 6 on the kept one.
  std::vector<int> changed(pressing.begin() + 10, pressing.end());
  for (int i = 250; i < 255; ++i) changed.push_back(i);
  std::rotate(changed.begin(), changed.begin() + 3, changed.end());  // order does not matter
  const NewtonRows second = kinds(changed, 6, 3);
  const Case b = random_case(second, m, 4);
  EXPECT_LT(relative_difference(solve_newton_rows(C, b.F, b.s, second, stats), dense_reference(C.block, b.F, second)),
            1e-10);
  EXPECT_EQ(stats.factorizations, 1);
  EXPECT_EQ(stats.capacitances, 2);

  // Half the points change: factorized afresh.
  std::vector<int> other;
  for (int i = 100; i < 300; ++i) other.push_back(i);
  const NewtonRows third = kinds(other, 4, 5);
  const Case c = random_case(third, m, 6);
  EXPECT_LT(relative_difference(solve_newton_rows(C, c.F, c.s, third, stats), dense_reference(C.block, c.F, third)),
            1e-10);
  EXPECT_EQ(stats.factorizations, 2);
}

TEST(NewtonRows, SmallSystemsAndSlipHeavyOnesMatchTheDenseJacobian) {
  const int points = 200, m = 2 * points;
  const Compliance C = random_compliance(m, 11);
  std::vector<int> few{3, 17, 40, 41, 150}, many;
  for (int i = 0; i < points; ++i) many.push_back(i);
  // 5 points (LU), 200 with 80 slipping (a slip coupling too wide to correct: LU), none.
  for (const NewtonRows& rows : {kinds(few, 2, 12), kinds(many, 80, 13), kinds({}, 0, 14)}) {
    NewtonRowStats stats;
    const Case k = random_case(rows, m, 15);
    EXPECT_LT(relative_difference(solve_newton_rows(C, k.F, k.s, rows, stats), dense_reference(C.block, k.F, rows)),
              1e-10);
  }
}

}  // namespace
}  // namespace grip
