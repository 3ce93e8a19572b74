// Reading scenes: every error with the JSON pointer of its value, all of them collected;
// defaults filled in; only the effects a scene calls for are built.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "apps/result_writer.hpp"
#include "solver/io/json_writer.hpp"
#include "solver/io/result.hpp"
#include "solver/io/schema_validation.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using testing::example_scene;

std::vector<SceneIssue> issues_of(const json& scene) {
  try {
    read_scene(scene);
  } catch (const SceneErrors& e) {
    return e.issues();
  }
  return {};
}

bool has(const std::vector<SceneIssue>& issues, const std::string& pointer, const std::string& words = "") {
  for (const auto& i : issues)
    if (i.pointer == pointer && i.detail.find(words) != std::string::npos) return true;
  return false;
}

TEST(SceneReader, CollectsEveryErrorWithItsPointer) {
  json j = example_scene("beam-on-cylinder");
  j["body"]["material"]["poisson"] = 0.62;
  j["body"]["section"]["depth"] = -2;
  j["obstacles"][0]["shape"]["radius"] = "fifty";
  j["obstacles"][0]["friction"] = -0.1;
  j["steps"] = 0;
  const auto issues = issues_of(j);
  EXPECT_TRUE(has(issues, "/body/material/poisson", "0.62"));
  EXPECT_TRUE(has(issues, "/body/section/depth", "not positive"));
  EXPECT_TRUE(has(issues, "/obstacles/0/shape/radius", "not a number"));
  EXPECT_TRUE(has(issues, "/obstacles/0/friction", "negative"));
  EXPECT_TRUE(has(issues, "/steps"));
  EXPECT_GE(issues.size(), 5u);
}

TEST(SceneReader, NamesTheRigidMotionThatSupportsLeaveFree) {
  // The von Karman beam turning about its one supported node: the cylinder holds it, about the
  // model's own finite rotation at its state (rigid_modes_at).
  json pinned = example_scene("beam-on-cylinder");
  pinned["body"]["supports"] = json::array({{{"node", 0}, {"fix", {"u", "w"}}}});
  EXPECT_TRUE(issues_of(pinned).empty());
  EXPECT_EQ(read_scene(pinned).problem.rigid.names, std::vector<std::string>{"rotate about (0, 0)"});

  // A free slide along x: the cylinder holds it (its surface turns across x); a frictionless
  // flat does not.
  json sliding = example_scene("beam-on-cylinder");
  sliding["body"]["supports"] = json::array({{{"node", 0}, {"fix", {"w", "theta"}}}});
  EXPECT_EQ(read_scene(sliding).problem.rigid.names, std::vector<std::string>{"translate along x"});
  sliding["obstacles"][0]["shape"] = {{"type", "segment"}, {"from", {200, -1}}, {"to", {-200, -1}}};
  sliding["obstacles"][0]["friction"] = 0;
  EXPECT_TRUE(has(issues_of(sliding), "/body/supports", "translate along x, and no obstacle within reach can stop"));

  // u held at two nodes leaves the von Karman beam free to turn to first order only: its finite
  // rotation moves u by -c w - c^2 x / 2, which no c != 0 keeps zero at both.
  json loose = example_scene("beam-on-cylinder");
  loose["body"]["supports"] = json::array({{{"node", 0}, {"fix", {"u"}}}, {{"node", 1}, {"fix", {"u"}}}});
  const auto l = issues_of(loose);
  ASSERT_EQ(l.size(), 1u);
  EXPECT_TRUE(has(l, "/body/supports", "with finite kinematics a rotation is free only about a single supported node"));

  json sheet = example_scene("sheet-stretching");  // pole x and clamp x, y hold the sheet
  EXPECT_TRUE(issues_of(sheet).empty());
}

