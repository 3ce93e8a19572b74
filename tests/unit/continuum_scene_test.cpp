// The scene reader of body.model "continuum": defaults written into the effective scene,
// meshes given or generated, node sets in supports and loads, and every error at the JSON
// pointer of its value.
#include <gtest/gtest.h>

#include "solver/elements/continuum.hpp"
#include "solver/io/scene.hpp"

namespace grip {
namespace {

using nlohmann::json;

// A 4 x 1 block on a flat, pressed by its top.
json block() {
  return json::parse(R"({
    "body": {
      "model": "continuum",
      "material": {"young": 1000},
      "mesh": {"rectangle": {"size": [4, 1], "divisions": [4, 2]}},
      "supports": [{"set": "top", "fix": ["x", "y"], "values": {"y": -0.01}}]
    },
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [10, 0], "to": [-10, 0]}}]
  })");
}

// The issues of a scene that must not read.
std::vector<SceneIssue> issues_of(const json& scene) {
  try {
    read_scene(scene);
  } catch (const SceneErrors& e) {
    return e.issues();
  }
  ADD_FAILURE() << "the scene was read";
  return {};
}

::testing::AssertionResult has_issue(const std::vector<SceneIssue>& issues, const std::string& pointer,
                                     const std::string& part) {
  std::string all;
  for (const auto& i : issues) {
    if (i.pointer == pointer && i.detail.find(part) != std::string::npos) return ::testing::AssertionSuccess();
    all += "\n  " + i.pointer + ": " + i.detail;
  }
  return ::testing::AssertionFailure() << "no issue at " << pointer << " with \"" << part << "\" among:" << all;
}

TEST(ContinuumScene, DefaultsAreFilledIn) {
  const Scene s = read_scene(block());
  const json& b = s.effective["body"];
  EXPECT_EQ(b["kinematics"], "finite");
  EXPECT_EQ(b["analysis"], "plane_strain");
  EXPECT_EQ(b["element"], "q4");
  EXPECT_EQ(b["thickness"], 1.0);
  EXPECT_EQ(b["material"]["poisson"], 0.3);
  EXPECT_EQ(b["material"]["law"], "neo_hookean");
  EXPECT_EQ(b["contact_set"], "bottom");
  EXPECT_EQ(b["mesh"]["rectangle"]["origin"], json::array({0.0, 0.0}));
  // Sites are the bottom nodes, left to right; each maps to its node.
  const Body& body = *s.problem.body;
  ASSERT_EQ(body.site_count(), 5);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(body.site_node(k), k);
    EXPECT_DOUBLE_EQ(body.site_reference(k).x(), k);
    EXPECT_DOUBLE_EQ(body.tributary_area(k), k == 0 || k == 4 ? 0.5 : 1.0);
  }
  EXPECT_EQ(body.site_fields(Vector::Zero(body.dof_count())).rows.size(), 15u);  // every node
  EXPECT_EQ(body.cells().size(), 8u);
  EXPECT_EQ(s.problem.candidates.size(), 5u);
  EXPECT_EQ(s.problem.constraints.size(), 10u);  // x and y of the five top nodes
}

TEST(ContinuumScene, HalfDiscSitesFollowTheArc) {
  json j = block();
  j["body"]["mesh"] = {{"half_disc", {{"radius", 1}, {"centre", {0, 1}}, {"divisions", {4, 2}}}}};
  j["body"]["supports"][0]["set"] = "diameter";
  const Scene s = read_scene(j);
  EXPECT_EQ(s.effective["body"]["contact_set"], "arc");
  EXPECT_EQ(s.effective["body"]["mesh"]["half_disc"]["facing"], "down");
  const Body& body = *s.problem.body;
  ASSERT_EQ(body.site_count(), 5);  // 4 arc divisions
  for (int k = 1; k < body.site_count(); ++k) EXPECT_GT(body.site_reference(k).x(), body.site_reference(k - 1).x());
  EXPECT_NEAR(body.site_reference(2).y(), 0.0, 1e-12);  // the pole
}

