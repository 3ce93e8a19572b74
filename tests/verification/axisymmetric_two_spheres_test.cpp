// Two deformable axisymmetric bodies in contact (docs/algorithm.md#axisymmetric): the mortar
// pair of plane strain with every integral weighed by 2 pi r. Two elastic hemispheres (the
// shipped hertz-sphere's section, q8, R1 = R2 = 10 mm) pressed together along their common
// axis: Hertz with 1/R = 1/R1 + 1/R2 and 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2, a = (3 P R /
// (4 E*))^(1/3), p0 = 3 P / (2 pi a^2), P the total over the circle read from the reactions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "tests/support/two_bodies.hpp"

namespace grip {
namespace {

using nlohmann::json;
using std::numbers::pi;
using namespace grip::testing;

// The upper sphere (steel) pressed down by 0.1 mm at its diameter onto the lower one (E 70 GPa,
// nu 0.33) held at its diameter; the upper arc is the slave.
json two_spheres() {
  json upper = example_scene("hertz-sphere")["body"];
  json lower = upper;
  upper["name"] = "upper";
  upper["mesh"]["half_disc"]["centre"] = {0, 10};
  upper["supports"][0]["values"]["y"] = -0.1;
  lower["name"] = "lower";
  lower["material"] = {{"young", 70000}, {"poisson", 0.33}};
  lower["mesh"]["half_disc"]["centre"] = {0, -10};
  lower["mesh"]["half_disc"]["facing"] = "up";
  lower["supports"] = {{{"set", "diameter"}, {"fix", {"y"}}}};
  return {{"bodies", {upper, lower}},
          {"contacts", {{{"slave", "upper.arc_refined"}, {"master", "lower.arc_refined"}, {"friction", 0}}}},
          {"steps", 2},
          {"solver", {{"contact", {{"method", "cev"}, {"tolerance", 1e-8}}}}}};
}

TEST(AxisymmetricTwoSpheres, HertzWithTheCombinedRadiusAndModulus) {
  const Solved s = solve_scene(two_spheres());
  expect_every_step_sound(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const json& bodies = s.scene.effective["bodies"];
  double inverse_R = 0, inverse_E = 0;
  for (const json& b : bodies) {
    const double E = b["material"]["young"], nu = b["material"]["poisson"];
    inverse_R += 1 / b["mesh"]["half_disc"]["radius"].get<double>();
    inverse_E += (1 - nu * nu) / E;
  }
  const Problem& problem = s.scene.problem;
  for (const StepRecord& rec : s.run.steps) {
    // Along the axis each body is in equilibrium with its reactions, and the pair's forces
    // cancel over the two bodies (r: a total radial force is no resultant, the hoops carry it).
    const Vector f = contact_forces(problem, rec);
    const double P = -body_resultant(problem, 0, rec.reactions).y();
    const double on_upper = body_resultant(problem, 0, f).y(), on_lower = body_resultant(problem, 1, f).y();
    EXPECT_NEAR(on_upper, P, 1e-8 * P);
    EXPECT_NEAR(body_resultant(problem, 1, rec.reactions).y(), P, 1e-8 * P);
    EXPECT_NEAR(on_upper + on_lower, 0.0, 1e-12 * P);
    const double a = std::cbrt(3 * P * inverse_E / (4 * inverse_R)), p0 = 3 * P / (2 * pi * a * a);
    const EllipseFit slave = fit_semi_ellipse_about(contact_profile(problem, rec), 0.0);
    const EllipseFit master = fit_semi_ellipse_about(master_field_profile(problem, rec, 0), 0.0);
    std::printf(
        "step %d: P %.1f N (balance upper %.1e, lower %.1e, pair %.1e of P); a %.4f mm: slave %+.3f %%, "
        "master %+.3f %%; p0 %.1f MPa: slave %+.3f %%, master %+.3f %%\n",
        rec.index, P, on_upper / P - 1, body_resultant(problem, 1, rec.reactions).y() / P - 1,
        (on_upper + on_lower) / P, a, 100 * (slave.a / a - 1), 100 * (master.a / a - 1), p0, 100 * (slave.p0 / p0 - 1),
        100 * (master.p0 / p0 - 1));
    EXPECT_NEAR(slave.a, a, 0.01 * a);
    EXPECT_NEAR(slave.p0, p0, 0.01 * p0);
    EXPECT_NEAR(master.a, a, 0.01 * a);
    EXPECT_NEAR(master.p0, p0, 0.01 * p0);
  }
}

// A section of revolution and a plane body in one scene: refused, naming the field.
TEST(AxisymmetricTwoSpheres, RefusesAPlaneBodyBesideAnAxisymmetricOne) {
  json j = two_spheres();
  j["bodies"][1]["analysis"] = "plane_strain";
  try {
    read_scene(j);
    ADD_FAILURE() << "a plane body beside an axisymmetric one was accepted";
  } catch (const SceneErrors& e) {
    bool found = false;
    for (const SceneIssue& issue : e.issues())
      found |=
          issue.pointer == "/bodies/1/analysis" && issue.detail.find("all sections of revolution") != std::string::npos;
    EXPECT_TRUE(found) << e.what();
  }
}

}  // namespace
}  // namespace grip
