// Frictional Hertz against Spence's self-similar solution (tests/support/spence.hpp) in the
// setting it is derived for: an elastic half-plane (a block 600 x 300 mm, bottom held) pressed
// by a rigid cylinder (R = 100 mm, a = 1.03 mm at the end), nu = 0.3, mu = 0.3, 10 steps,
// a / h = 40 (about 8 s at load 14 on 2 cores). Its reference: the half-plane
// boundary-element model of the same loading (tests/support/spence_halfplane.hpp, about 1 s).
// The mesh study, the increment and the far field are in tests/hard/spence_slow_test.cpp.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/support/spence.hpp"
#include "tests/support/spence_halfplane.hpp"

namespace grip {
namespace {

using namespace grip::testing;

constexpr double kNu = 0.3, kMu = 0.3, kSize = 0.025;  // a / h = 41 at the last step
constexpr int kPerA = 40;                              // the half-plane model's a / h

double relation() { return spence_stick_ratio((1 - 2 * kNu) / (2 * (1 - kNu)) / kMu); }

// The reference model itself: without the coupling of q into p it gives the relation
// beta / mu = K'(c/a) / K(c/a); c and a are each read at an element edge (to h / 2), so c/a to
// h / a. With the coupling, c/a falls (by 0.05: what the relation neglects).
TEST(Spence, HalfPlaneModelWithoutCouplingGivesTheRelation) {
  const HalfPlaneSpence u = spence_half_plane(kMu, kNu, kPerA, 50, false);
  const HalfPlaneSpence c = spence_half_plane(kMu, kNu, kPerA, 50, true);
  std::printf(
      "relation %.4f; half-plane model, a/h %d: uncoupled c/a %.4f, coupled c/a %.4f (a %.4f, peak %.4f of "
      "Hertz's)\n",
      relation(), kPerA, u.c_stick / u.a, c.c_stick / c.a, c.a, c.peak);
  EXPECT_NEAR(u.c_stick / u.a, relation(), 1.0 / kPerA);
  EXPECT_LT(c.c_stick / c.a, relation() - 1.0 / kPerA);
}

// The far field is a half-plane's: frictionless, the block gives Hertz's a and p0 at the
// computed load, to what tests/verification/hertz_test.cpp derives for the half-disc (the
// closed-form edge within half an edge element of the nodes where contact ends; p0 and the
// peak nodal stress within 0.2 %). The frictionless answer does not depend on the path: 2 steps.
TEST(Spence, FrictionlessBlockGivesHertz) {
  const Solved n = solve_scene(spence_block(kSize, 2, 0.0));
  expect_every_step_sound(n);
  ASSERT_TRUE(n.run.completed);
  const StepRecord& rec = n.run.steps.back();
  const SpenceReading r = read_spence(n, rec, 0.0);
  ASSERT_TRUE(r.found);
  const auto nodes = contact_profile(n.scene.problem, rec);
  const EllipseFit fit = fit_semi_ellipse(nodes);
  const Zone zone = contact_zone(nodes);
  std::printf("P %.1f N/mm: a %.4f mm, fitted %+.3f %%, edge %+.3f %%; p0 %.1f MPa, fitted %+.3f %%, peak %+.3f %%\n",
              r.hertz.P, r.hertz.a, 100 * (fit.a / r.hertz.a - 1), 100 * (r.a / r.hertz.a - 1), r.hertz.p0,
              100 * (fit.p0 / r.hertz.p0 - 1), 100 * (r.peak - 1));
  EXPECT_TRUE(zone.brackets(r.hertz.a, 0.5 * zone.edge_element())) << "a = " << r.hertz.a;
  EXPECT_NEAR(fit.p0 / r.hertz.p0, 1, 0.002);
  EXPECT_NEAR(r.peak, 1, 0.002);
}

// c/a (the solver's stick states, as the model's stick set) within 3 % of a of the coupled
// half-plane model at every step of the second half of the loading (self-similarity: c/a
// constant; each step's c is read to within a node spacing h, 0.032 a at step 6). Against
// the relation, which neglects the coupling, c/a is 0.05 lower. The contact narrows and the
// peak pressure rises over Hertz's as in the model: a within the two readings' resolutions
// (h / 2a each), the peak within 1 % of p0 (the rise is 8 %).
TEST(Spence, StickZoneMatchesTheHalfPlaneSolution) {
  const HalfPlaneSpence model = spence_half_plane(kMu, kNu, kPerA, 50, true);
  const double reference = model.c_stick / model.a;
  const Solved f = solve_scene(spence_block(kSize, 10, kMu));
  expect_every_step_sound(f);
  ASSERT_TRUE(f.run.completed);
  for (size_t k = f.run.steps.size() / 2; k < f.run.steps.size(); ++k) {
    const SpenceReading r = read_spence(f, f.run.steps[k], kMu);
    ASSERT_TRUE(r.found && r.c > 0);
    std::printf(
        "step %zu: a %.4f (a/h %.1f, %+.2f %% of Hertz's), c/a %.4f (0.99 rule %.4f), peak %+.2f %% over "
        "Hertz's p0\n",
        k + 1, r.a, r.a / kSize, 100 * (r.a / r.hertz.a - 1), r.c / r.a, r.c_rule / r.a, 100 * (r.peak - 1));
    EXPECT_NEAR(r.c / r.a, reference, 0.03) << "step " << k + 1;
  }
  const SpenceReading last = read_spence(f, f.run.steps.back(), kMu);
  std::printf(
      "c/a %.4f: half-plane model %.4f (%+.2f %% of a), relation %.4f (%+.2f %%); a %.4f, peak %.4f of "
      "Hertz's (model: %.4f, %.4f); %ld real solves, %.2f s\n",
      last.c / last.a, reference, 100 * (last.c / last.a - reference), relation(), 100 * (last.c / last.a - relation()),
      last.a / last.hertz.a, last.peak, model.a, model.peak, f.run.counters.solves, f.run.seconds);
  EXPECT_NEAR(last.a / last.hertz.a, model.a, 0.5 * kSize / last.a + 0.5 / kPerA);
  EXPECT_NEAR(last.peak, model.peak, 0.01);
}

}  // namespace
}  // namespace grip
