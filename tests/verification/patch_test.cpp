// Contact patch test: a block of distorted elements, its top pushed down (prescribed), its
// sides free, on a rigid frictionless flat. The state is homogeneous uniaxial compression, so
// every bottom node carries the same contact stress, equal to the closed form:
//   linear: E' delta / H with E' = E / (1 - nu^2) (plane strain) or E (plane stress);
//   finite: the nominal stress P22 = lambda_y S22 of the neo-Hookean law at F = diag(lambda_x,
//   lambda_y), lambda_y = 1 - delta / H and lambda_x such that S11 = 0.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "solver/elements/continuum.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/distorted_mesh.hpp"
#include "tests/support/force_precision.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

constexpr double kWidth = 3.0, kHeight = 2.0, kYoung = 1000.0, kPoisson = 0.3;

// An explicit mesh of 4 x 3 quadrilaterals (or 24 triangles) with the interior nodes moved off the grid.
json distorted_block(ElementShape shape) {
  RectangleSpec spec;
  spec.size = {kWidth, kHeight};
  spec.nx = 4;
  spec.ny = 3;
  PlaneMesh mesh = distorted_rectangle(spec, shape, 0.15, 11);
  json nodes = json::array();
  for (const Vec2& x : mesh.nodes) nodes.push_back({x.x(), x.y()});
  return {
      {"nodes", nodes},
      {"elements", mesh.elements},
      {"sets", {{"bottom", mesh.sets["bottom"]}, {"top", mesh.sets["top"]}, {"corner", {mesh.sets["top"].back()}}}}};
}

json patch_scene(const std::string& element, const std::string& kinematics, const std::string& analysis, double delta) {
  ContinuumElement kind = ContinuumElement::q4;
  for (ContinuumElement e : {ContinuumElement::t3, ContinuumElement::t6, ContinuumElement::q8, ContinuumElement::q9})
    if (element == element_name(e)) kind = e;
  const ElementShape shape = element_shape(kind);
  return {
      {"body",
       {{"model", "continuum"},
        {"kinematics", kinematics},
        {"analysis", analysis},
        {"element", element},
        {"thickness", 0.5},
        {"material", {{"young", kYoung}, {"poisson", kPoisson}}},
        {"mesh", distorted_block(shape)},
        {"contact_set", "bottom"},
        {"supports",
         {{{"set", "top"}, {"fix", {"y"}}, {"values", {{"y", -delta}}}}, {{"set", "corner"}, {"fix", {"x"}}}}}}},
      {"obstacles",
       {{{"name", "flat"}, {"shape", {{"type", "segment"}, {"from", {10, 0}}, {"to", {-10, 0}}}}, {"friction", 0}}}},
      {"steps", 2}};
}

// The nominal compressive stress of the homogeneous state, by the closed forms above.
double closed_form(const std::string& kinematics, PlaneAnalysis analysis, double delta) {
  const double ly = 1 - delta / kHeight;
  if (kinematics == "linear")
    return (analysis == PlaneAnalysis::plane_strain ? kYoung / (1 - kPoisson * kPoisson) : kYoung) * delta / kHeight;
  const NeoHookeMaterial law(kYoung, kPoisson, analysis);
  double lx = 1.0;
  for (int it = 0; it < 50; ++it) {  // Newton on S11(lambda_x) = 0
    Mat2 E = Mat2::Zero();
    E(0, 0) = 0.5 * (lx * lx - 1);
    E(1, 1) = 0.5 * (ly * ly - 1);
    const MaterialResponse r = law.response(E);
    const double step = r.S[0] / (r.D(0, 0) * lx);
    lx -= step;
    if (std::abs(step) < 1e-15) break;
  }
  Mat2 E = Mat2::Zero();
  E(0, 0) = 0.5 * (lx * lx - 1);
  E(1, 1) = 0.5 * (ly * ly - 1);
  return -ly * law.response(E).S[1];
}

TEST(ContactPatch, UniformCompressionGivesUniformPressure) {
  struct Case {
    const char* element;
    const char* kinematics;
    const char* analysis;
  };
  const Case cases[] = {
      {"q4", "linear", "plane_strain"}, {"q4", "linear", "plane_stress"}, {"q4_bbar", "linear", "plane_strain"},
      {"q9", "linear", "plane_strain"}, {"q4", "finite", "plane_strain"}, {"q4", "finite", "plane_stress"},
      {"q9", "finite", "plane_strain"}, {"q9", "finite", "plane_stress"}, {"t3", "linear", "plane_strain"},
      {"t6", "linear", "plane_stress"}, {"q8", "linear", "plane_strain"}, {"t3", "finite", "plane_strain"},
      {"t6", "finite", "plane_strain"}, {"t6", "finite", "plane_stress"}, {"q8", "finite", "plane_strain"}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.element) + " " + c.kinematics + " " + c.analysis);
    // Finite strain at 5 % compression; the linear cases are exact at any size.
    const double delta = std::string(c.kinematics) == "finite" ? 0.1 : 0.004;
    const Solved s = solve_scene(patch_scene(c.element, c.kinematics, c.analysis, delta));
    expect_every_step_sound(s);
    ASSERT_TRUE(s.run.completed);
    const PlaneAnalysis analysis =
        std::string(c.analysis) == "plane_strain" ? PlaneAnalysis::plane_strain : PlaneAnalysis::plane_stress;
    const StepRecord& last = s.run.steps.back();
    const double expected = closed_form(c.kinematics, analysis, delta);
    // The step ends at ||v|| <= tol, which pins each nodal force only to the correction
    // dp = C_EE^-1 v_E that its remaining error asks for (force_precision.hpp): the pressures
    // equal the closed form to round-off (1e-9) plus the largest |dp| over its tributary area,
    // and the forces corrected by dp equal it to round-off.
    const Problem& problem = s.scene.problem;
    const Vector dp = force_correction(s.scene, last);
    double worst = 0.0, corrected = 0.0, pinned = 0.0, pinned_total = 0.0, mean = 0.0;
    for (const Candidate& cand : problem.candidates) {
      const double area = problem.body->tributary_area(cand.site);
      const double sigma = -last.p[cand.eta] / area;
      worst = std::max(worst, std::abs(sigma - expected));
      corrected = std::max(corrected, std::abs(-(last.p[cand.eta] - dp[cand.eta]) / area - expected));
      pinned = std::max(pinned, std::abs(dp[cand.eta]) / area);
      pinned_total += std::abs(dp[cand.eta]);
      mean += sigma / problem.candidates.size();
    }
    std::printf(
        "%-8s %-7s %-13s sigma_n %.9g, closed form %.9g, largest deviation %.2e relative (pinned to %.2e; "
        "corrected %.2e)\n",
        c.element, c.kinematics, c.analysis, mean, expected, worst / expected, pinned / expected, corrected / expected);
    EXPECT_LT(worst, 1e-9 * expected + pinned);
    EXPECT_LT(corrected, 1e-9 * expected);
    // The reactions carry the same: sigma times the bottom's area, to the sum of the |dp|.
    EXPECT_NEAR(-reaction_resultant(problem, last).y(), expected * kWidth * 0.5,
                1e-9 * expected * kWidth + pinned_total);
  }
}

}  // namespace
}  // namespace grip
