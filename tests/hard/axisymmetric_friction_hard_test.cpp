// Issue 36, hard cases of two deformable axisymmetric bodies with friction (docs/algorithm.md#axisymmetric):
// - two identical spheres pressed together: by the symmetry of the pair no point slips against
//   the other, so friction (mu 0.5) leaves Hertz's answer as it is;
// - steel on aluminium (Dundurs' beta != 0: the surfaces would slip against each other
//   inward by different amounts): friction 0.3 engages, stays inside the Coulomb cone, and
//   stiffens the contact only slightly (Spence: a per cent or less at this beta);
// - two rubber spheres under finite kinematics pressed to a contact radius near 0.3 R with
//   friction: every step sound, the pair's forces balanced.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tests/support/two_bodies.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

// Two hemispheres (the shipped hertz-sphere's section, R 10 mm), the upper one pressed down by
// `approach` at its diameter onto the lower one held at its diameter.
json sphere_pair(double approach, double friction, const json& lower_material) {
  json upper = example_scene("hertz-sphere")["body"];
  json lower = upper;
  upper["name"] = "upper";
  upper["mesh"]["half_disc"]["centre"] = {0, 10};
  upper["supports"][0]["values"]["y"] = -approach;
  lower["name"] = "lower";
  lower["material"] = lower_material;
  lower["mesh"]["half_disc"]["centre"] = {0, -10};
  lower["mesh"]["half_disc"]["facing"] = "up";
  lower["supports"] = {{{"set", "diameter"}, {"fix", {"y"}}}};
  return {{"bodies", {upper, lower}},
          {"contacts", {{{"slave", "upper.arc_refined"}, {"master", "lower.arc_refined"}, {"friction", friction}}}},
          {"steps", 4},
          {"solver", {{"contact", {{"method", "cev"}, {"tolerance", 1e-8}}}}}};
}

struct Reading {
  double P = 0.0;      // the total load over the circle, from the upper body's reactions
  double p0 = 0.0;     // the largest contact stress
  double shear = 0.0;  // the largest |sigma_t|
  double cone = 0.0;   // the largest |sigma_t| / (mu |sigma_n|) over pressed points
};

Reading last_step(const Solved& s, double friction) {
  const StepRecord& rec = s.run.steps.back();
  Reading r;
  r.P = -body_resultant(s.scene.problem, 0, rec.reactions).y();
  for (const ContactNode& n : contact_profile(s.scene.problem, rec)) {
    r.p0 = std::max(r.p0, -n.sigma_n);
    r.shear = std::max(r.shear, std::abs(n.sigma_t));
    if (friction > 0 && n.sigma_n < 0) r.cone = std::max(r.cone, std::abs(n.sigma_t) / (friction * -n.sigma_n));
  }
  return r;
}

// Every step sound; along the axis each body in equilibrium with its reactions and the pair's
// forces cancelling (a total radial force is no resultant in axisymmetry: the hoops carry it).
Solved solved_and_sound(const json& scene) {
  Solved s = solve_scene(scene);
  expect_every_step_sound(s);
  const Problem& problem = s.scene.problem;
  for (const StepRecord& rec : s.run.steps) {
    const Vector f = contact_forces(problem, rec);
    const double P = -body_resultant(problem, 0, rec.reactions).y();
    EXPECT_NEAR(body_resultant(problem, 0, f).y(), P, 1e-8 * P) << "step " << rec.index;
    EXPECT_NEAR(body_resultant(problem, 1, rec.reactions).y(), P, 1e-8 * P) << "step " << rec.index;
    EXPECT_NEAR(body_resultant(problem, 0, f).y() + body_resultant(problem, 1, f).y(), 0.0, 1e-12 * P);
  }
  return s;
}

