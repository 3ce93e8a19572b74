// The scene's quantities of interest (outputs, solver/io/quantities.hpp) against what they
// measure: on Hertz's half-cylinder the contact resultant carries the load the supports apply
// (equilibrium), the contact width is Hertz's 2a and the peak pressure his p0 within the
// tolerances of tests/verification/hertz_test.cpp, a displacement is the value of the result's
// field; on Cattaneo-Mindlin the stick width is 2c within cattaneo_mindlin_test.cpp's
// tolerance. The result's outputs equal the step_finished events' bit for bit and validate
// against the schemas; bad outputs are refused with the pointer of the field at fault.
#include <gtest/gtest.h>

#include <cstdio>
#include <numbers>
#include <sstream>

#include "solver/io/gmsh_mesh.hpp"
#include "solver/io/result.hpp"
#include "solver/io/schema_validation.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

json hertz_with_outputs() {
  json j = example_scene("hertz");
  j["outputs"] = json::parse(R"([
    {"name": "P", "kind": "resultant", "obstacle": "flat", "component": "y"},
    {"name": "support", "kind": "reaction", "set": "diameter", "component": "y"},
    {"name": "width", "kind": "contact_width"},
    {"name": "p0", "kind": "peak_pressure"},
    {"name": "mid", "kind": "displacement", "at": [0.3, -5], "component": "y"},
    {"name": "sxx", "kind": "field", "at": [0, -9.9], "component": "sxx"}
  ])");
  return j;
}

struct Solve {
  Solved solved;
  std::vector<json> events;
  json result;
};

Solve solve_with_events(const json& scene) {
  Solve out{{read_scene(scene), {}}, {}, {}};
  Scene& s = out.solved.scene;
  SteppingObserver observer;
  observer.step_finished = [&](const StepRecord& rec) {
    out.events.push_back(step_finished_event(s.problem, rec, s.output));
  };
  out.solved.run = run_load_steps(s.problem, s.steps, s.params, observer);
  std::ostringstream text;
  write_result(text, s, out.solved.run);
  out.result = json::parse(text.str());
  return out;
}

TEST(Outputs, HertzQuantitiesMatchEquilibriumAndTheClosedForm) {
  const Solve r = solve_with_events(hertz_with_outputs());
  const Solved& s = r.solved;
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const json& body = s.scene.effective["body"];
  for (size_t k = 0; k < s.run.steps.size(); ++k) {
    const StepRecord& rec = s.run.steps[k];
    const json& out = r.result["steps"][k]["outputs"];
    ASSERT_TRUE(out.is_object());
    // The events carry the result's numbers, bit for bit.
    EXPECT_EQ(out, r.events[k]["outputs"]);
    const double P = out["P"], support = out["support"], width = out["width"], p0 = out["p0"];
    // Equilibrium: the contact resultant carries what the supports apply, and is the sum of the
    // contact forces (tests/support's resultant).
    EXPECT_NEAR(P, -support, 1e-8 * P);
    EXPECT_NEAR(P, contact_resultant(s.scene.problem, rec, 0).y(), 1e-12 * P);
    const HertzContact hertz = hertz_contact(body, P);
    std::printf("step %zu: P %.3f N/mm; width %.5f mm = 2a %+.3f %% (a = %.5f); peak %.1f MPa, p0 %+.3f %%\n", k + 1, P,
                width, 100 * (width / (2 * hertz.a) - 1), hertz.a, p0, 100 * (p0 / hertz.p0 - 1));
    EXPECT_LT(std::abs(width / (2 * hertz.a) - 1), 0.02);
    EXPECT_LT(std::abs(p0 / hertz.p0 - 1), 0.02);
    // The width ends between the nodes where contact ends (the helper's bracket, whose x is
    // the reference abscissa; the width is the length along the undeformed arc).
    const Zone zone = contact_zone(contact_profile(s.scene.problem, rec));
    ASSERT_TRUE(zone.found);
    EXPECT_GE(width, zone.right.inner - zone.left.inner);
    EXPECT_LE(width, zone.right.outer - zone.left.outer + 1e-3 * width);
    // The peak is the result's largest contact stress.
    double peak = 0;
    for (const json& point : r.result["steps"][k]["contact_points"])
      peak = std::max(peak, -point["sigma_n"].get<double>());
    EXPECT_NEAR(p0, peak, 5e-7 * p0);
    // The displacement is the field's value (rounded to 7 digits) at the node nearest the point
    // (in the reference configuration); halfway between the diameter (-0.05 mm) and the pole
    // (held at 0 by the flat) it is between them.
    const json* near = nullptr;
    double d = 1e300;
    for (const json& n : r.result["steps"][k]["nodes"]) {
      const double x = n["x"].get<double>() - n["ux"].get<double>(), y = n["y"].get<double>() - n["uy"].get<double>();
      if (std::hypot(x - 0.3, y + 5) < d) {
        d = std::hypot(x - 0.3, y + 5);
        near = &n;
      }
    }
    ASSERT_NE(near, nullptr);
    const double uy = (*near)["uy"], mid = out["mid"];
    EXPECT_NEAR(mid, uy, 5e-7 * std::abs(uy));
    EXPECT_LT(mid, 0.0);
    EXPECT_GT(mid, -0.05 * rec.load_factor);
    // An element field: sxx in the element at the pole, as the elements table has it.
    bool found = false;
    for (const json& e : r.result["steps"][k]["elements"])
      found |= std::abs(e["sxx"].get<double>() - out["sxx"].get<double>()) <= 5e-7 * std::abs(out["sxx"].get<double>());
    EXPECT_TRUE(found);
    EXPECT_LT(out["sxx"].get<double>(), 0.0);  // compressed under the contact
  }
  EXPECT_TRUE(validate_against(r.result, SchemaName::result).empty());
  for (const json& ev : r.events) EXPECT_TRUE(validate_against(ev, SchemaName::event).empty()) << ev.dump();
}