// A beam's distributed load: a traction along the axis, not at a node; its span inside the
// beam; a follower only on the geometrically exact beam.
TEST(SceneReader, BeamTractionsNameTheirField) {
  json j = example_scene("beam-on-cylinder");
  const double length = j["body"]["mesh"]["length"];
  j["body"]["loads"] = json::array({{{"traction", {0, -1}}, {"node", 3}},
                                    {{"traction", {0, -1}}, {"from", length}},
                                    {{"traction", {0, -1}}, {"follower", true}},
                                    {{"moment", 1.0}},
                                    {{"node", 2}, {"to", 3.0}}});
  const auto issues = issues_of(j);
  EXPECT_TRUE(has(issues, "/body/loads/0/node", "not at a node"));
  EXPECT_TRUE(has(issues, "/body/loads/3", "needs \"node\""));
  EXPECT_TRUE(has(issues, "/body/loads/4/to", "belongs to a traction"));
  j["body"]["loads"].erase(4);
  j["body"]["loads"].erase(3);
  j["body"]["loads"].erase(0);
  const auto read = issues_of(j);
  EXPECT_TRUE(has(read, "/body/loads/0/from", "is not in"));
  EXPECT_TRUE(has(read, "/body/loads/1/follower", "only a reissner_beam"));
  j["body"]["model"] = "reissner_beam";
  j["body"].erase("kinematics");
  j["body"]["loads"].erase(0);
  EXPECT_TRUE(issues_of(j).empty());
}

TEST(SceneReader, MembraneNeedsAStart) {
  json j = example_scene("sheet-stretching");
  j["solver"].erase("start");
  EXPECT_TRUE(has(issues_of(j), "/solver/start", "no transverse stiffness"));
  j = example_scene("sheet-stretching");
  j["solver"]["start"]["obstacle"] = "anvil";
  EXPECT_TRUE(has(issues_of(j), "/solver/start/obstacle", "anvil"));
}

TEST(SceneReader, StagesNameKnownCasesAndObstacles) {
  json j = example_scene("beam-on-cylinder");
  j.erase("steps");
  j["stages"] = json::array({{{"steps", 2}, {"factors", {{"main", 1}}}, {"friction", {{"cylinder", 0}}}},
                             {{"steps", 3}, {"factors", {{"shear", 1}}}, {"friction", {{"anvil", 0.1}}}}});
  const auto issues = issues_of(j);
  EXPECT_TRUE(has(issues, "/stages/1/factors/shear", "names no load case"));
  EXPECT_TRUE(has(issues, "/stages/1/friction/anvil", "names no obstacle"));
}

// A body the reader stops at (a bad mesh, a negative thickness) must not drag a "names no
// load case" error with it for the cases its unread supports would have named (issue 34).
TEST(SceneReader, ABadBodyDoesNotMakeItsStagesNameUnknownCases) {
  for (const auto& [pointer, value] :
       std::vector<std::pair<std::string, json>>{{"/body/mesh/rectangle/divisions", json::array({0, 10})},
                                                 {"/body/mesh/rectangle/divisions", json::array({2.5, 10})},
                                                 {"/body/thickness", -1}}) {
    json j = example_scene("sliding-block");
    j[json::json_pointer(pointer)] = value;
    const auto issues = issues_of(j);
    ASSERT_FALSE(issues.empty()) << pointer;
    for (const auto& issue : issues) {
      EXPECT_EQ(issue.pointer.rfind("/body", 0), 0u)
          << pointer << " = " << value.dump() << " also gave " << issue.pointer << ": " << issue.detail;
    }
  }
}

TEST(SceneReader, StagesRampTheirCasesFromWherePreviousStagesLeftThem) {
  json j = example_scene("beam-on-cylinder");
  j.erase("steps");
  j["stages"] = json::array({{{"steps", 2}, {"factors", {{"main", 1}}}},
                             {{"steps", 4}, {"factors", {{"main", 0}}}, {"friction", {{"cylinder", 0.5}}}}});
  const Scene s = read_scene(j);
  ASSERT_EQ(s.steps.size(), 6u);
  const std::vector<double> expected = {0.5, 1.0, 0.75, 0.5, 0.25, 0.0};
  for (size_t k = 0; k < 6; ++k) {
    EXPECT_DOUBLE_EQ(s.steps[k].factors[0], expected[k]);
    EXPECT_DOUBLE_EQ(s.steps[k].friction[0], k < 2 ? 0.2 : 0.5);
  }
}

