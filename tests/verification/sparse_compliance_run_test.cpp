// Issue 14: a large contact zone takes the compliance in sparse form (no dense C, G or factor
// of C's active block; ContactParams::sparse_compliance_from). On the flat of
// bench/scaling.py with 250 contact nodes (500 unknowns) and friction 0.3, the run with the
// sparse form forced equals the dense form's: the same real solves and states in every step,
// displacements within the contact tolerance (both solve the same inner model, each to
// rounding, then the same real solves), forces within 1e-9 of the largest normal force, and
// every step sound (converged, Coulomb cone to 1e-9, monotone contact error).
#include <gtest/gtest.h>

#include "tests/support/flat_block.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using namespace grip::testing;

Solved solve_flat(int sparse_from) {
  Solved s{read_scene(flat_block(250, 10)), {}};
  s.scene.params.contact.sparse_compliance_from = sparse_from;
  s.run = run_load_steps(s.scene.problem, s.scene.steps, s.scene.params);
  return s;
}

TEST(SparseCompliance, FlatWith250ContactNodesEqualsTheDenseRun) {
  const Solved dense = solve_flat(kDenseCompliance);
  const Solved sparse = solve_flat(0);
  expect_every_step_sound(dense);
  expect_every_step_sound(sparse);
  ASSERT_EQ(sparse.run.steps.size(), dense.run.steps.size());
  const double length = dense.scene.problem.body->characteristic_length();
  const double tolerance = dense.scene.params.contact.tolerance * length;
  for (size_t k = 0; k < dense.run.steps.size(); ++k) {
    const StepRecord &a = sparse.run.steps[k], &b = dense.run.steps[k];
    EXPECT_EQ(a.solves, b.solves) << "step " << k + 1;
    const double p_max = b.p.cwiseAbs().maxCoeff();
    ASSERT_GT(p_max, 0.0);
    const double dp = (a.p - b.p).cwiseAbs().maxCoeff() / p_max;
    const double dq = (a.state.q - b.state.q).cwiseAbs().maxCoeff();
    std::printf("step %zu: forces differ by %.3g of the largest, displacements by %.3g (tolerance %.3g)\n", k + 1, dp,
                dq, tolerance);
    EXPECT_LT(dp, 1e-9) << "step " << k + 1;
    EXPECT_LT(dq, tolerance) << "step " << k + 1;
    int slipping = 0;
    for (size_t i = 0; i < dense.scene.problem.candidates.size(); ++i) {
      EXPECT_EQ(contact_state(sparse.scene.problem, i, a.p, a.tau), contact_state(dense.scene.problem, i, b.p, b.tau))
          << "step " << k + 1 << ", candidate " << i;
      slipping += contact_state(dense.scene.problem, i, b.p, b.tau) == ContactState::slip;
    }
    EXPECT_GT(slipping, 0) << "step " << k + 1;  // the slip rows' coupling took part
  }
}

}  // namespace
}  // namespace grip
