// Two deformable bodies (issue 19) at their harder end: the two cylinders of unequal materials
// (E 200 / 70 GPa, the nodes slide along the master) on a refined mesh, h 0.025 mm (a / h 14
// and 21 at the two steps), with friction 0.3 between them. Hertz with the combined radius and
// modulus within 2 %, read from either side; the pair's forces cancel on every step.
// (Frictionless, the same mesh is TwoBodies.CylindersOfUnequalMaterialsMatchHertz.)
#include <gtest/gtest.h>

#include "tests/support/two_bodies.hpp"

namespace grip {
namespace {

using namespace grip::testing;

// Friction between unequal materials narrows the zone a little (Spence-like coupling, first
// order in beta mu): the frictionless closed form is held to 2 % there.
TEST(TwoBodiesHard, RefinedCylindersWithFrictionStayNearHertz) {
  nlohmann::json j = cylinders_with_pole_elements(0.025);
  j["contacts"][0]["friction"] = 0.3;
  const Solved s = solve_scene(j);
  expect_every_step_sound(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  for (const StepRecord& rec : s.run.steps) {
    expect_pairs_balanced(s, rec);
    const CylinderReading r = read_cylinders(s, rec);
    EXPECT_NEAR(r.slave.a, r.closed.a, 0.02 * r.closed.a) << "step " << rec.index;
    EXPECT_NEAR(r.slave.p0, r.closed.p0, 0.02 * r.closed.p0) << "step " << rec.index;
    // The same traction field read at the master's sites (master_field_profile).
    EXPECT_NEAR(r.master.a, r.closed.a, 0.02 * r.closed.a) << "step " << rec.index;
    EXPECT_NEAR(r.master.p0, r.closed.p0, 0.02 * r.closed.p0) << "step " << rec.index;
  }
}

}  // namespace
}  // namespace grip
