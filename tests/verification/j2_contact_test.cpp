// Contact on a plastic body (docs/algorithm.md#j2-plasticity): the shipped Hertz scene (a
// half-cylinder R = 10 mm pressed 0.05 mm onto a rigid flat, plane strain, linear kinematics)
// with a von Mises material of yield stress 2000 MPa (the elastic Hertz peak pressure there is
// 2.9 sigma_y; yield starts below the surface at p0 = 1.79 sigma_y), loaded in 4 steps and
// unloaded in 4, by the cev and the ssn strategies. Checked against invariants:
// - at every step the contact resultant balances the support reactions;
// - after unloading the pole keeps a flattening (residual indentation) of a few per cent of the
//   approach, where the elastic body returns to zero;
// - every element that yielded lies under the contact (within 3 contact half-widths of the
//   pole), and the most strained one below the surface near the axis;
// - the plastic run's real solves against the elastic run's on the same scene (printed;
//   bench/results/plasticity.md), by cev and by ssn.
#include <gtest/gtest.h>

#include <cstdio>

#include "solver/elements/continuum.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

json pressed_and_released(bool plastic, const std::string& method) {
  json j = example_scene("hertz");
  j["body"]["element"] = "q4_bbar";  // plastic flow keeps the volume: q4 would lock
  if (plastic)
    j["body"]["material"].update(
        {{"law", "j2_plasticity"}, {"yield_stress", 2000.0}, {"hardening", {{"linear", 20000.0}}}});
  j.erase("steps");
  j["stages"] = json::array({{{"steps", 4}, {"factors", {{"main", 1}}}}, {{"steps", 4}, {"factors", {{"main", 0}}}}});
  j["solver"]["contact"]["method"] = method;
  return j;
}

struct Reading {
  double pole_uy = 0.0;  // after unloading: the pole's displacement (toward the centre: > 0)
  int solves = 0, newton = 0;
  double peak_alpha = 0.0;
};

Reading run(const json& j, bool plastic) {
  const Solved s = solve_scene(j);
  EXPECT_TRUE(s.run.completed) << s.run.reason;
  Reading out;
  if (!s.run.completed) return out;
  const Problem& problem = s.scene.problem;
  // The contact invariants where a load is carried (released, the forces are round-off).
  for (const StepRecord& rec : s.run.steps)
    if (reaction_resultant(problem, rec).norm() > 1.0) {
      EXPECT_TRUE(step_invariants(problem, rec, tolerances_of(s.scene))) << "step " << rec.index;
      if (j["solver"]["contact"]["method"] == "cev") EXPECT_TRUE(monotone_contact_error(rec)) << "step " << rec.index;
    }
  const auto& body = dynamic_cast<const ContinuumBody&>(*problem.body);
  const PlaneMesh& mesh = body.mesh();
  const std::vector<std::vector<int>> cells = body.cells();
  double a_max = 0.0;
  for (const StepRecord& rec : s.run.steps) {
    out.solves += rec.solves;
    out.newton += rec.newton_iterations;
    const Vec2 contact = contact_resultant(problem, rec), support = reaction_resultant(problem, rec);
    EXPECT_LT((contact + support).norm(), 1e-6 * std::max(1.0, support.norm())) << "step " << rec.index;
    const auto nodes = contact_profile(problem, rec);
    for (const auto& n : nodes)
      if (n.p_n < 0) a_max = std::max(a_max, std::abs(n.x));
  }
  const StepRecord& last = s.run.steps.back();
  int pole = -1;
  for (int k = 0; k < body.node_count(); ++k)
    if ((mesh.nodes[k] - Vec2(0, -10)).norm() < 1e-9) pole = k;
  EXPECT_GE(pole, 0);
  if (pole < 0) return out;
  out.pole_uy = last.site_fields.rows[pole][3];
  const std::vector<std::string>& names = last.element_fields.names;
  EXPECT_EQ(names.size(), plastic ? 6u : 4u);
  if (!plastic) return out;
  EXPECT_EQ(names[4], "equivalent_plastic_strain");
  // The yielded elements lie under the contact; the most strained below the surface near the axis.
  int yielded = 0, peak = -1;
  for (int e = 0; e < body.element_count(); ++e) {
    const double alpha = last.element_fields.rows[e][4];
    if (alpha <= 0) continue;
    ++yielded;
    Vec2 c = Vec2::Zero();
    for (int n : cells[e]) c += mesh.nodes[n] / 4;
    EXPECT_LT((c - Vec2(0, -10)).norm(), 3 * a_max) << "element " << e << " yielded far from the contact";
    if (alpha > out.peak_alpha) {
      out.peak_alpha = alpha;
      peak = e;
    }
  }
  EXPECT_GT(yielded, 10);
  if (peak >= 0) {
    Vec2 c = Vec2::Zero();
    for (int n : cells[peak]) c += mesh.nodes[n] / 4;
    const double depth = c.y() + 10;
    std::printf("plastic zone: %d elements, peak alpha %.3e at depth %.3f mm, x %.3f mm (a = %.3f mm)\n", yielded,
                out.peak_alpha, depth, c.x(), a_max);
    EXPECT_GT(depth, 0.1 * a_max);
    EXPECT_LT(std::abs(c.x()), a_max);
  }
  // No element is still flowing once unloaded.
  for (const auto& row : last.element_fields.rows) EXPECT_EQ(row[5], 0.0);
  return out;
}

