// Prandtl's punch with a filleted edge (issue 37, bench/results/prandtl-fillet.md): the punch a
// frictionless profile obstacle (a flat to x = 1 - r, an arc of radius r = b/20, the side x = b)
// pressed 0.08 b in 16 steps into the perfectly plastic block of h = b/10
// (bench/peers/prandtl_ccx.py's mesh), cev at its defaults. In step 15 the outermost pressing
// node, flowing outward under the punch, crosses the flat-arc join, and the block at its limit
// lets it slide along the arc: the sum of its tangent and the turning stiffness of the point's
// force is indefinite there. Before the compliance kept those terms where the sum is
// indefinite (docs/algorithm.md#the-contact-compliance), the updates on the arc converged
// linearly and step 15 failed after ~200 s; now every step converges. Steps 8-14 (the node
// still on the flat) carry the square-edged punch's plateau load on the same mesh, and step 15 the
// load that ssn's semismooth Newton found on the same path (0.9175 of (2 + pi) k b,
// bench/results/prandtl-fillet.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "tests/support/contact_profile.hpp"
#include "tests/support/prandtl_punch.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using namespace grip::testing;

// bench/peers/prandtl_ccx.py's graded(): steps of h up to `fine`, then growing by 1.15.
std::vector<double> graded(double length, double h, double fine) {
  std::vector<double> xs{0.0};
  while (xs.back() < fine - 1e-9) xs.push_back(std::min(xs.back() + h, fine));
  double step = h;
  while (xs.back() < length - 1e-9) {
    step *= 1.15;
    xs.push_back(std::min(xs.back() + step, length));
  }
  const size_t n = xs.size();
  if (n > 2 && xs[n - 1] - xs[n - 2] < 0.5 * (xs[n - 2] - xs[n - 3])) xs.erase(xs.end() - 2);
  return xs;
}

// The scene of bench/results/prandtl-fillet.md: the punch's edge a fillet of radius r (0: square).
nlohmann::json fillet_scene(double r, int steps, double depth) {
  const double h = 0.1;
  const std::vector<double> xs = graded(10, h, 3.5);
  std::vector<double> ys;
  for (double y : graded(10, h, 2.5)) ys.insert(ys.begin(), -y);
  nlohmann::json nodes = nlohmann::json::array(), elements = nlohmann::json::array();
  std::vector<int> left, right, bottom, near;
  const int nx = static_cast<int>(xs.size());
  for (size_t j = 0; j < ys.size(); ++j)
    for (size_t i = 0; i < xs.size(); ++i) {
      const int n = static_cast<int>(nodes.size());
      nodes.push_back({xs[i], ys[j]});
      if (xs[i] < 1e-9) left.push_back(n);
      if (xs[i] > 10 - 1e-9) right.push_back(n);
      if (ys[j] < -10 + 1e-9) bottom.push_back(n);
      if (ys[j] > -1e-9 && xs[i] <= 2.5 + 1e-9) near.push_back(n);
    }
  for (int j = 0; j + 1 < static_cast<int>(ys.size()); ++j)
    for (int i = 0; i + 1 < nx; ++i)
      elements.push_back({j * nx + i, j * nx + i + 1, (j + 1) * nx + i + 1, (j + 1) * nx + i});
  nlohmann::json pieces = {{{"type", "segment"}, {"from", {-2, 0}}, {"to", {1 - r, 0}}}};
  if (r > 0)
    pieces.push_back({{"type", "arc"}, {"centre", {1 - r, r}}, {"radius", r}, {"start_angle", -90}, {"end_angle", 0}});
  pieces.push_back({{"type", "segment"}, {"from", {1, r}}, {"to", {1, 5}}});
  return {{"body",
           {{"model", "continuum"},
            {"kinematics", "linear"},
            {"analysis", "plane_strain"},
            {"element", "q4_bbar"},
            {"material", {{"young", 1000}, {"poisson", 0.3}, {"law", "j2_plasticity"}, {"yield_stress", 1}}},
            {"mesh",
             {{"nodes", nodes},
              {"elements", elements},
              {"sets", {{"left", left}, {"right", right}, {"bottom", bottom}, {"near", near}}}}},
            {"contact_set", "near"},
            {"supports",
             {{{"set", "left"}, {"fix", {"x"}}},
              {{"set", "right"}, {"fix", {"x"}}},
              {{"set", "bottom"}, {"fix", {"x", "y"}}}}}}},
          {"obstacles",
           {{{"name", "punch"},
             {"shape", {{"type", "profile"}, {"pieces", pieces}}},
             {"motion", {{"translation", {0, -depth}}}}}}},
          {"steps", steps},
          {"solver", {{"contact", {{"method", "cev"}}}}}};
}

struct FilletRun {
  std::vector<double> load;       // per converged step: the pressing points' normal forces summed, over (2 + pi) k b
  std::vector<double> outermost;  // the largest current x of a pressing node
  int solves = 0, newton = 0;
  bool completed = false;
};

FilletRun run(double r, int steps, double depth) {
  const Solved s = solve_scene(fillet_scene(r, steps, depth));
  FilletRun out;
  out.completed = s.run.completed;
  EXPECT_TRUE(s.run.completed) << "r = " << r << ": " << s.run.reason;
  const Problem& problem = s.scene.problem;
  for (const StepRecord& rec : s.run.steps) {
    out.solves += rec.solves;
    out.newton += rec.newton_iterations;
    if (!rec.converged) continue;
    double sum = 0.0, x = 0.0;
    for (size_t i = 0; i < problem.candidates.size(); ++i) {
      const Candidate& c = problem.candidates[i];
      if (!(rec.p[c.eta] < 0)) continue;
      sum -= rec.p[c.eta];
      x = std::max(x, rec.state.points[i].point.x.x());
    }
    out.load.push_back(sum / prandtl_limit_half());
    out.outermost.push_back(x);
  }
  return out;
}

TEST(PrandtlFilletSlow, CevPressesTheFilletedPunchPastTheJoin) {
  const double r = 0.05;
  const FilletRun fillet = run(r, 16, 0.08), square = run(0.0, 14, 0.07);
  ASSERT_TRUE(fillet.completed && square.completed);
  ASSERT_EQ(fillet.load.size(), 16u);
  std::printf("fillet r = b/20: load / (2 + pi) k b per step:");
  for (double l : fillet.load) std::printf(" %.4f", l);
  std::printf(
      "\nthe outermost pressing node at x = %.4f (step 14), %.4f (15), %.4f (16); %d real solves, %d Newton "
      "iterations (square edge, 14 steps: %d, %d)\n",
      fillet.outermost[13], fillet.outermost[14], fillet.outermost[15], fillet.solves, fillet.newton, square.solves,
      square.newton);
  // On the flat, on the plateau: the square edge's load (to step 7 the square edge's corner node,
  // under the fillet's arc here, still presses: 1.2 % more at step 1, 2e-6 at step 7).
  for (size_t k = 7; k < 14; ++k) EXPECT_NEAR(fillet.load[k], square.load[k], 1e-6) << "step " << k + 1;
  EXPECT_LT(fillet.outermost[13], 1 - r);
  // Past the join, on the arc: ssn's load on the same path, then less as the node is squeezed out.
  EXPECT_GT(fillet.outermost[14], 1 - r);
  EXPECT_NEAR(fillet.load[14], 0.9175, 1e-3);
  EXPECT_LT(fillet.load[15], fillet.load[14] - 0.01);
}

}  // namespace
}  // namespace grip