TEST(ContinuumScene, ExplicitMeshSetsAndTraction) {
  json j = block();
  j["body"]["mesh"] = json::parse(R"({"nodes": [[0, 0], [2, 0], [2, 1], [0, 1], [4, 0], [4, 1]],
      "elements": [[0, 1, 2, 3], [1, 4, 5, 2]], "sets": {"base": [4, 0, 1], "lid": [3, 2, 5]}})");
  j["body"]["contact_set"] = "base";
  j["body"]["thickness"] = 2.0;
  j["body"]["supports"] =
      json::parse(R"([{"set": "lid", "fix": ["y"], "values": {"y": -0.01}}, {"node": 3, "fix": ["x"]}])");
  j["body"]["loads"] =
      json::parse(R"([{"set": "lid", "traction": [0.5, 0]}, {"node": 5, "force": [0, -1], "case": "extra"}])");
  const Scene s = read_scene(j);
  const Body& body = *s.problem.body;
  ASSERT_EQ(body.site_count(), 3);
  EXPECT_EQ(body.site_node(0), 0);  // in order along the boundary, whatever the set's order
  EXPECT_EQ(body.site_node(1), 1);
  EXPECT_EQ(body.site_node(2), 4);
  EXPECT_DOUBLE_EQ(body.tributary_area(1), 2.0 * 2.0);
  // The traction over the lid (length 4, thickness 2): 0.5 x 8 = 4 along x in total.
  const Vector& main = s.problem.loads[0];
  EXPECT_NEAR(body.rigid_translation(Vec2::UnitX()).dot(main), 4.0, 1e-12);
  EXPECT_NEAR(main[2 * 2], 2.0, 1e-12);  // the middle lid node carries half
  ASSERT_EQ(s.load_cases.size(), 2u);
  EXPECT_EQ(s.problem.loads[1][2 * 5 + 1], -1.0);
}

TEST(ContinuumScene, MeshErrorsNameTheElementOrNode) {
  json j = block();
  j["body"]["mesh"] = json::parse(R"({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1], [9, 9]],
      "elements": [[0, 1, 2, 3], [1, 5, 4, 2], [1, 4, 7, 2]], "sets": {"base": [0, 1, 4]}})");
  j["body"]["contact_set"] = "base";
  const auto issues = issues_of(j);
  EXPECT_TRUE(has_issue(issues, "/body/mesh/elements/1", "element 1 is inverted"));
  EXPECT_TRUE(has_issue(issues, "/body/mesh/elements/2", "names node 7, which does not exist"));
  EXPECT_TRUE(has_issue(issues, "/body/mesh/nodes/6", "belongs to no element"));
}

TEST(ContinuumScene, ExplicitMeshNeedsAContactSet) {
  json j = block();
  j["body"]["mesh"] = json::parse(R"({"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "elements": [[0, 1, 2, 3]],
      "sets": {"top": [2, 3], "diagonal": [0, 2]}})");
  EXPECT_TRUE(has_issue(issues_of(j), "/body/contact_set", "is required"));
  j["body"]["contact_set"] = "diagonal";
  EXPECT_TRUE(has_issue(issues_of(j), "/body/contact_set", "lies on no boundary side"));
  j["body"]["contact_set"] = "bottom";
  EXPECT_TRUE(has_issue(issues_of(j), "/body/contact_set", "names no node set (sets: \"diagonal\", \"top\")"));
}

