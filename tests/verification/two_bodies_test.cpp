// Two deformable bodies in contact (node-to-segment, issue 19).
// Hertz between two elastic cylinders in plane strain: two half-discs facing each other (the
// shipped schemas/examples/two-cylinders.json), the upper one pressed down by its diameter,
// the lower one held at its diameter. Closed form with the combined radius and modulus:
// 1/R = 1/R1 + 1/R2, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2, a = sqrt(4 P R / (pi E*)),
// p0 = 2 P / (pi a), P the load per unit thickness from the upper body's reactions.
#include <gtest/gtest.h>

#include <cstdio>
#include <numbers>

#include "tests/support/two_bodies.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

HertzContact combined_hertz(const json& scene, double P) {
  double inverse_R = 0, inverse_E = 0;
  for (const json& b : scene["bodies"]) {
    const double E = b["material"]["young"], nu = b["material"]["poisson"];
    inverse_R += 1 / b["mesh"]["half_disc"]["radius"].get<double>();
    inverse_E += (1 - nu * nu) / E;
  }
  const double a = std::sqrt(4 * P / inverse_R * inverse_E / std::numbers::pi);
  return {P, a, 2 * P / (std::numbers::pi * a)};
}

// The forces of every pair cancel over the two bodies, and each body is in equilibrium with
// its own reactions.
void expect_pairs_balanced(const Solved& s, const StepRecord& rec) {
  const Problem& problem = s.scene.problem;
  const Vector f = contact_forces(problem, rec);
  double scale = 0.0;
  for (size_t i = 0; i < problem.candidates.size(); ++i) scale += std::abs(rec.p[problem.candidates[i].eta]);
  Vec2 total = Vec2::Zero();
  for (int b = 0; b < body_set(problem).count(); ++b) {
    const Vec2 on_body = body_resultant(problem, b, f);
    total += on_body;
    const Vec2 reaction = body_resultant(problem, b, rec.reactions) + body_resultant(problem, b, problem.load(rec.factors));
    EXPECT_LT((on_body + reaction).norm(), 1e-7 * scale) << "body " << b << " step " << rec.index;
  }
  EXPECT_LT(total.norm(), 1e-12 * scale) << "step " << rec.index;
}

struct CylinderReading {
  HertzContact closed;
  EllipseFit slave, master;
};

CylinderReading read_cylinders(const Solved& s, const StepRecord& rec) {
  const json& scene = s.scene.effective;
  const double P = -body_resultant(s.scene.problem, 0, rec.reactions).y() / scene["bodies"][0]["thickness"].get<double>();
  CylinderReading r{combined_hertz(scene, P), fit_semi_ellipse(contact_profile(s.scene.problem, rec)), {}};
  const Vec2 centre(0, -scene["bodies"][1]["mesh"]["half_disc"]["radius"].get<double>());
  r.master = fit_semi_ellipse(master_profile(s.scene.problem, rec, 1, [&](const Vec2& x) { return Vec2((x - centre).normalized()); }));
  std::printf("step %d: P %.2f N/mm, a %.4f mm (slave %+.2f %%, master %+.2f %%), p0 %.1f MPa (slave %+.2f %%, master %+.2f %%)\n",
              rec.index, P, r.closed.a, 100 * (r.slave.a / r.closed.a - 1), 100 * (r.master.a / r.closed.a - 1),
              r.closed.p0, 100 * (r.slave.p0 / r.closed.p0 - 1), 100 * (r.master.p0 / r.closed.p0 - 1));
  return r;
}

// The slave's contact stresses against the closed form (a / h 7 and 10 at the two steps);
// the master's nodal stresses against the slave's within `master_a` and `master_p0`.
void expect_cylinders_hertz(const json& scene, double master_a, double master_p0) {
  const Solved s = solve_scene(scene);
  expect_every_step_sound(s);
  ASSERT_TRUE(s.run.completed);
  for (const StepRecord& rec : s.run.steps) {
    expect_pairs_balanced(s, rec);
    const CylinderReading r = read_cylinders(s, rec);
    EXPECT_NEAR(r.slave.a, r.closed.a, 0.01 * r.closed.a);
    EXPECT_NEAR(r.slave.p0, r.closed.p0, 0.01 * r.closed.p0);
    EXPECT_NEAR(r.master.a, r.slave.a, master_a * r.slave.a);
    EXPECT_NEAR(r.master.p0, r.slave.p0, master_p0 * r.slave.p0);
  }
}

// Unequal materials slide against each other (frictionless): the slave nodes end between the
// master's, and node-to-segment hands each slave force to two master nodes by (1 - t, t).
// The master's nodal stresses are then the slave's smeared over one element: the same
// resultant (to 1e-12) and peak (2 % at a / h 7, 0.7 % at 10), a contact edge read up to one
// node wider (a +5.9 %, +1.4 %).
TEST(TwoBodies, CylindersOfUnequalMaterialsMatchHertz) { expect_cylinders_hertz(example_scene("two-cylinders"), 0.07, 0.025); }

// Equal materials: mirror images, the nodes stay face to face (t = 0 or 1), and the pressure
// read from either body is the same.
TEST(TwoBodies, CylindersOfEqualMaterialsMatchHertz) {
  json j = example_scene("two-cylinders");
  j["bodies"][1]["material"] = j["bodies"][0]["material"];
  expect_cylinders_hertz(j, 0.002, 0.002);
}

}  // namespace
}  // namespace grip