TEST(SceneReader, FillsDefaultsIntoTheEffectiveScene) {
  json j = example_scene("beam-on-cylinder");
  j.erase("solver");
  const Scene s = read_scene(j);
  EXPECT_EQ(s.effective["solver"]["contact"]["method"], "cev");
  EXPECT_EQ(s.effective["solver"]["contact"]["tolerance"], 1e-8);
  EXPECT_EQ(s.effective["body"]["section"]["shear_factor"], 5.0 / 6.0);
  EXPECT_EQ(s.effective["obstacles"][0]["motion"], json::array());
  // The effective scene reads back to the same problem.
  const Scene again = read_scene(s.effective);
  EXPECT_EQ(again.effective, s.effective);
}

// Only the effects a scene calls for: no friction means no tangential unknowns and a single
// tau pass per step (with friction too by default: the bound moves with p_eta; several with
// friction_loop: passes); linear kinematics means one factorization of the stiffness.
TEST(SceneEffects, FrictionlessHasHalfTheUnknownsAndNoTauPasses) {
  json frictionless = example_scene("beam-on-cylinder");
  frictionless["obstacles"][0]["friction"] = 0;
  json passes = example_scene("beam-on-cylinder");
  passes["solver"]["contact"]["friction_loop"] = "passes";
  const auto a = testing::solve_scene(example_scene("beam-on-cylinder"));
  const auto b = testing::solve_scene(frictionless);
  const auto c = testing::solve_scene(passes);
  const json ea = effects_json(a.scene, a.run), eb = effects_json(b.scene, b.run);
  EXPECT_EQ(ea["unknowns_per_contact_point"], 2);
  EXPECT_EQ(eb["unknowns_per_contact_point"], 1);
  EXPECT_EQ(2 * eb["contact_unknowns"].get<int>(), ea["contact_unknowns"].get<int>());
  EXPECT_EQ(eb["counters"]["tau_passes"], 20);  // one per step
  EXPECT_EQ(ea["counters"]["tau_passes"], 20);
  EXPECT_GT(effects_json(c.scene, c.run)["counters"]["tau_passes"].get<int>(), 20);
  EXPECT_TRUE(ea["friction"]);
  EXPECT_FALSE(eb["friction"]);
  EXPECT_TRUE(ea["geometric_nonlinearity"]);
}

// The effects block reports the shape of a continuum's elements: right angles throughout
// the sliding block's rectangle; the half-disc's single mapped block puts two of its corners
// on the smooth arc, where the corner elements are strongly skewed (reported, not hidden).
TEST(SceneEffects, ContinuumReportsItsElementQuality) {
  const Scene block = read_scene(example_scene("sliding-block"));
  const json b = effects_json(block, RunResult{})["element_quality"];
  EXPECT_EQ(b["elements"], block.problem.body->cells().size());
  EXPECT_NEAR(b["min_angle"].get<double>(), 90.0, 1e-9);
  EXPECT_NEAR(b["max_angle"].get<double>(), 90.0, 1e-9);
  const json h = effects_json(read_scene(example_scene("hertz")), RunResult{})["element_quality"];
  EXPECT_GT(h["min_angle"].get<double>(), 0.0);
  EXPECT_LT(h["min_angle"].get<double>(), 90.0);
  EXPECT_GT(h["max_angle"].get<double>(), 90.0);
  EXPECT_LT(h["max_angle"].get<double>(), 180.0);
  EXPECT_GT(h["max_aspect_ratio"].get<double>(), 1.0);
  EXPECT_FALSE(effects_json(read_scene(example_scene("beam-on-cylinder")), RunResult{}).contains("element_quality"));
}

