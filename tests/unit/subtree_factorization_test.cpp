// A large simplicial Cholesky factorization on two threads (FreeBlockSolver::set_parallel,
// CholmodFactor::factorize_ordered): two groups of independent subtrees of the elimination
// tree at once, then the rows above them. Each row is the same arithmetic as in CHOLMOD's own
// row-by-row factorization, so the factor, and every solve with it, is the serial one to the
// last bit; a block that is not positive definite is found so on both paths.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "apps/thread_team.hpp"
#include "solver/equilibrium/free_block_solver.hpp"

namespace grip {
namespace {

ParallelFor two_threads() {
  auto team = std::make_shared<ThreadTeam>(2);
  return [team](int count, const std::function<void(int)>& task) { team->run(count, task); };
}

// Strips of nx x ny nodes, two dofs each (strips side by side share no entry): every cell
// couples its four nodes, k (I - J / 4) per direction, k varying from cell to cell, with a
// spring to ground of `ground` at every dof (at `soft_dof`, -10: not positive definite).
void emit_strips(TangentSink& sink, int strips, int nx, int ny, double ground, int soft_dof = -1) {
  const int per_strip = 2 * nx * ny;
  for (int s = 0; s < strips; ++s)
    for (int i = 0; i + 1 < nx; ++i)
      for (int j = 0; j + 1 < ny; ++j) {
        const int nodes[4] = {i * ny + j, (i + 1) * ny + j, (i + 1) * ny + j + 1, i * ny + j + 1};
        int dofs[8];
        for (int a = 0; a < 4; ++a)
          for (int d = 0; d < 2; ++d) dofs[2 * a + d] = s * per_strip + 2 * nodes[a] + d;
        const double k = 1.0 + 0.3 * std::sin(0.7 * i + 1.3 * j + s);
        Matrix block = Matrix::Zero(8, 8);
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b)
            for (int d = 0; d < 2; ++d) block(2 * a + d, 2 * b + d) = k * ((a == b ? 1.0 : 0.0) - 0.25);
        sink.add_block(dofs, block);
      }
  for (int dof = 0; dof < strips * per_strip; ++dof) sink.add(dof, dof, dof == soft_dof ? -10.0 : ground);
}

struct Factorized {
  FreeBlockSolver solver;
  bool ok = false;
  Factorized(int strips, int nx, int ny, const ParallelFor& parallel, int soft_dof = -1) {
    const int n = 2 * strips * nx * ny;
    free_index.resize(n);
    for (int i = 0; i < n; ++i) free_index[i] = i;
    solver.set_parallel(parallel);
    for (int repeat = 0; repeat < 3; ++repeat) {  // the rows' split is planned from the first factor
      emit_strips(solver.assemble(free_index, n), strips, nx, ny, 1e-3 * (1 + repeat), soft_dof);
      ok = solver.factorize();
    }
  }
  std::vector<int> free_index;
};

Vector load(int n) {
  Vector b(n);
  for (int i = 0; i < n; ++i) b[i] = std::cos(0.37 * i) * (i % 5 - 2);
  return b;
}

void expect_same_solves(const FreeBlockSolver& serial, const FreeBlockSolver& split) {
  const Vector b = load(static_cast<int>(serial.matrix().rows()));
  Vector x, y;
  serial.solve_into(b, x);
  split.solve_into(b, y);
  ASSERT_EQ(x.size(), y.size());
  for (int i = 0; i < x.size(); ++i) ASSERT_EQ(x[i], y[i]) << "row " << i;
  const Vector residual = split.matrix() * y - b;
  EXPECT_LT(residual.cwiseAbs().maxCoeff(), 1e-9 * b.cwiseAbs().maxCoeff());
}

// The split path taken on two threads, not on one, and its solves the serial ones to the bit.
void expect_split_serial_bits(int strips, int nx, int ny) {
  Factorized serial(strips, nx, ny, {});
  Factorized split(strips, nx, ny, two_threads());
  ASSERT_TRUE(serial.ok);
  ASSERT_TRUE(split.ok);
  EXPECT_FALSE(serial.solver.rows_split());
  EXPECT_TRUE(split.solver.rows_split()) << "the rows were not split";
  expect_same_solves(serial.solver, split.solver);
}

TEST(SubtreeFactorization, ThinStripIsTheSerialFactorToTheBit) {
  // 400 x 3 nodes, 2400 rows: a fill-reducing order of a strip is nearly banded; the middle
  // cross-section ordered last splits it in two.
  expect_split_serial_bits(1, 400, 3);
}

TEST(SubtreeFactorization, TwoUncoupledStripsSplitByTheirOwnTrees) { expect_split_serial_bits(2, 250, 3); }

TEST(SubtreeFactorization, NotPositiveDefiniteOnBothPaths) {
  // One dof's spring to ground negative and larger than its cells' stiffness: Cholesky fails on
  // either path and both fall back to the same LU.
  Factorized serial(1, 400, 3, {}, 1201);
  Factorized split(1, 400, 3, two_threads(), 1201);
  ASSERT_TRUE(serial.ok);
  ASSERT_TRUE(split.ok);
  EXPECT_FALSE(serial.solver.symmetric());
  EXPECT_FALSE(split.solver.symmetric());
  expect_same_solves(serial.solver, split.solver);
}

TEST(SubtreeFactorization, SmallBlockStaysOnTheCallingThread) {
  Factorized split(1, 100, 3, two_threads());  // 600 rows
  ASSERT_TRUE(split.ok);
  EXPECT_FALSE(split.solver.rows_split());
}

}  // namespace
}  // namespace grip
