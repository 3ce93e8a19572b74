// Frictional Hertz against Spence's self-similar solution (tests/support/spence.hpp) on finer
// meshes, a / h = 40 and 80 (about 25 s; the a / h = 20 check is in the default run,
// tests/verification/spence_test.cpp), with the two things besides the mesh that the stick zone
// could depend on: the increment (20 steps instead of 10) and the far field (the diameter also
// held in x), and the tau passes of eq. 14 instead of cev's default. Measured (issue 15):
// c/a 0.781 and 0.784 (midpoint between nodes) against 0.744 from the relation, +3.7 % and
// +4.0 % of a; 20 steps and the tau passes: 0.781 too; the diameter also held in x: 0.798.
// The relation neglects the effect of the shear traction on the pressure (first order in
// beta mu = 0.086) and is for a half-plane: the half-plane model of bench/spence_halfplane.cpp
// gives 0.667 by the 0.99 rule with the coupling (the pressure's rise, 8 %, and the narrower
// contact, 2.5 %, as here) and 0.718 with the coupling and the surface stretch of a cylinder
// of R/a = 20 (0.769 at R/a = 10); the half-disc held at its diameter stretches more. So the
// relation is held to 5 % of a here, not 3 %.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/support/spence.hpp"

namespace grip {
namespace {

using namespace grip::testing;

constexpr double kNu = 0.3, kMu = 0.3;

double stick_ratio(const nlohmann::json& scene) {
  const Solved s = solve_scene(scene);
  expect_every_step_sound(s);
  EXPECT_TRUE(s.run.completed) << s.run.reason;
  if (!s.run.completed) return 0.0;
  const SpenceReading r = read_spence(s, s.run.steps.back(), kMu);
  EXPECT_TRUE(r.found);
  std::printf("a %.4f, c %.4f, c/a %.4f, peak %.4f p0; %ld real solves, %.1f s\n", r.a, r.c, r.c / r.a, r.peak,
              s.run.counters.solves, s.run.seconds);
  return r.c / r.a;
}

TEST(SpenceSlow, StickZoneConvergesInTheMesh) {
  const double beta = (1 - 2 * kNu) / (2 * (1 - kNu)), expected = spence_stick_ratio(beta / kMu);
  const double coarse = 0.0125, fine = 0.00625;  // a / h = 40 and 80
  const double c40 = stick_ratio(frictional_hertz(coarse, 10, kMu));
  const double c80 = stick_ratio(frictional_hertz(fine, 10, kMu));
  const double c40_20 = stick_ratio(frictional_hertz(coarse, 20, kMu));
  nlohmann::json held = frictional_hertz(coarse, 10, kMu);
  held["body"]["supports"] = example_scene("hertz")["body"]["supports"];
  const double c40_held = stick_ratio(held);
  nlohmann::json passes = frictional_hertz(coarse, 10, kMu);
  passes["solver"]["contact"]["friction_loop"] = "passes";  // the cone held to the pass tolerance
  const Solved p = solve_scene(passes);
  const SpenceReading rp = read_spence(p, p.run.steps.back(), kMu);
  std::printf("tau passes, a/h 40: c/a %.4f (%s)\n", rp.c / rp.a, p.run.completed ? "converged" : p.run.reason.c_str());
  std::printf("relation %.4f; a/h 40: %.4f (%+.2f %% of a), a/h 80: %.4f (%+.2f %%); 20 steps %.4f; diameter "
              "held in x and y %.4f\n",
              expected, c40, 100 * (c40 - expected), c80, 100 * (c80 - expected), c40_20, c40_held);
  EXPECT_NEAR(c80, c40, 0.5 * coarse / 0.5);   // within half the coarse node spacing (a = 0.5 mm)
  EXPECT_NEAR(c40_20, c40, 0.5 * coarse / 0.5);  // the increment does not matter
  EXPECT_NEAR(c80, expected, 0.05);
}

}  // namespace
}  // namespace grip
