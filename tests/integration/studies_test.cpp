// Refinement studies (POST /v1/studies, server/studies.hpp) through the real binary: a 3-level
// study of Lame's thick cylinder (axisymmetric, q4, internal pressure: u_r closed form) runs
// as three jobs, and its table gives an observed order near q4's 2 and a Richardson value
// closer to the closed form than the finest level's; bad plans are refused before any job is
// stored, with the pointer of the field at fault; deleting the study dismisses its jobs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "grip_process.hpp"

namespace grip::testing {
namespace {

constexpr double kE = 1000.0, kNu = 0.3, kP = 10.0, kA = 1.0, kB = 2.0;

// u_r at r of the cylinder a <= r <= b under internal pressure p, u_z held (plane strain).
double lame(double r) {
  return kP * kA * kA / (kE * (kB * kB - kA * kA)) * (1 + kNu) * ((1 - 2 * kNu) * r + kB * kB / r);
}

// The cylinder's r-z section on a 2 x 1 grid of q4 (the study doubles it), pressure on the
// inner side, u_z held at both ends; u_r at the inner and outer radius as outputs.
json cylinder() {
  return json::parse(R"({
    "body": {
      "model": "continuum", "kinematics": "linear", "analysis": "axisymmetric", "element": "q4",
      "material": {"young": 1000, "poisson": 0.3, "law": "saint_venant_kirchhoff"},
      "mesh": {"rectangle": {"origin": [1, 0], "size": [1, 0.5], "divisions": [2, 1]}},
      "contact_set": "right",
      "supports": [{"set": "bottom", "fix": ["y"]}, {"set": "top", "fix": ["y"]}],
      "loads": [{"set": "left", "traction": [10, 0]}]
    },
    "obstacles": [{"name": "far", "shape": {"type": "segment", "from": [100, 50], "to": [200, 50]}}],
    "steps": 1,
    "solver": {"contact": {"reach": 0.01}},
    "outputs": [
      {"name": "u_inner", "kind": "displacement", "at": [1, 0], "component": "x"},
      {"name": "u_outer", "kind": "displacement", "at": [2, 0], "component": "x"}
    ]
  })");
}

json post_study(const Api& api, const json& request, int status) {
  const auto r = api.post_json("/v1/studies", request.dump());
  if (!r) throw std::runtime_error("no response");
  EXPECT_EQ(r->status, status) << r->body;
  return json::parse(r->body);
}

TEST(Studies, ThreeLevelsOfLamesCylinderGiveQ4sOrderAndABetterExtrapolation) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--workers", "2"}, dir.path() / "serve.log");
  const Api api(server.port());
  const json accepted = post_study(api, {{"scene", cylinder()}, {"refine", {{"levels", 3}}}}, 201);
  const std::string id = accepted["id"];
  ASSERT_EQ(accepted["levels"].size(), 3u);
  json study;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto r = api.get("/v1/studies/" + id);
    ASSERT_TRUE(r && r->status == 200);
    study = json::parse(r->body);
  } while (study["status"] != "successful" && std::chrono::steady_clock::now() < deadline);
  ASSERT_EQ(study["status"], "successful") << study.dump(2);
  // Each level is a job of its own; its table row holds the job's last step's outputs.
  for (int j = 0; j < 3; ++j) {
    const json& level = study["levels"][j];
    EXPECT_EQ(level["h"], std::ldexp(1.0, -j));
    const json job = api.job(level["job"]);
    EXPECT_EQ(job["status"], "successful");
    EXPECT_EQ(job["nodes"], (2 * (1 << j) + 1) * ((1 << j) + 1));
    const auto result = api.get("/v1/jobs/" + level["job"].get<std::string>() + "/result");
    ASSERT_TRUE(result && result->status == 200);
    EXPECT_EQ(json::parse(result->body)["steps"].back()["outputs"], level["outputs"]);
    EXPECT_GT(level["seconds"].get<double>(), 0.0);
  }
  // Bilinear elements on a smooth solution: the displacement's error goes as h^2 (its L2 norm,
  // and at the nodes of a uniformly refined grid), so the observed order should be near 2;
  // [1.5, 2.5] leaves room for the coarse grid's pre-asymptotic terms.
  for (const json& q : study["quantities"]) {
    const double r = q["name"] == "u_inner" ? kA : kB, exact = lame(r);
    const double finest = q["values"][2], extrapolated = q["extrapolated"], order = q["order"];
    std::printf(
        "%s: values %s; order %.3f; extrapolated %.8f; exact %.8f; error finest %.2e, extrapolated %.2e; "
        "estimated %.2e\n",
        q["name"].get<std::string>().c_str(), q["values"].dump().c_str(), order, extrapolated, exact,
        std::abs(finest / exact - 1), std::abs(extrapolated / exact - 1), q["estimated_error"][2].get<double>());
    EXPECT_GE(order, 1.5);
    EXPECT_LE(order, 2.5);
    EXPECT_LT(std::abs(extrapolated - exact), std::abs(finest - exact));
    EXPECT_TRUE(q["asymptotic"].is_null());  // three levels: one order, nothing to compare it with
    // The finest level's estimated error brackets its true error within a factor 2.
    const double estimated = q["estimated_error"][2], true_error = std::abs(finest / exact - 1);
    EXPECT_LT(estimated, 2 * true_error);
    EXPECT_GT(estimated, 0.5 * true_error);
    // The cheapest level under each threshold is one whose estimate is below it.
    for (const json& c : q["cheapest"])
      if (!c["level"].is_null()) EXPECT_LT(c["level"]["estimated_error"].get<double>(), c["below"].get<double>());
  }
  // Deleting the study dismisses its jobs (finished ones are removed).
  const auto removed = api.del("/v1/studies/" + id);
  ASSERT_TRUE(removed);
  EXPECT_EQ(removed->status, 204);
  EXPECT_EQ(api.get("/v1/studies/" + id)->status, 404);
  for (const json& level : study["levels"])
    EXPECT_EQ(api.get("/v1/jobs/" + level["job"].get<std::string>())->status, 404);
}

