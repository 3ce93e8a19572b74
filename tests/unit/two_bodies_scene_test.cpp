// Scenes of several bodies (issue 19): the reader's errors name the JSON pointer of the value,
// the result of a two-body scene validates against schemas/result.schema.json and tells each
// body's rows, contact points carry their body and master, the CSV tables name the body and
// the VTK cells carry it.
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>

#include "solver/io/export_csv.hpp"
#include "solver/io/export_vtk.hpp"
#include "solver/io/result.hpp"
#include "solver/io/schema_validation.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

// The pointers of the issues read_scene reports for `scene`.
std::vector<std::string> error_pointers(const json& scene) {
  try {
    read_scene(scene);
  } catch (const SceneErrors& e) {
    std::vector<std::string> pointers;
    for (const SceneIssue& i : e.issues()) pointers.push_back(i.pointer + ": " + i.detail);
    return pointers;
  }
  return {};
}

bool has_error(const json& scene, const std::string& pointer) {
  for (const std::string& e : error_pointers(scene))
    if (e.rfind(pointer + ": ", 0) == 0) return true;
  return false;
}

TEST(TwoBodiesScene, ErrorsNameThePointerOfTheValue) {
  const json ok = example_scene("two-cylinders");
  EXPECT_TRUE(error_pointers(ok).empty());
  json j = ok;
  j["contacts"][0]["master"] = "nobody.arc";
  EXPECT_TRUE(has_error(j, "/contacts/0/master"));
  j = ok;
  j["contacts"][0]["master"] = "lower.nothing";
  EXPECT_TRUE(has_error(j, "/contacts/0/master"));
  j = ok;
  j["contacts"][0]["slave"] = "upper";
  EXPECT_TRUE(has_error(j, "/contacts/0/slave"));
  j = ok;
  j["contacts"][0]["master"] = "upper.arc_refined";  // the slave's own body
  EXPECT_TRUE(has_error(j, "/contacts/0/master"));
  j = ok;
  j["bodies"][1]["name"] = "upper";
  EXPECT_TRUE(has_error(j, "/bodies/1/name"));
  j = ok;
  j["bodies"][1].erase("name");
  EXPECT_TRUE(has_error(j, "/bodies/1/name"));
  // Free motions that contact cannot stop are refused at the supports of the body they move: the
  // block free in x on a frictionless flat interface; both bodies free in y together.
  const json block = example_scene("block-on-foundation");
  j = block;
  j["bodies"][0]["supports"] = json::array({{{"set", "top"}, {"fix", {"y"}}}});
  EXPECT_TRUE(has_error(j, "/bodies/0/supports"));
  EXPECT_NE(error_pointers(j).front().find("leave the body free to translate along x"), std::string::npos)
      << error_pointers(j).front();
  j = block;
  j["bodies"][0]["supports"] = json::array({{{"set", "left"}, {"fix", {"x"}}}});
  j["bodies"][1]["supports"] = json::array({{{"set", "left"}, {"fix", {"x"}}}});
  EXPECT_TRUE(has_error(j, "/bodies/0/supports"));
  EXPECT_NE(error_pointers(j).front().find("leave the bodies free to move together (block: translate along y; "
                                           "foundation: translate along y)"),
            std::string::npos)
      << error_pointers(j).front();
  // Held by contact: the block free in y on the supported foundation.
  j = block;
  j["bodies"][0]["supports"] = json::array({{{"set", "left"}, {"fix", {"x"}}}});
  EXPECT_TRUE(error_pointers(j).empty());
  EXPECT_EQ(read_scene(j).problem.rigid.names, std::vector<std::string>{"block: translate along y"});
  j = ok;
  j["body"] = ok["bodies"][0];
  EXPECT_TRUE(has_error(j, "/body"));
  j = ok;
  j["contacts"][0]["friction"] = -1;
  EXPECT_TRUE(has_error(j, "/contacts/0/friction"));
}

