// The band Cholesky of small banded tangents (solver/solve/band_cholesky.hpp) against dense
// algebra, on a banded SPD matrix whose rows are numbered out of band order (as the beam's
// mid-element nodes are numbered after its end nodes).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <numeric>
#include <random>

#include "solver/solve/band_cholesky.hpp"

namespace grip {
namespace {

// A banded SPD matrix (half-bandwidth `band`, diagonally dominant) with its rows and columns
// shuffled.
Eigen::SparseMatrix<double> shuffled_band(int n, int band, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<int> label(n);
  std::iota(label.begin(), label.end(), 0);
  std::shuffle(label.begin(), label.end(), rng);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(label[i], label[i], 2.0 * band + 1.0);
    for (int j = i + 1; j <= std::min(n - 1, i + band); ++j) {
      const double v = u(rng);
      t.emplace_back(label[i], label[j], v);
      t.emplace_back(label[j], label[i], v);
    }
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

TEST(BandCholesky, SolvesEqualDenseOnAShuffledBand) {
  const int n = 120, band = 5;
  const Eigen::SparseMatrix<double> A = shuffled_band(n, band, 3);
  BandCholesky chol;
  const int b = chol.analyse(A);
  EXPECT_LE(b, 2 * band);  // reverse Cuthill-McKee recovers a narrow band (the shuffle alone: ~n)
  ASSERT_TRUE(chol.factorize(A));
  const Matrix dense = Matrix(A);
  const Eigen::LLT<Matrix> reference(dense);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix B(n, 70);  // more columns than G's blocks of 64, some of them unit columns
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < B.cols(); ++c) B(i, c) = c < 10 ? u(rng) : (i == (7 * c) % n ? 1.0 : 0.0);
  const Matrix X = chol.solve(B), Xref = reference.solve(B);
  EXPECT_LT((X - Xref).norm(), 1e-13 * Xref.norm());
  const Vector x = chol.solve(Vector(B.col(0))), xref = Xref.col(0);
  EXPECT_LT((x - xref).norm(), 1e-13 * xref.norm());
  // t_j^T A^-1 t_j for sparse columns.
  Eigen::SparseMatrix<double> t = B.rightCols(30).sparseView();
  const Vector q = chol.quadratic_forms(t);
  for (int c = 0; c < t.cols(); ++c) {
    const Vector tc = Matrix(t).col(c);
    EXPECT_NEAR(q[c], tc.dot(reference.solve(tc)), 1e-13 * q[c]) << "column " << c;
  }
  EXPECT_GT(chol.rcond(), 0.0);
}

TEST(BandCholesky, RefusesAnIndefiniteMatrix) {
  Eigen::SparseMatrix<double> A = shuffled_band(40, 3, 9);
  A.coeffRef(17, 17) = -1.0;
  BandCholesky chol;
  chol.analyse(A);
  EXPECT_FALSE(chol.factorize(A));
}

}  // namespace
}  // namespace grip