TEST(Outputs, StickWidthIsCattaneoMindlins) {
  json j = example_scene("cattaneo-mindlin");
  j["outputs"] = json::parse(R"([
    {"name": "stick", "kind": "stick_width", "obstacle": "flat"},
    {"name": "width", "kind": "contact_width"},
    {"name": "Q", "kind": "resultant", "component": "x"},
    {"name": "P", "kind": "resultant", "component": "y"}
  ])");
  const Solve r = solve_with_events(j);
  const Solved& s = r.solved;
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const json& body = s.scene.effective["body"];
  const double mu = 0.3;
  for (size_t k = 2; k < s.run.steps.size(); ++k) {  // the shear stage
    const json& out = r.result["steps"][k]["outputs"];
    const double P = out["P"], Q = std::abs(out["Q"].get<double>());
    const HertzContact hertz = hertz_contact(body, P);
    const double c = hertz.a * std::sqrt(1 - Q / (mu * P));
    const double stick = out["stick"];
    std::printf("step %zu: Q / mu P = %.3f; stick width %.5f mm, 2c = %.5f mm (%+.2f %% of 2a); width / 2a %.4f\n",
                k + 1, Q / (mu * P), stick, 2 * c, 100 * (stick - 2 * c) / (2 * hertz.a),
                out["width"].get<double>() / (2 * hertz.a));
    EXPECT_LT(std::abs(0.5 * stick - c), 0.03 * hertz.a);
    EXPECT_LT(stick, out["width"].get<double>());
  }
}

// The press fit (schemas/examples/press-fit.json) once the interference is closed (step 1): the
// hub's pressure on each half of the shaft's surface (a contact pair of two bodies) adds up to
// 2 p R across the diameter with Lame's p = 209.5 MPa of the example, the halves balance, the
// whole half-circle presses, and the peak pressure is p.
TEST(Outputs, PressFitPairsCarryLamesPressure) {
  json j = example_scene("press-fit");
  j["outputs"] = json::parse(R"([
    {"name": "upper", "kind": "resultant", "obstacle": "shaft.shaft_upper on hub.hub_upper", "component": "y"},
    {"name": "lower", "kind": "resultant", "obstacle": "shaft.shaft_lower on hub.hub_lower", "component": "y"},
    {"name": "width", "kind": "contact_width", "obstacle": "shaft.shaft_upper on hub.hub_upper"},
    {"name": "peak", "kind": "peak_pressure"}
  ])");
  const std::string folder = std::string(GRIP_SOURCE_DIR) + "/schemas/examples/";
  Scene scene = read_scene(j, [&](const json& ref) {
    return std::make_shared<const GmshMesh>(read_gmsh_file(folder + ref["file"].get<std::string>()));
  });
  const RunResult run = run_load_steps(scene.problem, scene.steps, scene.params);
  ASSERT_TRUE(run.completed) << run.reason;
  const json out = quantity_values(scene.problem, run.steps[0], scene.output.quantities);
  const double p = 209.5, R = 10.0, upper = out["upper"], lower = out["lower"];
  std::printf("upper %.2f, lower %.2f N/mm (2 p R = %.1f); width %.4f mm (pi R %.4f); peak %.2f MPa\n", upper, lower,
              2 * p * R, out["width"].get<double>(), std::numbers::pi * R, out["peak"].get<double>());
  EXPECT_NEAR(upper, -lower, 1e-8 * lower);
  EXPECT_NEAR(lower, 2 * p * R, 0.01 * 2 * p * R);
  EXPECT_NEAR(out["width"].get<double>(), std::numbers::pi * R, 0.002 * std::numbers::pi * R);
  EXPECT_NEAR(out["peak"].get<double>(), p, 0.01 * p);
}

