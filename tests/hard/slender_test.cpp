// Issue 13, slender continua: strips of L/t = 30 to 1000 (q9, finite strain) bent to
// F L^2 / EI = 5 (tip rotation 70 deg) in 10 steps. Round-off grows with the stiffness's
// condition number (about (L/t)^2 times the mesh's): Newton must stop at that floor, record
// it, and still follow the elastica; cutting the increment stays a rare last resort.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tests/support/result_checks.hpp"
#include "tests/support/strips.hpp"

namespace grip {
namespace {

using namespace grip::testing;

TEST(Slender, StripsFromThirtyToAThousandFollowTheElastica) {
  for (const double slenderness : {30.0, 100.0, 300.0, 1000.0}) {
    StripSpec spec;
    spec.thickness = 1.0 / slenderness;
    spec.young = 12.0 * slenderness * slenderness * slenderness;  // EI = 1
    spec.along = slenderness <= 100 ? 60 : 100;
    spec.alpha = 5.0;
    spec.steps = 10;
    const std::string what = "L/t = " + std::to_string(static_cast<int>(slenderness));
    const Solved s = solve_scene(strip_scene(spec));
    print_work(what, s);
    ASSERT_TRUE(s.run.completed) << what << ": " << s.run.reason;
    int cuts = 0, at_floor = 0;
    double floor = 0.0;
    for (const StepRecord& rec : s.run.steps) {
      cuts += rec.cuts;
      at_floor += rec.state.at_floor;
      floor = std::max(floor, rec.state.relative_residual);
    }
    std::printf("%s: %d cuts, %d steps at the round-off floor, largest final residual %.2g of the force scale\n",
                what.c_str(), cuts, at_floor, floor);
    EXPECT_LE(cuts, 4) << what;
    EXPECT_LT(floor, 3e-5) << what;  // a floor, not a stall: far below any engineering tolerance
    const ElasticaTip exact = elastica_tip(spec.alpha), tip = strip_tip(s, spec, s.run.steps.size() - 1);
    EXPECT_NEAR(tip.deflection, exact.deflection, 1e-2) << what;
    EXPECT_NEAR(tip.rotation, exact.rotation, 1e-2 * exact.rotation) << what;
  }
}

// A cantilever swung through more than 90 degrees: the dead end load points down and back at
// 45 degrees, so that the tip turns toward 135 degrees as the load grows (F L^2 / EI = 30 in
// 10 steps), most of it a rigid swing of the outer part that no trust region may throttle.
// The supports carry exactly the applied load.
TEST(Slender, CantileverSwingsPastNinetyDegrees) {
  StripSpec spec;
  spec.alpha = 30.0;
  spec.load_angle = std::acos(-1.0) / 4;
  spec.steps = 10;
  const Solved s = solve_scene(strip_scene(spec));
  print_work("swing", s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const double rotation = strip_tip(s, spec, 9).rotation;
  std::printf("swing: tip rotation %.1f deg\n", rotation * 180 / std::acos(-1.0));
  EXPECT_GT(rotation, std::acos(-1.0) / 2);
  EXPECT_LT(rotation, 3 * std::acos(-1.0) / 4);
  const Vector& reactions = s.run.steps.back().reactions;
  Vec2 total(0, 0);
  for (Eigen::Index d = 0; d < reactions.size(); ++d) total[d % 2] += reactions[d];
  const double F = spec.alpha * strip_bending_stiffness(spec);
  EXPECT_NEAR(total.x(), F * std::sin(spec.load_angle), 1e-8 * F);
  EXPECT_NEAR(total.y(), F * std::cos(spec.load_angle), 1e-8 * F);
}

}  // namespace
}  // namespace grip
