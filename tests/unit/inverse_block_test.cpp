// K^-1 on a few rows from CHOLMOD's partial forward solves (CholmodFactor::inverse_block)
// against full solves with unit right-hand sides.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <functional>
#include <thread>
#include <vector>

#include "solver/equilibrium/free_block_solver.hpp"

namespace grip {
namespace {

// The 5-point Laplacian of an nx x ny grid plus a small shift: SPD, sparse, a 2D mesh's pattern.
Eigen::SparseMatrix<double> grid_laplacian(int nx, int ny) {
  Triplets t;
  auto id = [&](int i, int j) { return i * ny + j; };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      t.emplace_back(id(i, j), id(i, j), 4.01);
      if (i + 1 < nx) t.emplace_back(id(i, j), id(i + 1, j), -1.0), t.emplace_back(id(i + 1, j), id(i, j), -1.0);
      if (j + 1 < ny) t.emplace_back(id(i, j), id(i, j + 1), -1.0), t.emplace_back(id(i, j + 1), id(i, j), -1.0);
    }
  Eigen::SparseMatrix<double> K(nx * ny, nx * ny);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

// CHOLMOD's two kinds of factor: the partial solves make a supernodal one simplicial, so they
// run on a copy of it; a simplicial one (a thin strip's block) they read as it is.
class InverseBlock : public ::testing::TestWithParam<int> {};

TEST_P(InverseBlock, SparseForwardSolvesEqualFullSolves) {
  const int nx = 60, ny = 60;
  const Eigen::SparseMatrix<double> K = grid_laplacian(nx, ny);
  CholmodFactor factor;
  factor.cholmod().supernodal = GetParam();
  factor.cholmod().final_ll = 1;
  factor.compute(K);
  ASSERT_EQ(factor.info(), Eigen::Success);
  ASSERT_EQ(factor.factor()->is_super != 0, GetParam() == CHOLMOD_SUPERNODAL);
  std::vector<int> rows;                                // two edges of the grid, as a contact surface (more rows than
  for (int i = 0; i < nx; ++i) rows.push_back(i * ny);  // G's sums take to run in tasks)
  for (int i = 0; i < nx; ++i) rows.push_back(i * ny + ny - 1);
  Matrix E = Matrix::Zero(K.rows(), rows.size());
  for (size_t a = 0; a < rows.size(); ++a) E(rows[a], a) = 1.0;
  const Matrix X = factor.solve(E);
  Matrix G;
  ASSERT_TRUE(factor.inverse_block(rows, G));
  Matrix reference(rows.size(), rows.size());
  for (size_t a = 0; a < rows.size(); ++a)
    for (size_t b = 0; b < rows.size(); ++b) reference(a, b) = X(rows[a], b);
  EXPECT_LT((G - reference).norm(), 1e-12 * reference.norm());
  EXPECT_EQ((G - G.transpose()).norm(), 0.0);
  // The factor itself is untouched: the same solves, to the last bit.
  EXPECT_EQ(factor.factor()->is_super != 0, GetParam() == CHOLMOD_SUPERNODAL);
  EXPECT_EQ((factor.solve(E) - X).norm(), 0.0);
  // A second G from the same factor (the storage kept from the first) is the same.
  Matrix again;
  ASSERT_TRUE(factor.inverse_block(rows, again));
  EXPECT_EQ((again - G).norm(), 0.0);
  // Its sums in tasks on threads of their own: each entry is summed by one task in the same
  // order, so G is the same to the last bit.
  const ParallelFor on_threads = [](int count, const std::function<void(int)>& task) {
    std::vector<std::thread> threads;
    for (int k = 0; k < count; ++k) threads.emplace_back(task, k);
    for (auto& t : threads) t.join();
  };
  Matrix parallel;
  ASSERT_TRUE(factor.inverse_block(rows, parallel, on_threads));
  EXPECT_EQ((parallel - G).norm(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Kinds, InverseBlock, ::testing::Values(CHOLMOD_SUPERNODAL, CHOLMOD_SIMPLICIAL),
                         [](const auto& info) {
                           return info.param == CHOLMOD_SUPERNODAL ? "supernodal" : "simplicial";
                         });

}  // namespace
}  // namespace grip
