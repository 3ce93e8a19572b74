// Contact on a plastic body (docs/algorithm.md#j2-plasticity): the shipped Hertz scene (a
// half-cylinder R = 10 mm pressed 0.05 mm onto a rigid flat, plane strain, linear kinematics)
// with a von Mises material of yield stress 2000 MPa (the elastic Hertz peak pressure there is
// 2.9 sigma_y; yield starts below the surface at p0 = 1.79 sigma_y), loaded in 4 steps and
// unloaded in 4, by every contact strategy. Checked against invariants:
// - at every step the contact resultant balances the support reactions;
// - after unloading the pole keeps a flattening (residual indentation) of a few per cent of the
//   approach, where the elastic body returns to zero;
// - every element that yielded lies under the contact (within 3 contact half-widths of the
//   pole), and the most strained one below the surface near the axis;
// - the plastic run's real solves against the linear elastic run's on the same scene (issue
//   37: at most 1.5 x), printed for every strategy and asserted where met
//   (bench/results/plasticity.md says which are not and why). The diameter is lowered by a
//   prescribed displacement, so no increment starts at rest (the start of a plastic body's
//   increment where only obstacles moved: docs/algorithm.md#load-stepping-and-cuts).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "solver/elements/continuum.hpp"
#include "solver/io/gmsh_mesh.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

// Pressed in 4 steps and released in `release_steps` to the factor `released` (0: the diameter
// back where it started).
json pressed_and_released_by(bool plastic, const json& contact, int release_steps = 4, double released = 0.0) {
  json j = example_scene("hertz");
  j["body"]["element"] = "q4_bbar";  // plastic flow keeps the volume: q4 would lock
  if (plastic)
    j["body"]["material"].update(
        {{"law", "j2_plasticity"}, {"yield_stress", 2000.0}, {"hardening", {{"linear", 20000.0}}}});
  j.erase("steps");
  j["stages"] = json::array(
      {{{"steps", 4}, {"factors", {{"main", 1}}}}, {{"steps", release_steps}, {"factors", {{"main", released}}}}});
  j["solver"]["contact"].update(contact);
  return j;
}

json pressed_and_released(bool plastic, const std::string& method) {
  return pressed_and_released_by(plastic, json{{"method", method}});
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
      if (j["solver"]["contact"]["method"] == "cev" && !j["solver"]["contact"].contains("loop"))
        EXPECT_TRUE(monotone_contact_error(rec)) << "step " << rec.index;
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
    std::printf("%s: residual pole displacement elastic %.3e mm, plastic %.3e mm (approach 0.05 mm)\n", method.c_str(),
                elastic.pole_uy, plastic.pole_uy);
    EXPECT_LT(std::abs(elastic.pole_uy), 1e-8);
    EXPECT_GT(plastic.pole_uy, 0.02 * 0.05);
  }
}

// Issue 37: the contact solve's real solves on the plastic body within 1.5 x of the linear
// elastic body's on the same scene, for every strategy. For cev the elastic body with a
// changing tangent (finite strain, q4) too: what a changing tangent alone costs.
struct Strategy {
  std::string name;
  json contact;
  bool within = true;  // the 1.5 x is met (asserted); otherwise printed only
  int release_steps = 4;
  double released = 0.0;
};

TEST(J2Contact, RealSolvesWithinOneAndAHalfOfTheElasticBody) {
  const std::vector<Strategy> strategies = {
      // cev's default: held real solves on the plastic body, given ones on the elastic body
      // (docs/algorithm.md#the-held-real-solve).
      {"cev", {{"method", "cev"}}},
      // Under given forces throughout: not met (1.87 x; bench/results/plasticity.md): one update
      // is exact on the linear elastic body, while on the plastic one each update moves the
      // plastic zone's edge, which the tangent at the state does not foresee (0.1-0.3 of the
      // error left per update at first).
      {"cev given", {{"method", "cev"}, {"real_solve", "given"}}, false},
      {"cev loop paper", {{"method", "cev"}, {"loop", "paper"}}},
      {"ssn", {{"method", "ssn"}}},
      // One real solve per step whatever the body; its error is about |p| / k, so the
      // tolerance follows the law's stiffness (docs/algorithm.md#tolerance).
      {"penalty", {{"method", "penalty"}, {"tolerance", 1e-4}, {"penalty", {{"factor", 1e4}}}}},
      // Linear convergence (a fixed multiplier step): a looser tolerance, and released to a
      // quarter only: at the full release the elastic body's displacement, and with it the
      // step's bound tolerance x D, goes to zero, below what the fixed step reaches.
      {"uzawa", {{"method", "uzawa"}, {"tolerance", 1e-5}, {"max_iterations", 20000}}, true, 3, 0.25},
  };
  for (const Strategy& st : strategies) {
    SCOPED_TRACE(st.name);
    const auto scene = [&](bool plastic) {
      return pressed_and_released_by(plastic, st.contact, st.release_steps, st.released);
    };
    const Reading elastic = run(scene(false), false);
    const Reading plastic = run(scene(true), true);
    const double ratio = double(plastic.solves) / elastic.solves;
    std::printf(
        "%s: real solves (Newton iterations) linear elastic %d (%d), plastic %d (%d): plastic / linear elastic "
        "%.2fx%s\n",
        st.name.c_str(), elastic.solves, elastic.newton, plastic.solves, plastic.newton, ratio,
        st.within ? "" : " (not met)");
    if (st.name == "cev") {
      json finite = scene(false);
      finite["body"]["kinematics"] = "finite";
      finite["body"]["element"] = "q4";
      const Reading nonlinear = run(finite, false);
      std::printf("cev: finite-strain elastic %d (%d): plastic / that %.2fx\n", nonlinear.solves, nonlinear.newton,
                  double(plastic.solves) / nonlinear.solves);
    }
    EXPECT_GT(elastic.solves, 0);
    if (st.within) EXPECT_LE(ratio, 1.5);
  }
}

