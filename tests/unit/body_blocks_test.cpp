// The bodies' own factorizations (FreeBlockSolver::set_blocks): a block-diagonal free block is
// factorized and solved body by body, each body's work through the caller's executor, with the
// answers of one factorization of the whole; an entry between two bodies keeps it whole.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>

#include "solver/equilibrium/free_block_solver.hpp"
#include "solver/io/scene.hpp"
#include "solver/stepping/load_stepping.hpp"

namespace grip {
namespace {

// Two 5-point grid Laplacians (plus a shift, SPD) one after the other, as two bodies' tangents
// of 45 x 45 and 40 x 40 nodes; `couple` adds one symmetric entry between them.
Triplets two_grids(bool couple) {
  Triplets t;
  int offset = 0;
  for (int n : {45, 40}) {
    auto id = [&](int i, int j) { return offset + i * n + j; };
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        t.emplace_back(id(i, j), id(i, j), 4.01 + 0.001 * offset);
        if (i + 1 < n) t.emplace_back(id(i, j), id(i + 1, j), -1.0), t.emplace_back(id(i + 1, j), id(i, j), -1.0);
        if (j + 1 < n) t.emplace_back(id(i, j), id(i, j + 1), -1.0), t.emplace_back(id(i, j + 1), id(i, j), -1.0);
      }
    offset += n * n;
  }
  if (couple) t.emplace_back(0, offset - 1, -0.5), t.emplace_back(offset - 1, 0, -0.5);
  return t;
}

// Runs the tasks last to first and counts them: the order must not matter.
struct ReversedCounter {
  std::shared_ptr<std::atomic<int>> tasks = std::make_shared<std::atomic<int>>(0);
  void operator()(int count, const std::function<void(int)>& task) const {
    for (int k = count - 1; k >= 0; --k, ++*tasks) task(k);
  }
};

// The two grids factorized whole and with the bodies' blocks declared (tasks counted).
struct BothWays {
  static constexpr int n = 45 * 45 + 40 * 40;
  FreeBlockSolver whole, parts;
  ReversedCounter counter;
  explicit BothWays(const Triplets& t) {
    std::vector<int> identity(n);
    for (int k = 0; k < n; ++k) identity[k] = k;
    parts.set_blocks({0, 45 * 45, n}, counter);
    factorized = whole.factorize(t, identity, n) && parts.factorize(t, identity, n);
  }
  bool factorized = false;
};

TEST(BodyBlocks, EachBodyOnItsOwnGivesTheWholeFactorizationsAnswers) {
  const Triplets t = two_grids(false);
  BothWays both(t);
  ASSERT_TRUE(both.factorized);
  const int n = both.n;
  FreeBlockSolver &whole = both.whole, &parts = both.parts;
  const ReversedCounter& counter = both.counter;
  EXPECT_FALSE(whole.split());
  EXPECT_TRUE(parts.split());
  EXPECT_TRUE(parts.symmetric());
  EXPECT_EQ(*counter.tasks, 2);  // the two bodies' factorizations (3625 rows: over the threshold)
  Vector b = Vector::LinSpaced(n, -1.0, 2.0);
  const Vector x = whole.solve(b), y = parts.solve(b);
  EXPECT_LT((x - y).norm(), 1e-13 * x.norm());
  EXPECT_EQ(*counter.tasks, 4);
  // K^-1 on rows of both bodies: the blocks between bodies are exactly zero.
  const std::vector<int> rows = {3, 44, 2024, 45 * 45 + 7, 45 * 45 + 39, 100};
  Matrix G, H;
  ASSERT_TRUE(whole.inverse_block(rows, G));
  ASSERT_TRUE(parts.inverse_block(rows, H));
  EXPECT_LT((G - H).norm(), 1e-13 * G.norm());
  EXPECT_EQ(H(0, 3), 0.0);
  EXPECT_EQ(H(4, 5), 0.0);
  // t^T K^-1 t for columns on one body, on the other, and on both.
  Eigen::SparseMatrix<double> cols(n, 3);
  Triplets ct = {{5, 0, 1.0}, {6, 0, -0.5}, {45 * 45 + 3, 1, 2.0}, {10, 2, 1.0}, {45 * 45 + 10, 2, 1.0}};
  cols.setFromTriplets(ct.begin(), ct.end());
  const Vector qa = whole.quadratic_forms(cols), qb = parts.quadratic_forms(cols);
  ASSERT_EQ(qb.size(), 3);
  EXPECT_LT((qa - qb).norm(), 1e-13 * qa.norm());
}

TEST(BodyBlocks, AnEntryBetweenBodiesKeepsOneFactorization) {
  const Triplets t = two_grids(true);
  BothWays both(t);
  ASSERT_TRUE(both.factorized);
  const int n = both.n;
  FreeBlockSolver &whole = both.whole, &parts = both.parts;
  const ReversedCounter& counter = both.counter;
  EXPECT_FALSE(parts.split());
  EXPECT_EQ(*counter.tasks, 0);
  const Vector b = Vector::LinSpaced(n, -1.0, 2.0);
  EXPECT_EQ((whole.solve(b) - parts.solve(b)).norm(), 0.0);
}

// The two cylinders of the example scene (issue 19's Hertz pair, linear kinematics) with the
// bodies' work run through an executor in reverse order: the same numbers to the last bit, and
// the executor was used.
TEST(BodyBlocks, TwoCylindersTheSameWithAnyOrderOfTheBodies) {
  Scene serial = read_scene_file(GRIP_SOURCE_DIR "/schemas/examples/two-cylinders.json");
  Scene reversed = read_scene_file(GRIP_SOURCE_DIR "/schemas/examples/two-cylinders.json");
  ReversedCounter counter;
  reversed.params.newton.parallel = counter;
  const RunResult a = run_load_steps(serial.problem, serial.steps, serial.params);
  const RunResult b = run_load_steps(reversed.problem, reversed.steps, reversed.params);
  ASSERT_TRUE(a.completed);
  ASSERT_TRUE(b.completed);
  EXPECT_GT(*counter.tasks, 0);
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (size_t k = 0; k < a.steps.size(); ++k) {
    EXPECT_EQ((a.steps[k].p - b.steps[k].p).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((a.steps[k].state.q - b.steps[k].state.q).cwiseAbs().maxCoeff(), 0.0);
  }
  EXPECT_EQ(a.counters.newton_iterations, b.counters.newton_iterations);
}

}  // namespace
}  // namespace grip
