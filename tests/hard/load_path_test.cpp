// Issue 9, the load path: load then unload (the friction force reverses), contact followed by
// full separation, and the whole load in one step against twenty (frictionless: the same answer).
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/hard/hard_scenes.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/result_checks.hpp"

namespace grip {
namespace {

using namespace grip::testing;
using nlohmann::json;

json with_stages(json j, const json& stages) {
  j.erase("steps");
  j["stages"] = stages;
  return j;
}

// Index of the last step of each stage.
std::vector<size_t> stage_ends(const Solved& s) {
  std::vector<size_t> ends;
  for (size_t k = 0; k < s.run.steps.size(); ++k)
    if (k + 1 == s.run.steps.size() || s.run.steps[k + 1].stage != s.run.steps[k].stage) ends.push_back(k);
  return ends;
}

// The beam bent round the cylinder to 500 kgf, then unloaded to 350 kgf: where it slid outward
// on the cylinder while loading it slides back while unloading, so some point that presses at
// both ends carries a friction force of the opposite sign (each at least a tenth of its bound).
TEST(LoadPath, UnloadingReversesTheFrictionOnTheCylinder) {
  const Solved s = solve_scene(with_stages(
      beam_on_cylinder(0.2),
      json::array({{{"steps", 10}, {"factors", {{"main", 1.0}}}}, {{"steps", 6}, {"factors", {{"main", 0.7}}}}})));
  print_work("beam on cylinder, load then unload", s);
  expect_hard_case_sound(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const auto ends = stage_ends(s);
  ASSERT_EQ(ends.size(), 2u);
  const StepRecord &loaded = s.run.steps[ends[0]], &unloaded = s.run.steps[ends[1]];
  int reversed = 0;
  for (size_t i = 0; i < s.scene.problem.candidates.size(); ++i) {
    const Candidate& c = s.scene.problem.candidates[i];
    const double a = loaded.p[c.xi], b = unloaded.p[c.xi];
    if (loaded.p[c.eta] < 0 && unloaded.p[c.eta] < 0 && a * b < 0 && std::abs(a) > 0.1 * loaded.tau[i] &&
        std::abs(b) > 0.1 * unloaded.tau[i])
      ++reversed;
  }
  std::printf("points whose friction force reversed: %d\n", reversed);
  EXPECT_GE(reversed, 1);
}

// The block pressed, slid 0.01 mm to the right and then 0.02 mm back: the total friction force
// is mu N one way at the end of the first slide and mu N the other way at the end of the return.
TEST(LoadPath, ShearingBackReversesTheFrictionOnTheBlock) {
  json j = example_scene("sliding-block");
  j["stages"].push_back({{"steps", 20}, {"factors", {{"slide", -1.0}}}});
  const Solved s = solve_scene(j);
  print_work("sliding block, there and back", s);
  expect_hard_case_sound(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const auto ends = stage_ends(s);
  ASSERT_EQ(ends.size(), 3u);
  const double mu = 0.3, tau_tol = s.scene.params.contact.tau_tolerance;
  double friction[2];
  for (int k = 0; k < 2; ++k) {
    const StepRecord& rec = s.run.steps[ends[k + 1]];
    const double N = -reaction_resultant(s.scene.problem, rec).y();
    friction[k] = 0.0;
    for (const auto& n : contact_profile(s.scene.problem, rec)) friction[k] += n.p_t;
    EXPECT_NEAR(std::abs(friction[k]), mu * N, 2 * tau_tol * mu * N) << "stage " << k + 2;
  }
  std::printf("total friction force: %.6g after the slide, %.6g after the return\n", friction[0], friction[1]);
  EXPECT_LT(friction[0] * friction[1], 0.0);
}

// Loaded to 500 kgf, then the load reversed to -50 kgf (upward): the beam leaves the cylinder.
// At the end no point presses, every gap but the clamped end's is open, and (the beam being
// elastic) the displacements equal those of the same beam loaded straight to -50 kgf with the
// cylinder out of reach.
TEST(LoadPath, ContactThenFullSeparation) {
  const Solved s = solve_scene(with_stages(
      beam_on_cylinder(0.2),
      json::array({{{"steps", 10}, {"factors", {{"main", 1.0}}}}, {{"steps", 10}, {"factors", {{"main", -0.1}}}}})));
  print_work("beam on cylinder, load then lift off", s);
  expect_hard_case_sound(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const StepRecord& last = s.run.steps.back();
  const Problem& problem = s.scene.problem;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    EXPECT_EQ(last.p[c.eta], 0.0) << "point " << i;
    EXPECT_EQ(last.p[c.xi], 0.0) << "point " << i;
    if (c.site != 0) EXPECT_GT(last.state.points[i].projection.gap, 0.0) << "point " << i;
  }
  json free = beam_on_cylinder(0.2);
  free["obstacles"][0]["shape"]["centre"] = {0, -1000};
  free["steps"] = json::array({-0.1});
  const Solved f = solve_scene(free);
  ASSERT_TRUE(f.run.completed) << f.run.reason;
  const Vector& q = last.state.q;
  EXPECT_LT((q - f.run.steps.back().state.q).lpNorm<Eigen::Infinity>(), 1e-8 * q.lpNorm<Eigen::Infinity>());
}

// Frictionless, the answer does not depend on the path: the whole load in one step (adaptive
// cutting may split it) reaches the same displacements and contact forces as 20 steps, to
// what the contact tolerance pins them to. With friction both converge, to answers that
// differ legitimately (printed).
TEST(LoadPath, OneStepReachesTheTwentyStepAnswerWithoutFriction) {
  for (const double mu : {0.0, 0.2}) {
    json one = beam_on_cylinder(mu);
    one["steps"] = 1;
    const Solved a = solve_scene(one), b = solve_scene(beam_on_cylinder(mu));
    print_work("beam on cylinder, one step, mu " + std::to_string(mu), a);
    print_work("beam on cylinder, 20 steps, mu " + std::to_string(mu), b);
    expect_hard_case_sound(a);
    expect_hard_case_sound(b);
    ASSERT_TRUE(a.run.completed && b.run.completed);
    const StepRecord &ra = a.run.steps.back(), &rb = b.run.steps.back();
    const double dq = (ra.state.q - rb.state.q).lpNorm<Eigen::Infinity>() / rb.state.q.lpNorm<Eigen::Infinity>();
    const double dp = (ra.p - rb.p).lpNorm<Eigen::Infinity>() / rb.p.lpNorm<Eigen::Infinity>();
    std::printf("mu %g: one step (%d cuts) vs 20 steps: displacements differ by %.3g, forces by %.3g\n", mu, ra.cuts,
                dq, dp);
    if (mu == 0.0) {
      EXPECT_LT(dq, 1e-7);
      EXPECT_LT(dp, 1e-5);
    }
  }
}

}  // namespace
}  // namespace grip