// cev with held real solves (solver.contact.real_solve: held, the default on a plastic body,
// docs/algorithm.md#the-held-real-solve): the same answer as with solves under the given forces,
// the contact forces and displacements of every step to what the contact tolerance pins them to,
// in fewer real solves: each update's solve holds the pressing points toward the linear model's
// gaps, so the yielding the tangent at the state does not foresee no longer leaves 0.1-0.3 of the
// error (measured: 16 real solves against 28, 1.07 x the linear elastic body's 15; 19, 1.27 x, before
// the held trials moved their springs' base forces).
TEST(J2Contact, HeldRealSolvesGiveTheSameAnswerInFewerSolves) {
  const Solved given = solve_scene(pressed_and_released_by(true, {{"method", "cev"}, {"real_solve", "given"}}));
  const Solved held = solve_scene(pressed_and_released_by(true, {{"method", "cev"}, {"real_solve", "held"}}));
  const Solved elastic = solve_scene(pressed_and_released(false, "cev"));
  ASSERT_TRUE(given.run.completed && held.run.completed && elastic.run.completed);
  ASSERT_EQ(given.run.steps.size(), held.run.steps.size());
  int given_solves = 0, held_solves = 0, elastic_solves = 0;
  double force_gap = 0.0, displacement_gap = 0.0;
  for (size_t k = 0; k < given.run.steps.size(); ++k) {
    const StepRecord &a = given.run.steps[k], &b = held.run.steps[k];
    given_solves += a.solves;
    held_solves += b.solves;
    elastic_solves += elastic.run.steps[k].solves;
    force_gap = std::max(force_gap, (a.p - b.p).cwiseAbs().maxCoeff() / std::max(1.0, a.p.cwiseAbs().maxCoeff()));
    displacement_gap = std::max(displacement_gap, (a.state.q - b.state.q).cwiseAbs().maxCoeff());
  }
  std::printf(
      "cev held: real solves %d against %d under given forces (linear elastic %d: %.2fx); largest force difference "
      "%.1e of the step's largest, displacement %.1e mm\n",
      held_solves, given_solves, elastic_solves, double(held_solves) / elastic_solves, force_gap, displacement_gap);
  // The displacements to 1e-8 of the 0.05 mm approach, the forces to 1e-6 of the largest.
  EXPECT_LT(displacement_gap, 1e-8 * 0.05);
  EXPECT_LT(force_gap, 1e-6);
  EXPECT_LE(held_solves, 1.5 * elastic_solves);
  EXPECT_LT(held_solves, given_solves);
}

// A held trial whose carried forces leave the cone is solved once more with those points let go
// (docs/algorithm.md#the-held-real-solve): the plastic sphere (hertz-sphere's axisymmetric q8
// body with the J2 law above, pressed in 4 steps and released in 4), whose full held trials
// left a point at the contact's edge pulled, took 107 real solves held where given forces take
// 35 (the line search halved its way down); letting go, 31, with the same answer.
TEST(J2Contact, HeldSolvesLetGoOfPointsThatLeaveTheCone) {
  const auto sphere = [](const std::string& real_solve) {
    json j = example_scene("hertz-sphere");
    j["body"]["material"].update(
        {{"law", "j2_plasticity"}, {"yield_stress", 2000.0}, {"hardening", {{"linear", 20000.0}}}});
    j.erase("steps");
    j["stages"] = json::array({{{"steps", 4}, {"factors", {{"main", 1}}}}, {{"steps", 4}, {"factors", {{"main", 0}}}}});
    j["solver"]["contact"]["real_solve"] = real_solve;
    return solve_scene(j);
  };
  const Solved given = sphere("given"), held = sphere("held");
  ASSERT_TRUE(given.run.completed && held.run.completed);
  ASSERT_EQ(given.run.steps.size(), held.run.steps.size());
  int given_solves = 0, held_solves = 0;
  double force_gap = 0.0, displacement_gap = 0.0;
  for (size_t k = 0; k < given.run.steps.size(); ++k) {
    const StepRecord &a = given.run.steps[k], &b = held.run.steps[k];
    given_solves += a.solves;
    held_solves += b.solves;
    force_gap = std::max(force_gap, (a.p - b.p).cwiseAbs().maxCoeff() / std::max(1.0, a.p.cwiseAbs().maxCoeff()));
    displacement_gap = std::max(displacement_gap, (a.state.q - b.state.q).cwiseAbs().maxCoeff());
  }
  std::printf("plastic sphere: real solves held %d, given %d; largest force difference %.1e, displacement %.1e mm\n",
              held_solves, given_solves, force_gap, displacement_gap);
  EXPECT_LT(held_solves, given_solves);
  EXPECT_LT(displacement_gap, 1e-8 * 0.05);
  EXPECT_LT(force_gap, 1e-6);
}