// The discrete pair is not exactly symmetric (the slave takes nodal forces, the master their
// mortar spread), so the frictionless surfaces slip against each other a little and sticking
// moves a surface node by some 4 % of its radial displacement. What must not change is the
// answer: the load, the contact radius and the peak pressure. The stick multipliers of the
// quadratic sides are not smooth (a node's share alternates with its neighbours', up to 6 %
// of p0 here); their net is bounded.
TEST(AxisymmetricFrictionHard, IdenticalSpheresGiveTheFrictionlessAnswer) {
  constexpr double approach = 0.1;
  const json steel = example_scene("hertz-sphere")["body"]["material"];
  const Solved s0 = solved_and_sound(sphere_pair(approach, 0.0, steel));
  const Solved s1 = solved_and_sound(sphere_pair(approach, 0.5, steel));
  const Reading without = last_step(s0, 0.0), with = last_step(s1, 0.5);
  const EllipseFit f0 = fit_semi_ellipse_about(contact_profile(s0.scene.problem, s0.run.steps.back()), 0.0);
  const EllipseFit f1 = fit_semi_ellipse_about(contact_profile(s1.scene.problem, s1.run.steps.back()), 0.0);
  const double moved = (s1.run.steps.back().state.q - s0.run.steps.back().state.q).lpNorm<Eigen::Infinity>();
  double net_shear = 0.0;  // the tangential forces over the contact, summed with their signs
  for (const ContactNode& n : contact_profile(s1.scene.problem, s1.run.steps.back())) net_shear += n.p_t;
  std::printf(
      "identical spheres, mu 0.5 against 0: P %+.1e, a %+.2e, p0 %+.2e; displacements differ by %.1e of the "
      "approach; largest shear %.3f p0, net %.1e P\n",
      with.P / without.P - 1, f1.a / f0.a - 1, f1.p0 / f0.p0 - 1, moved / approach, with.shear / with.p0,
      net_shear / with.P);
  EXPECT_NEAR(with.P, without.P, 1e-4 * without.P);
  EXPECT_NEAR(f1.a, f0.a, 2e-3 * f0.a);
  EXPECT_NEAR(f1.p0, f0.p0, 2e-3 * f0.p0);
  EXPECT_LT(moved, 5e-3 * approach);
  EXPECT_LT(std::abs(net_shear), 0.02 * with.P);
}

TEST(AxisymmetricFrictionHard, SteelOnAluminiumEngagesFrictionInsideTheCone) {
  const json aluminium = {{"young", 70000}, {"poisson", 0.33}};
  const Reading without = last_step(solved_and_sound(sphere_pair(0.1, 0.0, aluminium)), 0.0);
  const Reading with = last_step(solved_and_sound(sphere_pair(0.1, 0.3, aluminium)), 0.3);
  std::printf(
      "steel on aluminium: P %.2f N without friction, %.2f N with mu 0.3 (%+.3f %%); shear %.3f p0, "
      "cone use %.3f\n",
      without.P, with.P, 100 * (with.P / without.P - 1), with.shear / with.p0, with.cone);
  EXPECT_GT(with.shear, 1e-3 * with.p0);      // friction is engaged
  EXPECT_LE(with.cone, 1.0 + 1e-6);           // and inside the cone
  EXPECT_GE(with.P, without.P * (1 - 1e-6));  // friction does not soften
  EXPECT_LT(with.P, without.P * 1.01);        // and stiffens by less than 1 %
}

TEST(AxisymmetricFrictionHard, RubberSpheresUnderFiniteKinematics) {
  const json rubber = {{"law", "neo_hookean"}, {"young", 10.0}, {"poisson", 0.45}};
  json scene = sphere_pair(1.5, 0.3, rubber);
  for (json& b : scene["bodies"]) {
    b["kinematics"] = "finite";
    b["material"] = rubber;
    b["mesh"]["half_disc"]["refine"]["extent"] = 4.0;  // beyond the contact radius, some 2.7 mm
    refine_pole(b["mesh"]["half_disc"], 0.25);
  }
  scene["steps"] = 5;
  const Solved s = solved_and_sound(scene);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  // The load grows with the approach, and the contact radius is large: the linear Hertz a
  // at the last load is some 0.3 R.
  double previous = 0.0;
  for (const StepRecord& rec : s.run.steps) {
    const double P = -body_resultant(s.scene.problem, 0, rec.reactions).y();
    EXPECT_GT(P, previous) << "step " << rec.index;
    previous = P;
  }
  const Reading r = last_step(s, 0.3);
  std::printf("rubber spheres: P %.3f N at 1.5 mm approach; shear %.3f p0, cone use %.3f\n", r.P, r.shear / r.p0,
              r.cone);
  EXPECT_LE(r.cone, 1.0 + 1e-6);
}

}  // namespace
}  // namespace grip
