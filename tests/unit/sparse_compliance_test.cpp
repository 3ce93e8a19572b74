// The compliance in sparse form (large contact zones: T on the free dofs and the body's
// factorization, Equilibrium::compliance's sparse_from) against the dense form on the same
// state: its products C z, its diagonal and the inner model's Newton steps on its saddle-point
// systems (saddle_rows.hpp: a new LU, a low-rank correction of the kept one, a return to the
// factorized kinds) equal the dense ones to rounding.
#include <gtest/gtest.h>

#include <random>

#include "solver/contact/newton_rows.hpp"
#include "solver/equilibrium/equilibrium.hpp"
#include "solver/io/scene.hpp"
#include "tests/support/flat_block.hpp"

namespace grip {
namespace {

double relative_difference(const Vector& a, const Vector& b) { return (a - b).norm() / b.norm(); }

// Pressing candidates' normal rows active, the first `slipping` of them slip (c = +-0.3), the
// others stick.
NewtonRows kinds(const Problem& problem, const Compliance& C, const std::vector<int>& usable, int first, int last,
                 int slipping) {
  NewtonRows rows;
  for (int i = first; i < last; ++i) {
    const Candidate& c = problem.candidates[usable[i]];
    const int eta = C.position[c.eta], xi = C.position[c.xi];
    rows.active.push_back(eta);
    if (i - first < slipping) rows.slip.push_back({xi, eta, i % 2 ? 0.3 : -0.3});
    else rows.active.push_back(xi);
  }
  return rows;
}

TEST(SparseCompliance, ProductsDiagonalAndNewtonStepsEqualTheDenseForm) {
  const Scene scene = read_scene(testing::flat_block(40, 4));
  const Problem& problem = scene.problem;
  Equilibrium eq(problem, NewtonParams{});
  eq.set_step({1.0}, std::vector<double>(problem.candidates.size(), 0.0));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1e-5, 1e-5);
  Vector q(problem.body->dof_count());
  for (int i = 0; i < q.size(); ++i) q[i] = u(rng);
  const EquilibriumState state = eq.evaluate(q);
  std::vector<int> all;
  for (int a = 0; a < problem.component_count; ++a)
    if (state.enabled[a]) all.push_back(a);
  std::vector<int> usable;  // candidates with both components free
  for (size_t i = 0; i < problem.candidates.size(); ++i)
    if (state.enabled[problem.candidates[i].eta] && problem.candidates[i].xi >= 0 &&
        state.enabled[problem.candidates[i].xi])
      usable.push_back(static_cast<int>(i));
  ASSERT_GE(usable.size(), 40u);
  const Compliance dense = eq.compliance(state, all);  // a copy: the form of today
  const Compliance& sparse = eq.compliance(state, all, 0);
  ASSERT_TRUE(sparse.sparse());
  ASSERT_FALSE(dense.sparse());
  ASSERT_EQ(sparse.position, dense.position);
  const int m = sparse.size();
  Vector z(m);
  for (int k = 0; k < m; ++k) z[k] = u(rng) * 1e5;
  EXPECT_LT(relative_difference(sparse.apply(z), dense.block * z), 1e-12);
  Vector diagonal(m);
  for (int k = 0; k < m; ++k) diagonal[k] = sparse.diagonal(k);
  EXPECT_LT(relative_difference(diagonal, dense.block.diagonal()), 1e-12);

  // The model's Newton steps: 30 points pressing (3 slip), then two more slip and one more
  // presses (5 rows change kind: a correction), then back (the kept LU alone), then another set
  // altogether (a new LU).
  NewtonRowStats sparse_stats, dense_stats;
  const std::vector<NewtonRows> sets = {
      kinds(problem, sparse, usable, 5, 35, 3), kinds(problem, sparse, usable, 5, 36, 5),
      kinds(problem, sparse, usable, 5, 35, 3), kinds(problem, sparse, usable, 0, 40, 20)};
  for (size_t t = 0; t < sets.size(); ++t) {
    Vector F(m), s(m);
    for (int k = 0; k < m; ++k) F[k] = u(rng) * 1e3, s[k] = u(rng);
    for (int k : sets[t].active) F[k] = s[k];  // r = 1
    const Vector reference = solve_newton_rows(dense, F, s, sets[t], dense_stats);
    const Vector dx = solve_newton_rows(sparse, F, s, sets[t], sparse_stats);
    const double error = relative_difference(dx, reference);
    std::printf("set %zu: |dx_sparse - dx_dense| / |dx_dense| = %.3g\n", t, error);
    EXPECT_LT(error, 1e-9) << "set " << t;
  }
  EXPECT_EQ(sparse_stats.factorizations, 2);  // the first set and the last
  EXPECT_EQ(sparse_stats.capacitances, 1);    // the second
}

}  // namespace
}  // namespace grip
