// The penalty baseline: its error against the contact conditions falls in proportion to 1/k,
// and its answer approaches the contact error vector scheme's as k grows.
#include <gtest/gtest.h>

#include "solver/elements/timoshenko_beam.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using testing::example_scene;
using testing::solve_scene;

double max_penetration(const testing::Solved& s) {
  double worst = 0.0;
  for (const auto& pp : s.run.steps.back().state.points) worst = std::max(worst, -pp.projection.gap);
  return worst;
}

double tip_deflection(const testing::Solved& s) { return s.run.steps.back().state.q[TimoshenkoBeam::node_dof(40, 1)]; }

TEST(PenaltyBaseline, ErrorFallsAsThePenaltyGrows) {
  const auto reference = solve_scene(example_scene("beam-on-cylinder"));
  ASSERT_TRUE(reference.run.completed);
  std::vector<double> penetration, deviation;
  for (const double factor : {1.0, 10.0}) {
    nlohmann::json j = example_scene("beam-on-cylinder");
    // Penalty converges only where its answer meets the tolerance (docs/algorithm.md#tolerance):
    // at these soft laws its error is a large part of the displacement, so the tolerance says
    // what is accepted (the answer is the law's either way: Newton keeps the default precision).
    j["solver"]["contact"] = {{"method", "penalty"}, {"penalty", {{"factor", factor}}}, {"tolerance", 0.9}};
    const auto s = solve_scene(j);
    ASSERT_TRUE(s.run.completed) << s.run.reason;
    penetration.push_back(max_penetration(s));
    deviation.push_back(std::abs(tip_deflection(s) - tip_deflection(reference)));
    std::cout << "penalty factor " << factor << ": penetration " << penetration.back() << ", tip deflection off by "
              << deviation.back() << "\n";
  }
  // Penetration ~ p / k: ten times the stiffness, a tenth of the penetration.
  EXPECT_NEAR(penetration[1] / penetration[0], 0.1, 0.02);
  EXPECT_LT(deviation[1], deviation[0]);
  EXPECT_GT(penetration[0], 10 * 1e-8 * 30);  // far above cev's tolerance: the trade-off
}

// At a tolerance below what its law's penetration allows, the law does not converge, and says
// what it reached.
TEST(PenaltyBaseline, SaysWhatItReachedWhereTheToleranceIsNotMet) {
  nlohmann::json j = example_scene("beam-on-cylinder");
  j["solver"]["contact"] = {{"method", "penalty"}, {"tolerance", 1e-11}};
  const auto s = solve_scene(j);
  ASSERT_FALSE(s.run.completed);
  const StepRecord& failed = s.run.steps.back();
  EXPECT_GT(failed.contact_error, failed.bound);
  EXPECT_NE(failed.reason.find("penalty: contact error"), std::string::npos) << failed.reason;
  EXPECT_NE(failed.reason.find("penetration"), std::string::npos) << failed.reason;
  EXPECT_EQ(failed.cuts, 0);  // a shorter increment would not lower |p| / k
}

}  // namespace
}  // namespace grip
