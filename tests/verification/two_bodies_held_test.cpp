// A body held only by contact in a scene of several bodies (issues 16 and 19, ALGORITHM.md
// section 7): its free rigid amplitudes join the contact unknowns and its whole-body
// equilibrium, with the forces of its pairs on it, is their condition, as for one body against
// rigid obstacles. Closed forms: Hertz between two cylinders under a given force (combined
// radius and modulus), and a free block on a deformable foundation under a uniform pressure.
#include <gtest/gtest.h>

#include <cstdio>

#include "solver/elements/continuum.hpp"
#include "tests/support/held.hpp"
#include "tests/support/two_bodies.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

// The node of body b's mesh on the line y = x.y() nearest to x.
int node_at(const json& scene, int b, const Vec2& x) {
  const Scene s = read_scene(scene);
  const auto& mesh = dynamic_cast<const ContinuumBody&>(body_set(s.problem).part(b)).mesh();
  int best = -1;
  for (size_t i = 0; i < mesh.nodes.size(); ++i)
    if (std::abs(mesh.nodes[i].y() - x.y()) < 1e-9 &&
        (best < 0 || (mesh.nodes[i] - x).norm() < (mesh.nodes[best] - x).norm()))
      best = static_cast<int>(i);
  if (best < 0) ADD_FAILURE() << "no node on y = " << x.y();
  return std::max(best, 0);
}

// The shipped two cylinders with equal materials (steel), the upper one held in x on its
// diameter only and pressed by a force P at the diameter's centre. (The same state by
// displacement control, the centre and the node near (5, 10) held where the force put them,
// did not converge: cev stalled at ||v|| = 1.4e-3 after 5 cuts, 466 s; with the centre alone
// held, at 1e-6 on the rotation left to contact. Not asserted here; see the report.)
json cylinders_by_force(double P) {
  json j = example_scene("two-cylinders");
  j["bodies"][1]["material"] = j["bodies"][0]["material"];
  j["steps"] = 1;
  json& upper = j["bodies"][0];
  upper["supports"] = json::array({{{"set", "diameter"}, {"fix", {"x"}}}});
  upper["loads"] = json::array({{{"node", node_at(j, 0, Vec2(0, 10))}, {"force", {0.0, -P}}}});
  return j;
}

// The shipped block on its foundation with the block's top free (held in x on its left side
// only) under a uniform pressure `sigma`: contact alone carries the block's weight of load.
json block_under_pressure(double sigma) {
  json j = example_scene("block-on-foundation");
  j["bodies"][0]["supports"] = json::array({{{"set", "left"}, {"fix", {"x"}}}});
  j["bodies"][0]["loads"] = json::array({{{"set", "top"}, {"traction", {0.0, -sigma}}}});
  j["steps"] = 2;
  return j;
}

// The strategies of the one-body tests (held_by_contact_test.cpp), all run here.
const Strategy kStrategies[] = {
    {"cev", json::object()},
    {"cev_passes", {{"friction_loop", "passes"}}},
    {"cev_paper", {{"loop", "paper"}}},
    {"cev_paper_n3", {{"loop", "paper"}, {"acceleration", {{"n", 3}}}}},
    {"uzawa", {{"method", "uzawa"}}},
    {"penalty", {{"method", "penalty"}}},
    {"ssn", {{"method", "ssn"}}},
};

class TwoBodiesHeld : public ::testing::TestWithParam<Strategy> {
 protected:
  json with(json j) const { return with_strategy(std::move(j), GetParam()); }
  const char* name() const { return GetParam().name; }
};

