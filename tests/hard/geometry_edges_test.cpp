// Issue 9, geometry: grazing contact (the body tangent to an obstacle at a candidate point),
// points beyond the ends of an open profile, and a body that starts slightly inside an
// obstacle. (A point sliding across the joint of a segment and an arc: sheet_edges_test.cpp.)
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/hard/hard_scenes.hpp"
#include "tests/support/result_checks.hpp"

namespace grip {
namespace {

using namespace grip::testing;
using nlohmann::json;

// A cantilever (20 elements, length 10, depth 0.5) whose lower surface touches a cylinder of
// radius 50 at x = 5 (node 10) and nowhere else, loaded at its tip by (fx, fy).
json grazing_beam(double fx, double fy) {
  json j = beam_on_flat(20, 0.3, "von_karman");
  j["body"]["loads"] = json::array({{{"node", 20}, {"force", {fx, fy}}}});
  j["obstacles"][0]["shape"] = {{"type", "circle"}, {"centre", {5, -0.25 - 50}}, {"radius", 50}};
  j["steps"] = 2;
  return j;
}

// Pulled along its axis the beam stays straight: node 10 slides off the top of the cylinder by
// its axial displacement u, so its gap opens by u^2 / 2R (2.5e-7 here, 2.5 times the
// contact tolerance) with no force; lifted, it leaves; pushed down, node 10 presses.
TEST(GeometryEdges, GrazingContactAtACandidatePoint) {
  const struct {
    double fx, fy;
    const char* what;
  } cases[] = {{100, 0, "axial pull"}, {0, 1, "lift"}, {0, -1, "push"}};
  for (const auto& c : cases) {
    const Solved s = solve_scene(grazing_beam(c.fx, c.fy));
    print_work(std::string("grazing beam, ") + c.what, s);
    expect_hard_case_sound(s);
    ASSERT_TRUE(s.run.completed) << c.what << ": " << s.run.reason;
    const StepRecord& last = s.run.steps.back();
    const Problem& problem = s.scene.problem;
    const double tol = tolerances_of(s.scene).length;
    for (size_t i = 0; i < problem.candidates.size(); ++i) {
      const Candidate& cand = problem.candidates[i];
      const double pn = last.p[cand.eta], gap = last.state.points[i].projection.gap;
      if (cand.site != 10) {
        EXPECT_EQ(pn, 0.0) << c.what << ", node " << cand.site;
        continue;
      }
      std::printf("%s: node 10 gap %.3g, p_n %.3g\n", c.what, gap, pn);
      if (c.fy == 0) {
        const double u = last.state.q[3 * 10];
        EXPECT_NEAR(gap, u * u / (2 * 50), 0.01 * u * u / (2 * 50)) << c.what;
        EXPECT_EQ(pn, 0.0) << c.what;
      } else if (c.fy > 0) {
        EXPECT_GT(gap, tol) << c.what;
        EXPECT_EQ(pn, 0.0) << c.what;
      } else {
        EXPECT_LT(pn, 0.0) << c.what;
        EXPECT_LE(std::abs(gap), tol) << c.what;
      }
    }
  }
}

// The beam on the flat pulled along its axis (every point slides to the right). The flat is an
// open profile of one segment from x = 8 to x = 5: nodes 0-9 lie beyond its end, nodes 17-20
// beyond its start, and nodes 10 (at the end) and 16 (at the start) cross them. Beyond its ends a
// profile continues along its end tangents, so the answer is the long flat's, to rounding.
TEST(GeometryEdges, PointsBeyondTheEndsOfAnOpenProfile) {
  json long_flat = beam_on_flat(20, 0.3, "von_karman");
  long_flat["body"]["loads"].push_back({{"node", 20}, {"force", {2000, 0}}});
  json short_profile = long_flat;
  short_profile["obstacles"][0]["shape"] = {
      {"type", "profile"}, {"pieces", json::array({{{"type", "segment"}, {"from", {8, -0.25}}, {"to", {5, -0.25}}}})}};
  const Solved a = solve_scene(long_flat), b = solve_scene(short_profile);
  print_work("beam on a long flat, pulled", a);
  print_work("beam on a short profile, pulled", b);
  expect_hard_case_sound(a);
  expect_hard_case_sound(b);
  ASSERT_TRUE(a.run.completed && b.run.completed);
  ASSERT_EQ(a.run.steps.size(), b.run.steps.size());
  for (size_t k = 0; k < a.run.steps.size(); ++k) {
    const StepRecord &ra = a.run.steps[k], &rb = b.run.steps[k];
    EXPECT_LT((ra.state.q - rb.state.q).lpNorm<Eigen::Infinity>(), 1e-9 * ra.state.q.lpNorm<Eigen::Infinity>());
    EXPECT_LT((ra.p - rb.p).lpNorm<Eigen::Infinity>(), 1e-9 * ra.p.lpNorm<Eigen::Infinity>());
  }
  // Every free node slides right, so node 10 ends on the segment and node 16 beyond it.
  const Vector& q = b.run.steps.back().state.q;
  EXPECT_GT(q[3 * 10], 0.0);
  EXPECT_GT(q[3 * 16], 0.0);
}

// The unloaded cantilever with a frictionless cylinder (radius 50) under node 10 (x = a = 5) whose top lies
// 1e-3 inside the beam's lower surface. The solver pushes the beam out within the first step
// (it does not fail): no point is deeper than the tolerance, node 10 rests on the cylinder
// lifted by 1e-3, and the contact force is the one that lifts a Timoshenko cantilever's
// section at a by 1e-3: F = 1e-3 / (a^3 / 3EI + a / kGA).
TEST(GeometryEdges, BodyStartingInsideAnObstacleIsPushedOut) {
  json j = grazing_beam(0, 0);
  j["body"]["kinematics"] = "linear";
  j["body"].erase("loads");
  j["obstacles"][0]["shape"]["centre"] = {5, -0.25 - 50 + 1e-3};
  j["obstacles"][0]["friction"] = 0.0;  // a friction force at the surface would add a moment
  j["steps"] = 1;
  const Solved s = solve_scene(j);
  print_work("beam starting 1e-3 inside a cylinder", s);
  expect_hard_case_sound(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const double tol = tolerances_of(s.scene).length;
  const StepRecord& first = s.run.steps.front();
  double force = 0.0;
  for (size_t i = 0; i < s.scene.problem.candidates.size(); ++i) {
    EXPECT_GE(first.state.points[i].projection.gap, -tol) << "point " << i;
    force += first.p[s.scene.problem.candidates[i].eta];
  }
  EXPECT_NEAR(first.state.q[3 * 10 + 1], 1e-3, 2 * tol);
  const double E = 2e5, G = E / 2.6, b = 1, h = 0.5, a = 5;
  const double F = 1e-3 / (a * a * a / (3 * E * b * h * h * h / 12) + a / (5.0 / 6 * G * b * h));
  std::printf("contact force %.6g, closed form %.6g\n", -force, F);
  EXPECT_NEAR(-force, F, 0.01 * F);
}

}  // namespace
}  // namespace grip