TEST(Studies, BadPlansAreRefusedWithThePointerBeforeAnyJobIsStored) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--workers", "1", "--max-nodes", "2000"}, dir.path() / "serve.log");
  const Api api(server.port());
  struct Case {
    json request;
    std::string pointer, says;
  };
  json by_node = cylinder();
  by_node["outputs"][0] = {{"name", "u"}, {"kind", "displacement"}, {"node", 0}, {"component", "x"}};
  json unknown_set = cylinder();
  unknown_set["outputs"][0] = {{"name", "r"}, {"kind", "reaction"}, {"set", "rim"}, {"component", "y"}};
  json explicit_mesh = cylinder();
  explicit_mesh["body"]["mesh"] = {{"nodes", {{1, 0}, {2, 0}, {2, 1}, {1, 1}}}, {"elements", {{0, 1, 2, 3}}}};
  json no_outputs = cylinder();
  no_outputs.erase("outputs");
  json large = cylinder();
  large["body"]["mesh"]["rectangle"]["divisions"] = {16, 8};  // level 3: 64 x 32, 2145 nodes
  const Case cases[] = {
      {{{"scene", cylinder()}, {"refine", {{"levels", 10000}}}}, "/refine/levels", "[2, 6]"},
      {{{"scene", by_node}, {"refine", {{"levels", 3}}}}, "/scene/outputs/0/node", "at"},
      {{{"scene", unknown_set}, {"refine", {{"levels", 3}}}}, "/scene/outputs/0/set", "level 1 of 3"},
      {{{"scene", explicit_mesh}, {"refine", {{"levels", 3}}}}, "/scene/body/mesh", "not generated"},
      {{{"scene", no_outputs}, {"refine", {{"levels", 3}}}}, "/scene/outputs", "name at least one"},
      {{{"scene", cylinder()}, {"refine", {{"levels", 3}}}, {"outputs", {"u_middle"}}},
       "/outputs/0",
       "names no output"},
      {{{"scene", cylinder()}, {"refine", {{"levels", 3}}}, {"sweep", json::array()}}, "/sweep", "not a member"},
      {{{"scene", large}, {"refine", {{"levels", 3}}}}, "/scene/body/mesh", "level 3 of 3"},
  };
  for (const Case& c : cases) {
    const json p = post_study(api, c.request, 422);
    ASSERT_TRUE(p.contains("errors")) << p.dump();
    EXPECT_EQ(p["type"], "urn:grip:problem:invalid-study");
    EXPECT_EQ(p["errors"][0]["pointer"], c.pointer) << p.dump();
    EXPECT_NE(p["errors"][0]["detail"].get<std::string>().find(c.says), std::string::npos) << p.dump();
  }
  // Nothing was stored.
  const auto jobs = api.get("/v1/jobs");
  ASSERT_TRUE(jobs);
  EXPECT_TRUE(json::parse(jobs->body)["jobs"].empty()) << jobs->body;
}

}  // namespace
}  // namespace grip::testing
