// Frictional Hertz against Spence's self-similar solution (tests/support/spence.hpp): nu = 0.3,
// mu = 0.3, 10 steps, a / h = 20. The mesh study (a / h = 40 and 80) is in tests/hard
// (SpenceSlow: 25 s).
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/support/spence.hpp"

namespace grip {
namespace {

using namespace grip::testing;

constexpr double kNu = 0.3, kMu = 0.3;

// c/a against beta / mu = K'(c/a) / K(c/a) within 3 % of a; c/a the same at every step of the
// second half of the loading (self-similarity). Each step's c is read midway between the last
// node that sticks and the next, so to within a node spacing: two steps' ratios agree to the
// sum of their spacings over their half-widths, h / a_k + h / a_last (one node short at step
// 6 is 0.074 of a there, with h / a 0.067 there and 0.050 at the last step). The peak pressure's rise over the
// frictionless solution on the same mesh reported.
TEST(Spence, StickZoneRatioMatchesTheSelfSimilarSolution) {
  const double beta = (1 - 2 * kNu) / (2 * (1 - kNu)), expected = spence_stick_ratio(beta / kMu);
  const double size = 0.025;
  const Solved f = solve_scene(frictional_hertz(size, 10, kMu));
  const Solved n = solve_scene(frictional_hertz(size, 10, 0.0));
  expect_every_step_sound(f);
  ASSERT_TRUE(f.run.completed && n.run.completed);
  const SpenceReading last = read_spence(f, f.run.steps.back(), kMu);
  ASSERT_TRUE(last.found);
  for (size_t k = f.run.steps.size() / 2; k < f.run.steps.size(); ++k) {
    const SpenceReading r = read_spence(f, f.run.steps[k], kMu);
    ASSERT_TRUE(r.found);
    std::printf("step %zu: a %.4f (a/h %.1f), c/a %.4f\n", k + 1, r.a, r.a / size, r.c / r.a);
    EXPECT_NEAR(r.c / r.a, last.c / last.a, size / r.a + size / last.a) << "step " << k + 1;
  }
  const double rise = last.peak / read_spence(n, n.run.steps.back(), 0.0).peak - 1;
  std::printf("beta/mu %.4f: c/a %.4f by the relation, %.4f computed (%+.2f %% of a); peak pressure %+.2f %% "
              "over the frictionless solution; %ld real solves, %.2f s\n",
              beta / kMu, expected, last.c / last.a, 100 * (last.c / last.a - expected), 100 * rise,
              f.run.counters.solves, f.run.seconds);
  EXPECT_NEAR(last.c / last.a, expected, 0.03);
}

}  // namespace
}  // namespace grip
