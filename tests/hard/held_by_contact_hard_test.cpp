// Bodies held only by contact at their hardest (ALGORITHM.md section 7): a slender strip
// (L/t = 100, 400 x 4 elements, 401 contact points, 805 unknowns with the three rigid
// amplitudes) lying free on a flat (mu 0.3), pressed by 10 MPa and sheared up to 0.99 mu N,
// where all but a few points slip and the amplitudes of the sideways motion are decided by a
// handful of sticking points.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/support/contact_profile.hpp"
#include "tests/support/result_checks.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

TEST(HeldByContactHard, SlenderFreeStripShearedToTheFrictionLimit) {
  json j = block_under_shear();
  j["body"]["mesh"]["rectangle"] = {{"origin", {-50, 0}}, {"size", {100, 1}}, {"divisions", {400, 4}}};
  j["obstacles"][0]["shape"] = {{"type", "segment"}, {"from", {200, 0}}, {"to", {-200, 0}}};
  const double ratios[] = {0, 0.9, 0.99};
  j["stages"] = json::array();
  for (const double r : ratios) j["stages"].push_back({{"steps", 1}, {"factors", {{"press", 1}, {"shear", r}}}});
  const Solved s = solve_scene(j);
  expect_hard_case_sound(s);
  ASSERT_EQ(s.scene.problem.rigid.count(), 3);
  const double N = 1000.0, mu = 0.3;
  for (size_t k = 0; k < s.run.steps.size(); ++k) {
    const StepRecord& rec = s.run.steps[k];
    Vec2 total = Vec2::Zero();
    int slip = 0;
    for (size_t i = 0; i < s.scene.problem.candidates.size(); ++i) {
      const Candidate& c = s.scene.problem.candidates[i];
      total += rec.p[c.eta] * rec.state.points[i].eta + rec.p[c.xi] * rec.state.points[i].xi;
      slip += rec.p[c.eta] < 0 && contact_state(s.scene.problem, i, rec.p, rec.tau) == ContactState::slip;
    }
    EXPECT_NEAR(-total.x(), ratios[k] * mu * N, 1e-9 * N);
    EXPECT_NEAR(total.y(), N, 1e-9 * N);
    std::printf("Q/(mu N) = %.2f: %d of 401 points slip, %d real solves, %d Newton, %.2f s\n", ratios[k], slip,
                rec.solves, rec.newton_iterations, rec.seconds);
  }
  print_work("free strip 400 x 4", s);
}

}  // namespace
}  // namespace grip