TEST(J2Contact, PlasticCylinderKeepsAFlatAfterRelease) {
  for (const std::string method : {"cev", "ssn"}) {
    SCOPED_TRACE(method);
    const Reading elastic = run(pressed_and_released(false, method), false);
    const Reading plastic = run(pressed_and_released(true, method), true);
    std::printf(
        "%s: residual pole displacement elastic %.3e mm, plastic %.3e mm (approach 0.05 mm); real solves "
        "(Newton iterations) elastic %d (%d), plastic %d (%d): %.2fx\n",
        method.c_str(), elastic.pole_uy, plastic.pole_uy, elastic.solves, elastic.newton, plastic.solves,
        plastic.newton, double(plastic.solves) / elastic.solves);
    // The elastic body with a changing tangent (finite strain, q4), for the solve counts only.
    json finite = pressed_and_released(false, method);
    finite["body"]["kinematics"] = "finite";
    finite["body"]["element"] = "q4";
    const Reading nonlinear = run(finite, false);
    std::printf("%s: finite-strain elastic: real solves %d (Newton iterations %d); plastic / that: %.2fx\n",
                method.c_str(), nonlinear.solves, nonlinear.newton, double(plastic.solves) / nonlinear.solves);
    EXPECT_LT(std::abs(elastic.pole_uy), 1e-8);
    EXPECT_GT(plastic.pole_uy, 0.02 * 0.05);
  }
}

}  // namespace
}  // namespace grip

namespace grip {
namespace {

// The first issue's pointer and detail of a scene that must not read.
std::pair<std::string, std::string> refusal(const nlohmann::json& j) {
  try {
    read_scene(j);
  } catch (const SceneErrors& e) {
    if (!e.issues().empty()) return {e.issues()[0].pointer, e.issues()[0].detail};
  }
  return {"(read)", ""};
}

TEST(J2Contact, BadMaterialDataIsRefusedWithItsPointer) {
  const auto plastic = [](const nlohmann::json& extra) {
    nlohmann::json j = pressed_and_released(true, "cev");
    j["body"]["material"].update(extra);
    return j;
  };
  EXPECT_EQ(refusal(plastic({{"hardening", {{"linear", -100.0}}}})).first, "/body/material/hardening/linear");
  EXPECT_EQ(refusal(plastic({{"yield_stress", 0.0}})).first, "/body/material/yield_stress");
  EXPECT_EQ(refusal(plastic({{"kinematic_hardening", -1.0}})).first, "/body/material/kinematic_hardening");
  const auto table = refusal(plastic({{"hardening", {{"table", {{0, 2000}, {0.01, 2100}, {0.02, 2050}}}}}}));
  EXPECT_EQ(table.first, "/body/material/hardening/table/2/1");
  EXPECT_NE(table.second.find("must not decrease"), std::string::npos) << table.second;
  EXPECT_EQ(refusal(plastic({{"hardening", {{"table", {{0, 1900}}}}}})).first, "/body/material/hardening/table/0/1");
  EXPECT_EQ(refusal(plastic({{"hardening", {{"power", {{"K", 3000}, {"n", 0}}}}}})).first,
            "/body/material/hardening/power/n");
  EXPECT_EQ(refusal(plastic({{"hardening", {{"linear", 1.0}, {"table", {{0, 2000}}}}}})).first,
            "/body/material/hardening");
  // Finite strain takes isotropic hardening only.
  nlohmann::json finite = plastic({{"kinematic_hardening", 1000.0}});
  finite["body"]["kinematics"] = "finite";
  finite["body"]["element"] = "q4";
  EXPECT_EQ(refusal(finite).first, "/body/material/kinematic_hardening");
  nlohmann::json elastic = pressed_and_released(false, "cev");
  elastic["body"]["material"]["yield_stress"] = 100.0;
  EXPECT_EQ(refusal(elastic).first, "/body/material/yield_stress");
  nlohmann::json missing = plastic(nlohmann::json::object());
  missing["body"]["material"].erase("yield_stress");
  EXPECT_EQ(refusal(missing).first, "/body/material/yield_stress");
  // The effects block says plasticity is on.
  const Scene scene = read_scene(pressed_and_released(true, "cev"));
  EXPECT_TRUE(scene.problem.body->traits().plasticity);
  EXPECT_FALSE(scene.problem.body->traits().constant_tangent);
}

}  // namespace
}  // namespace grip