TEST_P(TwoBodiesHeld, CylindersUnderAForceMatchHertz) {
  const double P = 5000.0;  // N / mm: a = 0.54 mm, about 11 elements of 0.05 mm
  const Solved f = solve_scene(with(cylinders_by_force(P)));
  expect_held(f);
  ASSERT_TRUE(f.run.completed) << f.run.reason;
  EXPECT_EQ(f.scene.problem.rigid.names, (std::vector<std::string>{"upper: translate along y", "upper: rotate about (0, 10)"}));
  const StepRecord& rec = f.run.steps.back();
  expect_pairs_balanced(f, rec);
  // The lower body carries the whole force through the pair: no support of the upper one helps.
  const Vec2 on_lower = body_resultant(f.scene.problem, 1, contact_forces(f.scene.problem, rec));
  EXPECT_NEAR(-on_lower.y(), P, balance(f.scene) * P);
  const HertzContact closed = combined_hertz(f.scene.effective, P);
  const EllipseFit fit = fit_semi_ellipse(contact_profile(f.scene.problem, rec));
  std::printf("%s: force P = %.0f N/mm: a = %.4f mm (fit %+.3f %%), p0 = %.1f MPa (fit %+.3f %%), lower body carries "
              "%.12g; %d real solves, %d Newton\n",
              name(), P, closed.a, 100 * (fit.a / closed.a - 1), closed.p0, 100 * (fit.p0 / closed.p0 - 1), -on_lower.y(),
              rec.solves, rec.newton_iterations);
  EXPECT_LT(std::abs(fit.a / closed.a - 1), 0.01);
  EXPECT_LT(std::abs(fit.p0 / closed.p0 - 1), 0.01);

  // The upper body's rigid motion in the result: down, no rotation (symmetry).
  const json step = step_json(f.scene.problem, rec, f.scene.output);
  ASSERT_EQ(step["rigid_motions"].size(), 1u);
  EXPECT_EQ(step["rigid_motions"][0]["body"], "upper");
  EXPECT_LT(step["rigid_motions"][0]["translation"][1].get<double>(), 0.0);
  const double down = step["rigid_motions"][0]["translation"][1].get<double>();
  // No rotation by symmetry, to what the stopping test pins a soft mode to: measured 3e-8 to
  // 3.4e-7 rad, at the 10 mm lever 4e-5 of the descent at most.
  EXPECT_LT(std::abs(step["rigid_motions"][0]["rotation"].get<double>()) * 10.0, 1e-4 * std::abs(down));
}

// Exact: a uniform compression sigma through both bodies (q4 carries it exactly), so the
// interface pressure is sigma everywhere but at the foundation's end beyond the block's (the
// patch test of two_bodies_test.cpp, which the free block must pass the same way).
TEST_P(TwoBodiesHeld, FreeBlockOnAFoundationUnderPressure) {
  const double sigma = 100.0;  // MPa
  const Solved s = solve_scene(with(block_under_pressure(sigma)));
  expect_held(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  EXPECT_EQ(s.scene.problem.rigid.names, std::vector<std::string>{"block: translate along y"});
  const double width = 10.0;
  for (const StepRecord& rec : s.run.steps) {
    expect_pairs_balanced(s, rec);
    const double load = sigma * width * rec.load_factor;
    const Vec2 on_block = body_resultant(s.scene.problem, 0, contact_forces(s.scene.problem, rec));
    // The contact carries the pressure's resultant (x: held by the block's support).
    EXPECT_NEAR(on_block.y(), load, balance(s.scene) * load);
    double mean = 0.0, spread = 0.0;
    std::vector<double> pressing;
    for (const ContactNode& n : contact_profile(s.scene.problem, rec))
      if (n.p_n < 0) pressing.push_back(-n.sigma_n);
    for (double v : pressing) mean += v / pressing.size();
    for (double v : pressing) spread = std::max(spread, std::abs(v / (sigma * rec.load_factor) - 1));
    std::printf("%s, step %d: %zu nodes press, mean %.4f MPa (exact %.1f), largest departure %.2f %%, contact "
                "resultant %.12g (load %.12g); %d real solves\n",
                name(), rec.index, pressing.size(), mean, sigma * rec.load_factor, 100 * spread, on_block.y(), load,
                rec.solves);
    EXPECT_GT(pressing.size(), 15u);
    EXPECT_LT(spread, 0.02);
  }
}

INSTANTIATE_TEST_SUITE_P(Strategies, TwoBodiesHeld, ::testing::ValuesIn(kStrategies),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace grip
