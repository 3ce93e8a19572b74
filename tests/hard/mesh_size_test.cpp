// Issue 9, a fine mesh: the beam on the flat with 2000 elements, so 2000 candidate points.
#include <gtest/gtest.h>

#include <cstdio>

#include "solver/elements/timoshenko_beam.hpp"
#include "tests/hard/hard_scenes.hpp"
#include "tests/support/result_checks.hpp"

namespace grip {
namespace {

using namespace grip::testing;

// Closed form: the beam lies on the flat and stays straight, so every free node's contact
// force carries exactly that node's load, the clamp carries nothing, and no friction arises
// (each to what ||v|| <= tol pins a force to: 1e-5 of a node's load here).
void expect_each_node_carries_its_load(double mu) {
  const int elements = 2000;
  nlohmann::json j = beam_on_flat(elements, mu);
  j["steps"] = 2;
  const Solved s = solve_scene(j);
  print_work("beam on a flat, 2000 elements, mu " + std::to_string(mu), s);
  ASSERT_GE(s.scene.problem.candidates.size(), 2000u);
  expect_hard_case_sound(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const double per_node = 20.0 / elements;
  for (const StepRecord& rec : s.run.steps) {
    double worst = 0.0, friction = 0.0;
    for (const Candidate& c : s.scene.problem.candidates) {
      if (c.site == 0) continue;  // the clamped node
      const double load = (c.site == elements ? 0.5 : 1.0) * per_node * rec.load_factor;
      worst = std::max(worst, std::abs(-rec.p[c.eta] - load));
      if (c.xi >= 0) friction = std::max(friction, std::abs(rec.p[c.xi]));
    }
    std::printf("step %d: largest nodal force error %.3g, largest friction %.3g (load per node %.3g)\n", rec.index,
                worst, friction, per_node * rec.load_factor);
    EXPECT_LT(worst, 1e-5 * per_node);
    EXPECT_LT(friction, 1e-5 * per_node);
    EXPECT_NEAR(rec.reactions[TimoshenkoBeam::node_dof(0, 1)], 0.0, 1e-5 * per_node);
  }
}

TEST(MeshSize, TwoThousandCandidatesOnAFlat) { expect_each_node_carries_its_load(0.0); }

// With friction: 4000 contact unknowns (about 25 s; label hard_slow, see tests/CMakeLists.txt).
TEST(MeshSizeSlow, TwoThousandCandidatesOnAFlatWithFriction) { expect_each_node_carries_its_load(0.3); }

}  // namespace
}  // namespace grip