TEST(SceneEffects, LinearKinematicsFactorizesOnce) {
  json j = example_scene("beam-on-cylinder");
  j["body"]["kinematics"] = "linear";
  const auto s = testing::solve_scene(j);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const json e = effects_json(s.scene, s.run);
  EXPECT_FALSE(e["geometric_nonlinearity"]);
  EXPECT_TRUE(e["constant_tangent"]);
  EXPECT_EQ(e["counters"]["factorizations"], 1);
  EXPECT_GT(e["counters"]["equilibrium_solves"].get<int>(), 20);
}

}  // namespace
}  // namespace grip

namespace grip {
namespace {

TEST(SceneEffects, AnObstacleThatCannotReachTheBodyHasNoCandidates) {
  json j = testing::example_scene("beam-on-cylinder");
  j["obstacles"].push_back({{"name", "far"}, {"shape", {{"type", "circle"}, {"centre", {0, 500}}, {"radius", 1}}}});
  j["obstacles"].push_back({{"name", "arriving"},
                            {"shape", {{"type", "circle"}, {"centre", {15, 500}}, {"radius", 1}}},
                            {"motion", {{"translation", {0, -495}}}}});
  const Scene s = read_scene(j);
  int far = 0, arriving = 0;
  for (const Candidate& c : s.problem.candidates) {
    far += s.problem.obstacles[c.obstacle].name == "far";
    arriving += s.problem.obstacles[c.obstacle].name == "arriving";
  }
  EXPECT_EQ(far, 0);
  EXPECT_EQ(arriving, 41);  // it comes down onto the beam over the steps
}

TEST(SceneEffects, OutputsNotRequestedAreNotComputedOrStored) {
  json j = testing::example_scene("beam-on-cylinder");
  j["steps"] = 4;
  j["output"] = {{"steps", "last"}, {"fields", {"contact_points"}}};
  const auto s = testing::solve_scene(j);
  ASSERT_TRUE(s.run.completed);
  const json r = result_json(s.scene, s.run);
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(s.run.steps[k].site_fields.rows.empty(), k < 3);  // computed for the last step only
    EXPECT_FALSE(r["steps"][k].contains("nodes"));
    EXPECT_FALSE(r["steps"][k].contains("history"));
    EXPECT_EQ(r["steps"][k].contains("contact_points"), k == 3);
  }
}

// grip solve writes the result as it makes it (write_result); it must read back as the
// document result_json builds: the same members, the same numbers to the bit.
TEST(SceneEffects, StreamedResultReadsBackAsTheBuiltOne) {
  json j = testing::example_scene("hertz");
  j["steps"] = 2;
  j["output"] = {{"steps", "all"}};
  const auto s = testing::solve_scene(j);
  ASSERT_TRUE(s.run.completed);
  std::ostringstream streamed;
  write_result(streamed, s.scene, s.run);
  const json built = result_json(s.scene, s.run);
  ASSERT_FALSE(built["steps"][1]["elements"].empty());
  const json read = json::parse(streamed.str());
  EXPECT_EQ(read, built);
  // Every table number is the solver's double in kFieldDigits (7) significant digits: the
  // writer's shortest round trip of it, within half a unit of the 7th digit of the double.
  for (size_t k = 0; k < s.run.steps.size(); ++k)
    for (const auto& [key, table] :
         {std::pair{"nodes", &s.run.steps[k].site_fields}, std::pair{"elements", &s.run.steps[k].element_fields}}) {
      ASSERT_EQ(read["steps"][k][key].size(), table->rows.size());
      for (size_t i = 0; i < table->rows.size(); ++i)
        for (size_t c = 0; c < table->names.size(); ++c)
          if (table->names[c] != "node" && table->names[c] != "element") {
            const double v = table->rows[i][c];
            const json& written = read["steps"][k][key][i][table->names[c]];
            ASSERT_EQ(written.get<double>(), field_value(v)) << key << " row " << i << " " << table->names[c];
            ASSERT_LE(std::abs(written.get<double>() - v), 5e-7 * std::abs(v)) << key << " row " << i;
            char text[kMaxNumberChars];
            std::string digits(text, write_number(text, written.get<double>()));  // as the result has it
            digits = digits.substr(0, digits.find_first_of("eE"));                // the mantissa
            digits.erase(std::remove_if(digits.begin(), digits.end(), [](char ch) { return !std::isdigit(ch); }),
                         digits.end());
            digits.erase(0, digits.find_first_not_of('0'));
            ASSERT_LE(digits.find_last_not_of('0') + 1, 7u) << written.dump();  // significant digits
          }
    }
}

// A step's text in parts (step_parts): long tables are cut every kRowsPerPart rows so that two
// threads can share a step; written each by its own writer, in any order, the parts join into
// the step's JSON: every row once with its index, NaN cells left out as table_json does, the
// small members before and after the tables in nlohmann's key order.
TEST(SceneEffects, StepPartsJoinIntoTheStepWhateverWritesThem) {
  StepOutput step;
  step.summary = {{"converged", true}, {"step", 3}, {"zz_after_the_tables", "last"}};
  json expected = step.summary;
  auto table = [](size_t rows, const char* index, std::vector<std::string> names, json& rows_json) {
    FlatTable t{names, rows, {}};
    rows_json = json::array();
    for (size_t i = 0; i < rows; ++i) {
      json row = {{index, i}};
      for (size_t c = 0; c < names.size(); ++c) {
        const double v = (c == 1 && i % 7 == 0) ? std::nan("") : std::sin(0.37 * i + c) * 1e3;
        t.values.push_back(v);
        if (!std::isnan(v)) row[names[c]] = v;
      }
      rows_json.push_back(row);
    }
    return t;
  };
  step.nodes = table(2 * kRowsPerPart + 1, "node", {"ux", "uy", "x", "y"}, expected["nodes"]);
  step.elements = table(kRowsPerPart, "element", {"sxx", "sxy"}, expected["elements"]);
  step.contact_points.emplace();
  expected["contact_points"] = json::array();
  const std::vector<ResultPart> parts = step_parts(step);
  // One part before each table (the small members and its key) and one after the last; the
  // node table in 3 parts, the element table (exactly kRowsPerPart rows) and the contact points in 1.
  ASSERT_EQ(parts.size(), 3u + 1 + 3 + 1 + 1);
  std::vector<std::string> texts(parts.size());
  for (size_t i = parts.size(); i-- > 0;) {
    std::ostringstream out;
    {
      JsonWriter w(out);
      parts[i](w);
    }
    texts[i] = out.str();
  }
  std::string joined;
  for (const std::string& t : texts) joined += t;
  EXPECT_EQ(json::parse(joined), expected);
  std::ostringstream whole;
  write_step(whole, step);
  EXPECT_TRUE(joined == whole.str());
}

std::string file_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// grip solve writes its result while it solves (apps/result_writer.hpp: the head before the
// solve, each step as the solver's observer hands it over, the tail after); the file must be
// write_result's to the byte: a single body with every field, two bodies (master points,
// several tables), and a run that fails at step 7 (block_under_shear), whose file must still be
// a whole result with the six steps solved before, the failed one and the reason.
TEST(SceneEffects, StepsWrittenWhileSolvingAreTheStreamedResultByteForByte) {
  json hertz = testing::example_scene("hertz");
  hertz["steps"] = 3;
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("grip_scene_test_" + std::to_string(getpid()) + ".json");
  for (const json& j : {hertz, testing::example_scene("two-cylinders"), testing::block_under_shear()}) {
    Scene scene = read_scene(j);
    RunResult run;
    {
      ResultWriter writer(path.string(), scene);
      SteppingObserver observer;
      observer.step_finished = [&](const StepRecord& rec) { writer.add_step(rec); };
      run = run_load_steps(scene.problem, scene.steps, scene.params, observer);
      ASSERT_TRUE(writer.finish(run));
    }
    std::ostringstream streamed;
    write_result(streamed, scene, run);
    const std::string written = file_text(path);
    ASSERT_GT(written.size(), 10000u);
    EXPECT_TRUE(written == streamed.str()) << j["description"];
    // Known before the solve first, the steps, then what the run decides.
    std::vector<size_t> at;
    for (const char* key : {"\"mesh\":{", "\"scene\":{", "\"steps\":[", "],\"effects\":{", "},\"summary\":{"})
      at.push_back(written.find(key));
    EXPECT_TRUE(std::is_sorted(at.begin(), at.end()) && at.back() != std::string::npos) << written.substr(0, 200);
    const json r = json::parse(written);
    EXPECT_EQ(r, result_json(scene, run));
    ASSERT_EQ(r["steps"].size(), run.steps.size());
    EXPECT_EQ(r["summary"]["completed"], run.completed);
    if (run.completed) continue;
    ASSERT_EQ(run.steps.size(), 7u);
    for (int k = 0; k < 6; ++k) EXPECT_TRUE(r["steps"][k]["converged"].get<bool>()) << k;
    EXPECT_FALSE(r["steps"][6]["converged"].get<bool>());
    const std::string reason = r["summary"]["reason"];
    EXPECT_NE(reason.find("step 7 failed: the shear load exceeds what friction can hold"), std::string::npos) << reason;
  }
  std::filesystem::remove(path);
}

// An exception during a step (here from the observer, as the service's event store throws when
// its database is gone; the solver's own would be out of memory) fails that step with the
// exception's text and keeps the steps before: the written result is whole, its step 1 the
// same as an undisturbed run's, and nothing escapes to end grip solve.
TEST(SceneEffects, AnExceptionDuringAStepFailsThatStepAndKeepsTheStepsBefore) {
  json hertz = testing::example_scene("hertz");
  hertz["steps"] = 3;
  Scene undisturbed = read_scene(hertz);
  const RunResult whole = run_load_steps(undisturbed.problem, undisturbed.steps, undisturbed.params);
  ASSERT_TRUE(whole.completed);

  Scene scene = read_scene(hertz);
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("grip_scene_throw_" + std::to_string(getpid()) + ".json");
  RunResult run;
  {
    ResultWriter writer(path.string(), scene);
    SteppingObserver observer;
    observer.step_started = [](int step, double) {
      if (step == 2) throw std::runtime_error("the event store is unavailable");
    };
    observer.step_finished = [&](const StepRecord& rec) { writer.add_step(rec); };
    run = run_load_steps(scene.problem, scene.steps, scene.params, observer);
    ASSERT_TRUE(writer.finish(run));
  }
  EXPECT_FALSE(run.completed);
  EXPECT_EQ(run.reason, "step 2 failed: solver error: the event store is unavailable");
  ASSERT_EQ(run.steps.size(), 2u);
  EXPECT_TRUE(run.steps[0].converged);
  EXPECT_FALSE(run.steps[1].converged);
  EXPECT_EQ(run.steps[1].load_factor, undisturbed.steps[1].factors.front());
  EXPECT_EQ(run.steps[0].p, whole.steps[0].p);
  const json r = json::parse(file_text(path));
  EXPECT_EQ(r, result_json(scene, run));
  EXPECT_EQ(r["steps"].size(), 2u);
  EXPECT_EQ(r["summary"]["completed"], false);
  // Its kind, for a program (failure_kinds_test.cpp produces the others).
  EXPECT_EQ(run.failure, FailureKind::exception);
  EXPECT_EQ(run.failure_step, 2);
  EXPECT_EQ(r["summary"]["failure"], json({{"kind", "exception"}, {"message", run.reason}, {"step", 2}}));
  EXPECT_EQ(r["steps"][1]["failure"]["kind"], "exception");
  const auto issues = validate_against(r, SchemaName::result);
  EXPECT_TRUE(issues.empty()) << issues.front().pointer << ": " << issues.front().detail;
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace grip