TEST(TwoBodiesScene, ResultValidatesAndNamesTheBodies) {
  json scene = example_scene("two-cylinders");
  scene["steps"] = 1;
  Scene solved = read_scene(scene);
  const RunResult run = run_load_steps(solved.problem, solved.steps, solved.params);
  ASSERT_TRUE(run.completed) << run.reason;
  const json r = result_json(solved, run);
  const auto issues = validate_against(r, SchemaName::result);
  EXPECT_TRUE(issues.empty()) << (issues.empty() ? "" : issues.front().pointer + ": " + issues.front().detail);
  ASSERT_EQ(r["bodies"].size(), 2u);
  EXPECT_EQ(r["bodies"][1]["first_node"], r["bodies"][0]["nodes"]);
  const int nodes = r["bodies"][0]["nodes"].get<int>() + r["bodies"][1]["nodes"].get<int>();
  EXPECT_EQ(r["steps"][0]["nodes"].size(), static_cast<size_t>(nodes));
  for (const json& p : r["steps"][0]["contact_points"]) {
    EXPECT_EQ(p["body"], "upper");
    EXPECT_EQ(p["master"], "lower");
  }
  EXPECT_EQ(r["effects"]["contacts"][0]["contact_candidates"], r["effects"]["contact_candidates"]);
  // The pressure read on the master: the slave's stresses interpolated along the slave surface,
  // so each lies between the slave's extremes (a convex combination of two slave nodes').
  double slave_min = 0.0, master_min = 0.0;
  for (const json& p : r["steps"][0]["contact_points"]) slave_min = std::min(slave_min, p["sigma_n"].get<double>());
  const json& readings = r["steps"][0]["master_points"];
  ASSERT_FALSE(readings.empty());
  const int lower_first = r["bodies"][1]["first_node"];
  for (const json& m : readings) {
    EXPECT_EQ(m["body"], "lower");
    EXPECT_GE(m["node"].get<int>(), lower_first);
    EXPECT_GE(m["sigma_n"].get<double>(), slave_min);
    EXPECT_LE(m["sigma_n"].get<double>(), 0.0);
    master_min = std::min(master_min, m["sigma_n"].get<double>());
  }
  EXPECT_LT(master_min, 0.5 * slave_min);  // the contact zone is read from the master too
  const std::string csv = result_csv(r, "nodes");
  EXPECT_EQ(csv.substr(0, csv.find('\n')).find("step,load_factor,body,node"), 0u) << csv.substr(0, 80);
  EXPECT_NE(csv.find(",lower,"), std::string::npos);
  // VTK: one piece per body, each with its body's points (the rows of its nodes), its cells
  // numbered within the piece, and the cell array `body`.
  const std::string vtu = step_vtu(r, 0);
  EXPECT_NE(vtu.find("Name=\"body\""), std::string::npos);
  // The text between `open` (from `from` on) and the next `close`; `from` moves past it.
  auto between = [&](size_t& from, const std::string& open, const std::string& close) {
    const size_t a = vtu.find(open, from);
    if (a == std::string::npos) return std::string();
    const size_t b = vtu.find(close, a + open.size());
    from = b + close.size();
    return vtu.substr(a + open.size(), b - a - open.size());
  };
  auto numbers = [](const std::string& text) {
    std::istringstream in(text);
    std::vector<double> v;
    for (double x; in >> x;) v.push_back(x);
    return v;
  };
  size_t at = 0;
  for (size_t b = 0; b < 2; ++b) {
    SCOPED_TRACE("body " + std::to_string(b));
    const json& body = r["bodies"][b];
    const int first = body["first_node"], count = body["nodes"], cells = body["elements"];
    const std::string piece = between(at, "<Piece ", ">");
    EXPECT_EQ(piece,
              "NumberOfPoints=\"" + std::to_string(count) + "\" NumberOfCells=\"" + std::to_string(cells) + "\"");
    const std::vector<double> body_index = numbers(between(at, "Name=\"body\" format=\"ascii\">", "</DataArray>"));
    ASSERT_EQ(body_index.size(), static_cast<size_t>(cells));
    for (double v : body_index) EXPECT_EQ(v, static_cast<double>(b));
    const std::vector<double> xyz = numbers(between(at, "NumberOfComponents=\"3\" format=\"ascii\">", "</DataArray>"));
    ASSERT_EQ(xyz.size(), 3u * count);
    for (int n = 0; n < count; ++n) {
      EXPECT_EQ(xyz[3 * n], r["steps"][0]["nodes"][first + n]["x"].get<double>());
      EXPECT_EQ(xyz[3 * n + 1], r["steps"][0]["nodes"][first + n]["y"].get<double>());
    }
    const std::vector<double> connectivity =
        numbers(between(at, "Name=\"connectivity\" format=\"ascii\">", "</DataArray>"));
    ASSERT_FALSE(connectivity.empty());
    EXPECT_EQ(*std::min_element(connectivity.begin(), connectivity.end()), 0.0);
    EXPECT_EQ(*std::max_element(connectivity.begin(), connectivity.end()), count - 1.0);
    const int first_cell = body["first_element"];
    EXPECT_EQ(connectivity[0], r["mesh"]["cells"][first_cell][0].get<double>() - first);
  }
  EXPECT_EQ(vtu.find("<Piece ", at), std::string::npos);  // two pieces, no more
}

// A pair whose surfaces lie beyond the contact reach (the set's length by default) has no
// unknowns; an obstacle named by a contact pairs with that slave set only, one named by none
// with every body.
TEST(TwoBodiesScene, OnlyPairsThatCanMeetHaveUnknowns) {
  json far = example_scene("two-cylinders");
  far["bodies"][1]["mesh"]["half_disc"]["centre"] = {0, -40};
  EXPECT_EQ(read_scene(far).problem.component_count, 0);
  const int pair = read_scene(example_scene("two-cylinders")).problem.component_count;
  EXPECT_GT(pair, 0);
  json wall = example_scene("block-on-foundation");
  wall["obstacles"] =
      json::parse(R"([{"name": "wall", "shape": {"type": "segment", "from": [6, 10], "to": [6, -10]}}])");
  const Scene everyone = read_scene(wall);
  wall["contacts"].push_back({{"slave", "block.bottom"}, {"master", "wall"}});
  const Scene named = read_scene(wall);
  auto on_wall = [](const Scene& s) {
    int n = 0;
    for (const Candidate& c : s.problem.candidates) n += s.problem.obstacles[c.obstacle].name == "wall";
    return n;
  };
  const int block = 8, foundation = 21;  // contact set nodes
  EXPECT_EQ(on_wall(everyone), block + foundation);
  EXPECT_EQ(on_wall(named), block);
}

}  // namespace
}  // namespace grip
