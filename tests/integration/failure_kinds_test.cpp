// failure.kind, produced for real: each kind a run or a job can end with, from a scene or a
// service that fails that way, its result, events and job document valid against schemas/.
// `exception` is produced in tests/unit/scene_test.cpp (an observer that throws); `stopped`
// is a stop request without a reason, which neither grip solve (no stop) nor the service (its
// stops name their cause; a shutdown requeues the job) ever makes.
#include <gtest/gtest.h>

#include <set>

#include "grip_process.hpp"
#include "schema_check.hpp"
#include "server/sqlite.hpp"

namespace grip::testing {
namespace {

void expect_valid(const std::string& schema, const json& doc) {
  if (auto errors = schema_errors(schema, doc)) {
    EXPECT_TRUE(errors->empty()) << schema << ": " << (errors->empty() ? "" : errors->front());
  }
}

json example(const std::string& name) { return json::parse(read_text(examples_dir() / (name + ".json"))); }

// `grip solve` of a scene that must fail with `kind`: the result's summary and failed step,
// and the step_finished and job_failed events, carry it; all valid.
void expect_solve_fails_with(const json& scene, const std::string& kind) {
  SCOPED_TRACE(kind);
  TempDir dir;
  const fs::path in = dir.path() / "scene.json", out = dir.path() / "result.json",
                 events = dir.path() / "events.ndjson";
  std::ofstream(in) << scene.dump();
  const std::string cmd = std::string(GRIP_BINARY) + " solve " + in.string() + " --out " + out.string() + " --events " +
                          events.string() + " > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << "grip solve should fail (exit 1)";
  const json result = json::parse(read_text(out));
  expect_valid("result", result);
  const json& summary = result["summary"];
  EXPECT_EQ(summary["failure"]["kind"], kind) << summary;
  EXPECT_EQ(summary["failure"]["message"], summary["reason"]);
  const json& last = result["steps"].back();
  EXPECT_EQ(last["failure"]["kind"], kind);
  EXPECT_EQ(last["failure"]["step"], last["step"]);
  EXPECT_EQ(summary["failure"]["step"], last["step"]);
  std::istringstream lines(read_text(events));
  std::string line;
  json terminal, step_finished;
  while (std::getline(lines, line)) {
    const json e = json::parse(line);
    expect_valid("event", e);
    if (e["type"] == "step_finished") step_finished = e;
    terminal = e;
  }
  EXPECT_EQ(step_finished["failure"]["kind"], kind);
  EXPECT_EQ(terminal["type"], "job_failed");
  EXPECT_EQ(terminal["failure"], summary["failure"]);
}

TEST(FailureKinds, FrictionLimit) {
  expect_solve_fails_with(json::parse(read_text(source_dir() / "tests" / "golden" / "friction-limit.json")),
                          "friction_limit");
}

TEST(FailureKinds, NoEquilibriumWhenTheLoadPullsTheBodyOff) {
  json scene = example("block-held-by-friction");
  scene["body"]["loads"][0]["traction"] = {0, 10};  // the "press" case pulls up
  scene["stages"] = json::array({scene["stages"][0]});
  expect_solve_fails_with(scene, "no_equilibrium");
}

TEST(FailureKinds, NewtonDivergedWithOneNewtonIteration) {
  json scene = example("beam-on-cylinder");
  scene["solver"]["newton"]["max_iterations"] = 1;  // the von Karman beam needs more
  expect_solve_fails_with(scene, "newton_diverged");
}

// The punch drawn back a little: the sheet's stretch increments turn negative, which the
// rigid-plastic membrane refuses (it would wrinkle).
TEST(FailureKinds, InvalidStateWhenTheMembraneIsCompressed) {
  json scene = example("sheet-stretching");
  scene.erase("steps");
  // The punch drawn back from 0.3 to 0.1 of its travel in one step: the step fails after 5 cuts,
  // with its last attempt's reason, which follows the path (back to 0.25 at the contact bound
  // tol x D the last attempt ended in Newton's 40 iterations, at tol x L in the compression).
  scene["stages"] = {{{"steps", 6}, {"factors", {{"main", 0.3}}}}, {{"steps", 1}, {"factors", {{"main", 0.1}}}}};
  expect_solve_fails_with(scene, "invalid_state");
}

TEST(FailureKinds, ContactBudgetWithOneContactIteration) {
  json scene = example("sliding-block");
  scene["solver"]["contact"]["max_iterations"] = 1;
  expect_solve_fails_with(scene, "contact_budget");
}

// uzawa with an absurd fixed alpha: its update finds no usable direction.
TEST(FailureKinds, ContactStalledWithAnAbsurdUzawaAlpha) {
  json scene = example("sliding-block");
  scene["solver"]["contact"]["method"] = "uzawa";
  scene["solver"]["contact"]["uzawa_alpha"] = 1e12;
  expect_solve_fails_with(scene, "contact_stalled");
}

struct Server {
  TempDir dir;
  std::unique_ptr<ServerProcess> process;
  explicit Server(std::vector<std::string> args = {}) { start(std::move(args)); }
  void start(std::vector<std::string> args) {
    process = std::make_unique<ServerProcess>(dir.path() / "grip.sqlite", std::move(args), dir.path() / "server.log");
  }
  Api api() const { return Api(process->port()); }
};

// A job that ends with `kind`: its document and its events, valid and carrying it.
void expect_job_ends_with(const Api& api, const std::string& id, const std::string& status, const std::string& kind) {
  SCOPED_TRACE(kind);
  const json doc = api.wait_status(id, {"successful", "failed", "dismissed"}, std::chrono::seconds(120));
  expect_valid("job", doc);
  EXPECT_EQ(doc["status"], status);
  EXPECT_EQ(doc["failure"]["kind"], kind) << doc;
  EXPECT_EQ(doc["failure"]["message"], doc["message"]);
  const Stream s = follow(api, id);
  ASSERT_TRUE(s.ended);
  for (const SseEvent& e : s.events) expect_valid("event", e.object());
  EXPECT_EQ(s.events.back().object()["failure"]["kind"], kind);
  if (const auto r = api.get("/v1/jobs/" + id + "/result"); r && r->status == 200) {
    const json result = json::parse(r->body);
    expect_valid("result", result);
    EXPECT_EQ(result["summary"]["failure"], doc["failure"]);
  }
}

TEST(FailureKinds, JobLimitFromTheService) {
  Server server({"--workers", "1", "--max-iterations", "5"});
  const Api api = server.api();
  expect_job_ends_with(api, api.submit(example("beam-on-cylinder")), "failed", "job_limit");
}

TEST(FailureKinds, DismissedFromTheService) {
  Server server({"--workers", "1"});
  const Api api = server.api();
  const std::string running = api.submit(beam_scene(40, 4000));  // about 1.7 s
  api.wait_status(running, {"running"});
  ASSERT_EQ(api.del("/v1/jobs/" + running)->status, 200);
  expect_job_ends_with(api, running, "dismissed", "dismissed");
}

// The stored scene of an accepted job no longer reads (here: edited in the database while the
// service was down): the job fails with invalid_scene when it runs.
TEST(FailureKinds, InvalidSceneWhenTheStoredSceneDoesNotRead) {
  Server server({"--workers", "1"});
  const std::string blocker = server.api().submit(beam_scene(40, 4000));
  const std::string id = server.api().submit(example("hertz"));
  server.process->kill9();
  {
    server::Database db((server.dir.path() / "grip.sqlite").string(), 5000);
    db.prepare("UPDATE jobs SET scene = '{\"body\": 1}' WHERE id = ?").bind(1, id).run();
  }
  server.start({"--workers", "1"});
  // The blocker, older, runs first again: dismissed at once, it does not hold the job up (its
  // 4000 steps took over 2 minutes when four such tests ran beside other builds).
  ASSERT_EQ(server.api().del("/v1/jobs/" + blocker)->status, 200);
  expect_job_ends_with(server.api(), id, "failed", "invalid_scene");
}

// Every kind of the schema has its test: those above (each its own process under ctest, so
// the list is written out), `exception` in tests/unit/scene_test.cpp, and `stopped`, which
// nothing can produce (see the top of this file).
TEST(FailureKinds, EveryKindOfTheSchemaHasItsTest) {
  const json schema = json::parse(read_text(schemas_dir() / "result.schema.json"));
  std::set<std::string> listed;
  for (const json& k : schema["definitions"]["failure"]["properties"]["kind"]["enum"]) listed.insert(k);
  const std::set<std::string> tested = {"friction_limit",  "no_equilibrium",  "newton_diverged", "invalid_state",
                                        "contact_budget",  "contact_stalled", "check_failed",    "missed_contact",
                                        "penalty_inexact", "job_limit",       "dismissed",       "invalid_scene",
                                        "exception",       "stopped"};
  // check_failed and missed_contact: tests/robustness/checks_scenes_test.cpp; penalty_inexact:
  // tests/robustness/tolerance_scenes_test.cpp.
  EXPECT_EQ(tested, listed);
}

}  // namespace
}  // namespace grip::testing
