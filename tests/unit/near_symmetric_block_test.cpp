// A near-symmetric block (FreeBlockSolver::factorize with a near-symmetric tolerance): Cholesky
// of its symmetric part serves only as long as refinement against the block itself reaches
// round-off; the solve is the block's own, never its symmetric part's.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "solver/solve/free_block_solver.hpp"

namespace grip {
namespace {

// A 5-point grid operator on n x n nodes: diagonal `diagonal` (plus the count of missing
// neighbours times `boundary`), -1 to each neighbour, and a skew part: +skew on the entry to the
// right-hand neighbour, -skew on its transpose (a convection-like term).
Triplets grid(int n, double diagonal, double boundary, double skew) {
  Triplets t;
  auto id = [&](int i, int j) { return i * n + j; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int missing = (i == 0) + (i + 1 == n) + (j == 0) + (j + 1 == n);
      t.emplace_back(id(i, j), id(i, j), diagonal + boundary * missing);
      if (i + 1 < n) t.emplace_back(id(i, j), id(i + 1, j), -1.0), t.emplace_back(id(i + 1, j), id(i, j), -1.0);
      if (j + 1 < n)
        t.emplace_back(id(i, j), id(i, j + 1), -1.0 + skew), t.emplace_back(id(i, j + 1), id(i, j), -1.0 - skew);
    }
  return t;
}

Matrix dense(const Triplets& t, int n) {
  Matrix K = Matrix::Zero(n, n);
  for (const auto& e : t) K(e.row(), e.col()) += e.value();
  return K;
}

std::vector<int> identity(int n) {
  std::vector<int> rows(n);
  for (int k = 0; k < n; ++k) rows[k] = k;
  return rows;
}

// The relative residual |K x - b|_inf / (|K|_inf |x|_inf + |b|_inf): round-off is a few 1e-16.
double backward_error(const Matrix& K, const Vector& x, const Vector& b) {
  return (K * x - b).lpNorm<Eigen::Infinity>() /
         (K.cwiseAbs().rowwise().sum().maxCoeff() * x.lpNorm<Eigen::Infinity>() + b.lpNorm<Eigen::Infinity>());
}

// Skew 1e-5 of the largest entry, well inside the 1e-4 tolerance; the symmetric part's smallest
// eigenvalue is about 0.03 (Dirichlet grid of 30 x 30 plus 0.01), so refinement contracts by
// about 2e-5 / 0.03 a pass. Symmetrizing alone would change the answer by about that much.
TEST(NearSymmetricBlock, IsSolvedExactlyByRefinement) {
  const int n = 30 * 30;
  const double skew = 4e-5;
  const Triplets t = grid(30, 4.01, 0.0, skew);
  FreeBlockSolver solver;
  ASSERT_TRUE(solver.factorize(t, identity(n), n, 1e-4));
  EXPECT_FALSE(solver.symmetric());  // the factor is not the block's
  const Matrix K = dense(t, n);
  const Vector b = Vector::LinSpaced(n, -1.0, 2.0);
  const Vector x = solver.solve(b);
  const Vector symmetrized = Matrix(0.5 * (K + K.transpose())).llt().solve(b);
  const double departure = (symmetrized - x).lpNorm<Eigen::Infinity>() / x.lpNorm<Eigen::Infinity>();
  std::printf("refined: backward error %.2e; the symmetric part's answer departs by %.2e\n", backward_error(K, x, b),
              departure);
  EXPECT_LT(backward_error(K, x, b), 1e-14);
  EXPECT_GT(departure, 1e-7);  // so the check above can tell the two apart
  // Several right-hand sides at once, the same way.
  Matrix B(n, 2);
  B << b, Vector::Ones(n);
  const Matrix X = solver.solve(B);
  for (int c = 0; c < 2; ++c) EXPECT_LT(backward_error(K, X.col(c), B.col(c)), 1e-14) << c;
}

// The same skew on a nearly singular symmetric part (a grid Laplacian with free edges plus
// 1e-6): |K_s^-1 (K - K_s)| is about 1e2, refinement diverges, and LU of the block answers.
TEST(NearSymmetricBlock, FallsBackToLUWhereRefinementCannotContract) {
  const int n = 30 * 30;
  const Triplets t = grid(30, 4.0 + 1e-6, -1.0, 4e-5);
  FreeBlockSolver solver;
  ASSERT_TRUE(solver.factorize(t, identity(n), n, 1e-4));
  const Matrix K = dense(t, n);
  const Vector b = Vector::LinSpaced(n, -1.0, 2.0);
  const Vector x = solver.solve(b);
  const Vector exact = K.partialPivLu().solve(b);
  std::printf("LU: backward error %.2e, against a dense LU %.2e\n", backward_error(K, x, b),
              (x - exact).lpNorm<Eigen::Infinity>() / exact.lpNorm<Eigen::Infinity>());
  EXPECT_LT(backward_error(K, x, b), 1e-14);
  // The condition number is about 1e7: the answers agree to that times round-off.
  EXPECT_LT((x - exact).lpNorm<Eigen::Infinity>(), 1e-7 * exact.lpNorm<Eigen::Infinity>());
  // Later solves with the same factorization go to LU directly, as exactly.
  const Vector y = solver.solve(Vector(Vector::Ones(n)));
  EXPECT_LT(backward_error(K, y, Vector::Ones(n)), 1e-14);
}

// Skew at round-off (1e-15 of the largest entry) is dropped: the block counts as symmetric.
TEST(NearSymmetricBlock, SkewAtRoundOffCountsAsSymmetric) {
  const int n = 30 * 30;
  FreeBlockSolver solver;
  ASSERT_TRUE(solver.factorize(grid(30, 4.01, 0.0, 4e-15), identity(n), n, 1e-4));
  EXPECT_TRUE(solver.symmetric());
}

}  // namespace
}  // namespace grip
