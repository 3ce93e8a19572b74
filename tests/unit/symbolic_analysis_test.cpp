// Symbolic analyses (ordering, elimination tree) once per sparsity pattern (issue 39):
// FreeBlockSolver::analyses() and the counters newton_analyses / body_analyses against the
// patterns counted independently; and solve_into (Newton's solve into kept storage, by
// cholmod_solve2) the same values as solve() bit for bit.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "solver/equilibrium/free_block_solver.hpp"
#include "solver/io/scene.hpp"
#include "solver/stepping/load_stepping.hpp"

namespace grip {
namespace {

// A chain of n dofs (dof 0 prescribed): springs between neighbours (stiffness k_i), a spring to
// ground at every dof, and (extra) one more entry pair coupling dofs 1 and n - 1: another pattern.
void emit_chain(TangentSink& sink, int n, double scale, bool extra) {
  for (int i = 0; i + 1 < n; ++i) {
    const double k = scale * (1.0 + 0.1 * i);
    const int d[2] = {i, i + 1};
    Matrix block(2, 2);
    block << k, -k, -k, k;
    sink.add_block(d, block);
  }
  for (int i = 0; i < n; ++i) sink.add(i, i, 0.5 * scale);
  if (extra) {
    sink.add(1, n - 1, -0.1 * scale);
    sink.add(n - 1, 1, -0.1 * scale);
  }
}

TEST(SymbolicAnalysis, OncePerPatternOfTheBlock) {
  const int n = 40;
  std::vector<int> free_index(n);
  for (int i = 0; i < n; ++i) free_index[i] = i - 1;  // dof 0 prescribed
  FreeBlockSolver solver;
  // The pattern counted here, independently: a new one where `extra` changes.
  int patterns = 0;
  bool last_extra = false;
  const bool sequence[] = {false, false, false, true, true, false, false};
  int step = 0;
  for (const bool extra : sequence) {
    if (step == 0 || extra != last_extra) ++patterns;
    last_extra = extra;
    emit_chain(solver.assemble(free_index, n - 1), n, 1.0 + step, extra);
    ASSERT_TRUE(solver.factorize());
    ASSERT_TRUE(solver.symmetric());
    ++step;
    EXPECT_EQ(solver.factorizations(), step);
    EXPECT_EQ(solver.analyses(), patterns) << "after factorization " << step;
  }
  EXPECT_EQ(patterns, 3);
}

TEST(SymbolicAnalysis, SolveIntoIsSolveBitForBit) {
  const int n = 60;
  std::vector<int> free_index(n);
  for (int i = 0; i < n; ++i) free_index[i] = i - 1;
  FreeBlockSolver solver;
  emit_chain(solver.assemble(free_index, n - 1), n, 2.0, true);
  ASSERT_TRUE(solver.factorize());
  Vector b(n - 1), x;
  for (int i = 0; i < n - 1; ++i) b[i] = std::sin(1.0 + i) * (i % 7 - 3);
  for (int repeat = 0; repeat < 3; ++repeat) {  // the kept workspace reused
    solver.solve_into(b, x);
    const Vector y = solver.solve(b);
    ASSERT_EQ(x.size(), y.size());
    for (int i = 0; i < y.size(); ++i) EXPECT_EQ(x[i], y[i]) << i;
    // And it solves: K x = b to round-off.
    const Vector residual = solver.matrix() * x - b;
    EXPECT_LT(residual.cwiseAbs().maxCoeff(), 1e-12 * b.cwiseAbs().maxCoeff());
    b = b.reverse().eval() * -1.5;
  }
}

// The finite-strain strip on a cylinder (q9 50 x 2, a changing tangent: one factorization of
// Newton's tangent per iteration). Its candidates and supports stay the same through the run
// (counted: no candidate added), so Newton's tangent keeps one pattern: one analysis for all
// its factorizations, and one more where G came from Newton's factor and its order turned to
// nested dissection (FreeBlockSolver::inverse_block; measured: 2 in 10 steps, 1 in 20). The
// body's own tangent (the compliance's) has one pattern too: its analysis, its nested-dissection
// factor's for G and the turn of its own order, 3 in either run, however many factorizations.
TEST(SymbolicAnalysis, OncePerPatternThroughTheFiniteStrip) {
  EquilibriumCounters counters[2];
  for (const int steps : {10, 20}) {
    std::ifstream in(std::string(GRIP_SOURCE_DIR) + "/schemas/examples/strip-on-cylinder.json");
    nlohmann::json j = nlohmann::json::parse(in);
    j["steps"] = steps;
    Scene scene = read_scene(j);
    const size_t candidates = scene.problem.candidates.size();
    const RunResult run = run_load_steps(scene.problem, scene.steps, scene.params);
    ASSERT_TRUE(run.completed) << run.reason;
    ASSERT_EQ(scene.problem.candidates.size(), candidates);  // one pattern: no candidate added
    const EquilibriumCounters& c = run.counters;
    counters[steps == 20] = c;
    std::printf(
        "%d steps: %ld Newton factorizations, %ld Newton analyses; %ld body factorizations (+ %ld "
        "dissected), %ld body analyses\n",
        steps, c.newton_factorizations, c.newton_analyses, c.body_factorizations, c.dissected_factorizations,
        c.body_analyses);
    EXPECT_GE(c.newton_factorizations, 2 * steps);
    EXPECT_GE(c.newton_analyses, 1);
    EXPECT_LE(c.newton_analyses, 2);
    EXPECT_GE(c.body_factorizations, 1);
    EXPECT_GE(c.body_analyses, 1);
    // The body's pattern, and at most its nested-dissection factor's and the switch of its own
    // order to it (FreeBlockSolver::inverse_block): three.
    EXPECT_LE(c.body_analyses, 3);
  }
  EXPECT_GT(counters[1].newton_factorizations, counters[0].newton_factorizations);
  EXPECT_EQ(counters[1].body_analyses, counters[0].body_analyses);
}

}  // namespace
}  // namespace grip