// A held trial's Newton correction test is divided by 1 + held_stiffness (its carried forces move
// by k_j = c / C_jj times Newton's last correction; docs/algorithm.md#the-held-real-solve). With
// the test of a solve under given forces, hertz-t6's plastic body (the shipped t6 mesh with the
// J2 law above, pressed in 4 steps and released in 4) at c = 100 took 19 real solves in its
// first release step against 5 given: every trial of its second update found 2e-4 of Newton's
// inexactness as contact error, above the 2.3e-5 it started from, at every length, and the step
// was cut. Asserted: at c = 100 and at the default, no step takes more real solves held than
// given, and the answers agree.
TEST(J2Contact, HeldStepsTakeNoMoreRealSolvesThanGivenOnGmshTriangles) {
  const auto examples = [](const json& ref) {
    return std::make_shared<const GmshMesh>(
        read_gmsh_file(std::string(GRIP_SOURCE_DIR) + "/schemas/examples/" + ref["file"].get<std::string>()));
  };
  const auto t6 = [&](const json& contact) {
    json j = example_scene("hertz-t6");
    j["body"]["material"].update(
        {{"law", "j2_plasticity"}, {"yield_stress", 2000.0}, {"hardening", {{"linear", 20000.0}}}});
    j.erase("steps");
    j["stages"] = json::array({{{"steps", 4}, {"factors", {{"main", 1}}}}, {{"steps", 4}, {"factors", {{"main", 0}}}}});
    j["solver"]["contact"].update(contact);
    return solve_scene(j, examples);
  };
  const Solved given = t6({{"real_solve", "given"}});
  ASSERT_TRUE(given.run.completed) << given.run.reason;
  for (const json& held_contact : {json{{"held_stiffness", 100.0}}, json::object()}) {
    SCOPED_TRACE(held_contact.dump());
    const Solved held = t6(held_contact);
    ASSERT_TRUE(held.run.completed) << held.run.reason;
    EXPECT_EQ(held.scene.effective["solver"]["contact"]["real_solve"], "held");
    ASSERT_EQ(given.run.steps.size(), held.run.steps.size());
    std::string counts;
    for (size_t k = 0; k < given.run.steps.size(); ++k) {
      const StepRecord &a = given.run.steps[k], &b = held.run.steps[k];
      counts += " " + std::to_string(b.solves) + "/" + std::to_string(a.solves);
      EXPECT_LE(b.solves, a.solves) << "step " << a.index;
      EXPECT_LT((a.p - b.p).cwiseAbs().maxCoeff(), 1e-6 * std::max(1.0, a.p.cwiseAbs().maxCoeff()))
          << "step " << a.index;
      EXPECT_LT((a.state.q - b.state.q).cwiseAbs().maxCoeff(), 1e-8 * 0.05) << "step " << a.index;
    }
    std::printf("plastic hertz-t6, real solves per step held / given:%s\n", counts.c_str());
  }
}

// cev's real solves by default: held where a body has plasticity (one of several bodies
// included), given otherwise, and as the scene says where it says.
TEST(J2Contact, PlasticBodiesTakeHeldRealSolvesByDefault) {
  const auto real_solve = [](const json& j) {
    const Scene s = read_scene(j);
    const std::string written = s.effective["solver"]["contact"]["real_solve"];
    EXPECT_EQ(written == "held", s.params.contact.real_solve == RealSolve::held) << written;
    return written;
  };
  EXPECT_EQ(real_solve(pressed_and_released(true, "cev")), "held");
  EXPECT_EQ(real_solve(pressed_and_released(false, "cev")), "given");
  EXPECT_EQ(real_solve(pressed_and_released_by(true, {{"real_solve", "given"}})), "given");
  EXPECT_EQ(real_solve(pressed_and_released_by(false, {{"real_solve", "held"}})), "held");
  json pair = example_scene("two-cylinders");
  EXPECT_EQ(real_solve(pair), "given");
  pair["bodies"][1]["element"] = "q4_bbar";
  pair["bodies"][1]["material"].update(
      {{"law", "j2_plasticity"}, {"yield_stress", 2000.0}, {"hardening", {{"linear", 20000.0}}}});
  EXPECT_EQ(real_solve(pair), "held");
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
  // Finite strain takes kinematic hardening (on the log strain), and the plain q4 is refused.
  nlohmann::json finite = plastic({{"kinematic_hardening", 1000.0}});
  finite["body"]["kinematics"] = "finite";
  finite["body"]["element"] = "q8";
  EXPECT_EQ(refusal(finite).first, "(read)");
  finite["body"]["element"] = "q4";
  EXPECT_EQ(refusal(finite).first, "/body/element");
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
