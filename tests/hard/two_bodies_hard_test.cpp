// Two deformable bodies (issue 19) at their harder end: the two cylinders of unequal materials
// (E 200 / 70 GPa, the nodes slide along the master) on a refined mesh, h 0.025 mm (a / h 14
// and 21 at the two steps, 16,000 dofs), with friction 0.3
// between them too. Hertz with the combined radius and modulus within 1 %, read from either side;
// the pair's forces cancel on every step.
#include <gtest/gtest.h>

#include "tests/support/two_bodies.hpp"

namespace grip {
namespace {

using namespace grip::testing;

nlohmann::json refined_cylinders(double friction) {
  nlohmann::json j = example_scene("two-cylinders");
  for (auto& b : j["bodies"]) {
    b["mesh"]["half_disc"]["refine"]["size"] = 0.025;
    b["mesh"]["half_disc"]["divisions"] = {88, 44};
  }
  j["contacts"][0]["friction"] = friction;
  return j;
}

void expect_refined_hertz(double friction) {
  const Solved s = solve_scene(refined_cylinders(friction));
  expect_every_step_sound(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  for (const StepRecord& rec : s.run.steps) {
    expect_pairs_balanced(s, rec);
    const CylinderReading r = read_cylinders(s, rec);
    // Friction between unequal materials narrows the zone a little (Spence-like coupling,
    // first order in beta mu): the frictionless closed form is held to 2 % there.
    const double tolerance = friction > 0 ? 0.02 : 0.01;
    EXPECT_NEAR(r.slave.a, r.closed.a, tolerance * r.closed.a) << "step " << rec.index;
    EXPECT_NEAR(r.slave.p0, r.closed.p0, tolerance * r.closed.p0) << "step " << rec.index;
    // The same traction field read at the master's sites (master_field_profile).
    EXPECT_NEAR(r.master.a, r.closed.a, tolerance * r.closed.a) << "step " << rec.index;
    EXPECT_NEAR(r.master.p0, r.closed.p0, tolerance * r.closed.p0) << "step " << rec.index;
  }
}

TEST(TwoBodiesHard, RefinedCylindersOfUnequalMaterialsMatchHertz) { expect_refined_hertz(0.0); }

TEST(TwoBodiesHard, RefinedCylindersWithFrictionStayNearHertz) { expect_refined_hertz(0.3); }

}  // namespace
}  // namespace grip
