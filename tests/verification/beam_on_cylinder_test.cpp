// The paper's example 4.2: a von Karman Timoshenko beam bent around a rigid cylinder.
#include <gtest/gtest.h>

#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using testing::example_scene;
using testing::expect_every_step_sound;
using testing::solve_scene;

nlohmann::json with_friction(double mu) {
  nlohmann::json j = example_scene("beam-on-cylinder");
  j["obstacles"][0]["friction"] = mu;
  return j;
}

TEST(BeamOnCylinder, ConvergesAtEveryStepWithFriction) {
  const auto s = solve_scene(example_scene("beam-on-cylinder"));
  expect_every_step_sound(s);
  ASSERT_EQ(s.run.steps.size(), 20u);
  // A prototype of the same model needed about 320 real solves over the 20 steps.
  EXPECT_LE(s.run.counters.solves, 320);
  // Contact spreads round the cylinder, and the friction force changes direction along it
  // (the paper's Fig. 8): leftward on the old contact, rightward near its moving edge.
  const StepRecord& last = s.run.steps.back();
  int in_contact = 0, positive = 0, negative = 0;
  for (const Candidate& c : s.scene.problem.candidates) {
    if (last.p[c.eta] >= 0) continue;
    ++in_contact;
    positive += last.p[c.xi] > 0;
    negative += last.p[c.xi] < 0;
  }
  EXPECT_GE(in_contact, 20);
  EXPECT_GE(positive, 5);
  EXPECT_GE(negative, 1);
}

TEST(BeamOnCylinder, ConvergesAtEveryStepWithoutFriction) {
  const auto s = solve_scene(with_friction(0.0));
  expect_every_step_sound(s);
  EXPECT_LE(s.run.counters.solves, 80);  // the prototype needed about 80
  for (const Candidate& c : s.scene.problem.candidates) EXPECT_EQ(c.xi, -1);
}

// mu = 0, friction left out, and a vanishing mu all give the frictionless answer.
TEST(BeamOnCylinder, ZeroFrictionMatchesFrictionLeftOut) {
  nlohmann::json omitted = example_scene("beam-on-cylinder");
  omitted["obstacles"][0].erase("friction");
  const auto a = solve_scene(with_friction(0.0));
  const auto b = solve_scene(omitted);
  const auto c = solve_scene(with_friction(1e-7));
  ASSERT_TRUE(a.run.completed && b.run.completed && c.run.completed);
  const Vector& qa = a.run.steps.back().state.q;
  EXPECT_EQ((qa - b.run.steps.back().state.q).norm(), 0.0);
  EXPECT_LT((qa - c.run.steps.back().state.q).norm(), 1e-5 * qa.norm());
}

// cev needs at most a fifth of uzawa's real solves to the same tolerance, or uzawa does not
// get there within its iteration limit.
TEST(BeamOnCylinder, CevNeedsAFifthOfUzawasSolves) {
  const auto cev = solve_scene(example_scene("beam-on-cylinder"));
  nlohmann::json j = example_scene("beam-on-cylinder");
  j["solver"]["contact"]["method"] = "uzawa";
  j["solver"]["contact"]["max_iterations"] = 400;
  j["solver"]["max_cuts"] = 0;
  const auto uzawa = solve_scene(j);
  ASSERT_TRUE(cev.run.completed);
  std::cout << "cev " << cev.run.counters.solves << " solves; uzawa "
            << (uzawa.run.completed ? "converged" : "failed: " + uzawa.run.reason) << " after "
            << uzawa.run.counters.solves << " solves\n";
  if (uzawa.run.completed) EXPECT_GE(uzawa.run.counters.solves, 5 * cev.run.counters.solves);
  else EXPECT_GE(uzawa.run.counters.solves, 400);  // it stopped at its limit, not on an error
}

}  // namespace
}  // namespace grip