TEST(ContinuumScene, FreeMotionThatNoObstacleStopsIsRejected) {
  json j = block();
  // Held in y; the frictionless flat cannot stop a slide along x.
  j["body"]["supports"] = json::parse(R"([{"set": "top", "fix": ["y"], "values": {"y": -0.01}}])");
  EXPECT_TRUE(has_issue(issues_of(j), "/body/supports",
                        "leave the body free to translate along x, and no obstacle within reach can stop that motion"));
  // With friction the flat holds it: read, with the motion held by contact recorded.
  j["obstacles"][0]["friction"] = 0.3;
  Scene s = read_scene(j);
  EXPECT_EQ(s.problem.rigid.names, std::vector<std::string>{"translate along x"});
  ASSERT_EQ(s.problem.rigid.count(), 1);
  EXPECT_EQ(s.problem.component_count, 2 * 5 + 1);
  // The mode is 1 at its own pin, on a dof that no support and no contact point uses.
  EXPECT_DOUBLE_EQ(s.problem.rigid.modes(s.problem.rigid.pins[0], 0), 1.0);
  EXPECT_EQ(s.problem.rigid.pins[0] % 2, 0);
  EXPECT_GE(s.problem.rigid.pins[0] / 2, 5);
  // No supports, finite kinematics: the rotation is held too, about the block's current shape
  // (rigid_modes_at; a finite rotation leaves the continuum's strain unchanged).
  j["body"].erase("supports");
  EXPECT_EQ(read_scene(j).problem.rigid.count(), 3);
  // The top held in x: free to turn about a point of the top to first order only (a finite turn
  // moves the top in x), which finite kinematics cannot hold by contact.
  j["body"]["supports"] = json::parse(R"([{"set": "top", "fix": ["x"]}])");
  EXPECT_TRUE(has_issue(issues_of(j), "/body/supports",
                        "rotate about (0, 1): with finite kinematics a rotation is free only about a single supported "
                        "node"));
  // One node held: the rotation about it is free at any angle.
  j["body"]["supports"] = json::parse(R"([{"node": 0, "fix": ["x", "y"]}])");
  EXPECT_EQ(read_scene(j).problem.rigid.names, std::vector<std::string>{"rotate about (0, 0)"});
  j["body"].erase("supports");
  // Linear kinematics: all three motions are held (the flat resists the rotation, friction the slide).
  j["body"]["kinematics"] = "linear";
  s = read_scene(j);
  EXPECT_EQ(s.problem.rigid.count(), 3);
  // The flat out of reach: nothing stops the body falling.
  j["obstacles"][0]["shape"] = json::parse(R"({"type": "segment", "from": [10, -50], "to": [-10, -50]})");
  EXPECT_TRUE(has_issue(issues_of(j), "/body/supports", "leave the body free to translate along y, and no obstacle"));
}

TEST(ContinuumScene, SupportErrors) {
  // One faulty support per scene: a schema error elsewhere may hide the reader's own checks.
  auto with_support = [](const char* support) {
    json j = block();
    j["body"]["supports"].push_back(json::parse(support));
    return issues_of(j);
  };
  EXPECT_TRUE(
      has_issue(with_support(R"({"set": "lid", "fix": ["x"]})"), "/body/supports/1/set", "\"lid\" names no node set"));
  EXPECT_TRUE(has_issue(with_support(R"({"node": 14, "fix": ["y"], "values": {"y": 0.2}})"), "/body/supports/1/fix/0",
                        "prescribes y of node 14, which /body/supports/0 fixes already"));
  EXPECT_TRUE(has_issue(with_support(R"({"node": 14, "fix": ["z"]})"), "/body/supports/1/fix/0",
                        "\"z\" is not one of \"x\", \"y\""));
  EXPECT_TRUE(
      has_issue(with_support(R"({"node": 99, "fix": ["x"]})"), "/body/supports/1/node", "99 is outside [0, 14]"));
  // The same zero support twice (a corner in two sets) is accepted.
  json k = block();
  k["body"]["supports"].push_back(json::parse(R"({"set": "right", "fix": ["x"]})"));
  EXPECT_NO_THROW(read_scene(k));
}

TEST(ContinuumScene, ElementAndRefinementErrors) {
  json j = block();
  j["body"]["element"] = "q4_bbar";
  j["body"]["analysis"] = "plane_stress";
  j["body"]["kinematics"] = "linear";
  EXPECT_TRUE(has_issue(issues_of(j), "/body/element", "is for plane strain"));
  json k = block();
  k["body"]["mesh"]["rectangle"]["refine"] = {{"towards", {2, 1}}, {"size", 0.1}, {"extent", 0.5}};
  EXPECT_TRUE(has_issue(issues_of(k), "/body/mesh/rectangle/divisions", "cannot hold the refinement"));
  json l = block();
  l["body"]["loads"] = json::parse(R"([{"node": 3, "traction": [1, 0]}])");
  EXPECT_TRUE(has_issue(issues_of(l), "/body/loads/0/traction", "give \"set\", not \"node\""));
  l["body"]["loads"] = json::parse(R"([{"set": "top"}])");
  EXPECT_TRUE(has_issue(issues_of(l), "/body/loads/0", "needs exactly one of \"force\""));
}

}  // namespace
}  // namespace grip
