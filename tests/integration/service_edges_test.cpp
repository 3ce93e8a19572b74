// Rough edges of the service (issue 17): 405 with Allow, DELETE racing a job's end, jobs
// readable during the SIGTERM grace period.
#include <gtest/gtest.h>

#include <signal.h>

#include "grip_process.hpp"

namespace grip::testing {
namespace {

using namespace std::chrono_literals;

TEST(ServiceEdges, AWrongMethodOnAKnownRouteIs405WithAllow) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {}, dir.path() / "server.log");
  auto cli = Api(server.port()).client();
  struct Case {
    const char* method;
    const char* path;
    const char* allow;  // empty: 404
  };
  for (const Case& c : {Case{"PUT", "/v1/jobs", "GET, POST"}, Case{"PATCH", "/v1/jobs/abc", "GET, DELETE"},
                        Case{"POST", "/v1/jobs/abc/events", "GET"}, Case{"DELETE", "/v1/health", "GET"},
                        Case{"GET", "/processes/contact2d/execution", "POST"}, Case{"PUT", "/v1/nope", ""}}) {
    httplib::Request req;
    req.method = c.method;
    req.path = c.path;
    auto r = cli.send(req);
    ASSERT_TRUE(r) << c.method << " " << c.path;
    const json body = json::parse(r->body);
    if (std::string(c.allow).empty()) {
      EXPECT_EQ(r->status, 404) << c.path;
      continue;
    }
    EXPECT_EQ(r->status, 405) << c.method << " " << c.path;
    EXPECT_EQ(r->get_header_value("Allow"), c.allow) << c.path;
    EXPECT_EQ(body["status"], 405);
    EXPECT_EQ(body["type"], "urn:grip:problem:method-not-allowed");
  }
}

// The answer to a DELETE is the truth afterwards: "dismissed" only for a job that ends
// dismissed (no result), "removed" only for a job that had finished and is gone.
TEST(ServiceEdges, ADeleteRacingTheEndOfAJobAnswersWhatTheJobBecomes) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--workers", "2"}, dir.path() / "server.log");
  const Api api(server.port());
  const json scene = beam_scene(10, 3);
  int dismissed = 0, removed = 0;
  for (int i = 0; i < 40; ++i) {
    const std::string id = api.submit(scene);
    std::this_thread::sleep_for(std::chrono::microseconds(500 * (i % 20)));  // around the job's end
    auto del = api.del("/v1/jobs/" + id);
    ASSERT_TRUE(del);
    ASSERT_EQ(del->status, 200);
    const json answer = json::parse(del->body);
    if (answer["status"] == "dismissed") {
      ++dismissed;
      const json doc = api.wait_status(id, {"dismissed", "successful", "failed"});
      EXPECT_EQ(doc["status"], "dismissed") << id;
      EXPECT_EQ(api.get("/v1/jobs/" + id + "/result")->status, 404) << id;
      const Stream s = follow(api, id);
      ASSERT_TRUE(s.ended);
      EXPECT_EQ(s.events.back().object()["reason"], "dismissed") << id;
    } else {
      ++removed;
      EXPECT_EQ(answer["message"], "removed with its events and result");
      EXPECT_EQ(answer["status"], "successful") << id;
      EXPECT_EQ(api.get("/v1/jobs/" + id)->status, 404) << id;
    }
  }
  std::printf("[ info ] %d dismissed, %d removed\n", dismissed, removed);
}

TEST(ServiceEdges, JobsStayReadableDuringTheGracePeriod) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--workers", "1", "--grace", "30"}, dir.path() / "server.log");
  const Api api(server.port());
  const std::string id = api.submit(beam_scene(40, 150));
  api.wait_status(id, {"running"});
  ::kill(server.pid(), SIGTERM);
  // The signal is handled asynchronously: wait (bounded) until readiness says so.
  for (int i = 0; i < 250; ++i) {
    auto ready = api.get("/v1/ready");
    if (!ready || ready->status == 503) break;
    std::this_thread::sleep_for(20ms);
  }
  // The running job may finish; meanwhile its status answers, new work is refused.
  bool seen_in_grace = false;
  for (int i = 0; i < 200; ++i) {
    auto doc = api.get("/v1/jobs/" + id);
    if (!doc) break;  // finished and stopped
    ASSERT_EQ(doc->status, 200);
    if (json::parse(doc->body)["status"] != "running") break;
    seen_in_grace = true;
    auto ready = api.get("/v1/ready");
    ASSERT_TRUE(ready);
    EXPECT_EQ(ready->status, 503);
    auto refused = api.post_json("/v1/jobs", beam_scene(10, 3).dump());
    ASSERT_TRUE(refused);
    EXPECT_EQ(refused->status, 503);
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_TRUE(seen_in_grace) << "the job finished before the signal arrived: take a longer one";
  EXPECT_EQ(server.terminate(60s), 0);
  ServerProcess again(dir.path() / "grip.sqlite", {}, dir.path() / "server.log");
  EXPECT_EQ(Api(again.port()).job(id)["status"], "successful");
}

}  // namespace
}  // namespace grip::testing