// A plastic strain as a field output: the shipped Hertz scene with a von Mises material
// (yield 2000 MPa, as tests/verification/j2_contact_test.cpp) pressed in 2 steps and released in
// 2. Below the pole, where yield starts (0.78 a deep), the equivalent plastic strain is the
// elements table's value, grows while loading, is positive at the peak load, and is kept when
// the load is released (it never decreases).
TEST(Outputs, APlasticStrainBelowTheContactGrowsAndIsKept) {
  json j = example_scene("hertz");
  j["body"]["element"] = "q4_bbar";
  j["body"]["material"].update(
      {{"law", "j2_plasticity"}, {"yield_stress", 2000.0}, {"hardening", {{"linear", 20000.0}}}});
  j.erase("steps");
  j["stages"] = json::array({{{"steps", 2}, {"factors", {{"main", 1}}}}, {{"steps", 2}, {"factors", {{"main", 0}}}}});
  j["outputs"] = json::parse(R"([
    {"name": "alpha", "kind": "field", "at": [0, -9.6], "component": "equivalent_plastic_strain"}
  ])");
  const Solve r = solve_with_events(j);
  ASSERT_TRUE(r.solved.run.completed) << r.solved.run.reason;
  double before = 0.0;
  for (size_t k = 0; k < r.solved.run.steps.size(); ++k) {
    const json& step = r.result["steps"][k];
    const double alpha = step["outputs"]["alpha"];
    std::printf("step %zu: load factor %.2f, alpha %.4e\n", k + 1, step["load_factor"].get<double>(), alpha);
    bool found = false;
    for (const json& e : step["elements"])
      found |= std::abs(e["equivalent_plastic_strain"].get<double>() - alpha) <= 5e-7 * alpha;
    EXPECT_TRUE(found) << "step " << k + 1;
    EXPECT_GE(alpha, before) << "step " << k + 1;
    before = alpha;
  }
  EXPECT_GT(r.result["steps"][1]["outputs"]["alpha"].get<double>(), 0.0);
}

// The first issue of reading `scene` (with outputs `outputs`): its pointer and detail.
SceneIssue first_issue(json outputs, json scene = example_scene("hertz")) {
  scene["outputs"] = std::move(outputs);
  try {
    read_scene(scene);
  } catch (const SceneErrors& e) {
    return e.issues().front();
  }
  return {};
}

TEST(Outputs, BadOutputsAreRefusedWithThePointer) {
  struct Case {
    const char* outputs;
    const char* pointer;
    const char* says;
  };
  const Case cases[] = {
      {R"([{"name": "r", "kind": "reaction", "set": "rim", "component": "y"}])", "/outputs/0/set", "names no node set"},
      {R"([{"name": "r", "kind": "resultant", "obstacle": "wall", "component": "y"}])", "/outputs/0/obstacle",
       "names no obstacle"},
      {R"([{"name": "r", "kind": "peak_pressure"}, {"name": "r", "kind": "contact_width"}])", "/outputs/1/name",
       "another output"},
      {R"([{"name": "r", "kind": "displacement", "node": 100000000, "component": "y"}])", "/outputs/0/node", "outside"},
      {R"([{"name": "r", "kind": "displacement", "node": 3, "at": [0, 0], "component": "y"}])", "/outputs/0",
       "exactly one"},
      {R"([{"name": "r", "kind": "stick_width"}])", "/outputs/0/kind", "no friction"},
      {R"([{"name": "r", "kind": "peak_pressure", "set": "diameter"}])", "/outputs/0/set", "is not used by"},
      {R"([{"name": "r", "kind": "field", "element": 0, "component": "equivalent_plastic_strain"}])",
       "/outputs/0/component", "plasticity"},
      {R"([{"name": "r", "kind": "reaction", "set": "diameter", "component": "z"}])", "/outputs/0/component", "z"},
      {R"([{"name": "r", "kind": "torque"}])", "/outputs/0/kind", ""},
  };
  for (const Case& c : cases) {
    const SceneIssue issue = first_issue(json::parse(c.outputs));
    EXPECT_EQ(issue.pointer, c.pointer) << c.outputs << ": " << issue.detail;
    EXPECT_NE(issue.detail.find(c.says), std::string::npos) << c.outputs << ": " << issue.detail;
  }
  // A field output reads every step's fields.
  json last = example_scene("hertz");
  last["output"] = {{"steps", "last"}};
  const SceneIssue issue =
      first_issue(json::parse(R"([{"name": "s", "kind": "field", "element": 0, "component": "sxx"}])"), last);
  EXPECT_EQ(issue.pointer, "/outputs/0/kind") << issue.detail;
}

}  // namespace
}  // namespace grip
