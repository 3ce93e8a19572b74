// What the service tells operators (issue 34.6): request counts by method, route template and
// status and latency histograms per route after known requests; queue-wait and run-duration
// histograms by outcome; the request id echoed, attached to the job and logged with the
// client's address; log lines in UTC with a Z, as text or as one JSON object a line.
#include <gtest/gtest.h>

#include <chrono>
#include <regex>
#include <thread>

#include "grip_process.hpp"

namespace grip::testing {
namespace {

// The value of one sample line ("name{labels} value") of /v1/metrics; -1 when absent.
double sample(const std::string& metrics, const std::string& series) {
  const size_t at = metrics.find("\n" + series + " ");
  if (at == std::string::npos) return -1;
  return std::stod(metrics.substr(at + series.size() + 2));
}

TEST(Observability, RequestsAreCountedByMethodRouteAndStatusWithLatencyAndJobHistograms) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {}, dir.path() / "serve.log");
  const Api api(server.port());
  const std::string id = api.submit(json::parse(read_text(source_dir() / "tests" / "load" / "small-job.json")));
  api.wait_status(id, {"successful"});
  for (int i = 0; i < 3; ++i) ASSERT_EQ(api.get("/v1/jobs/" + id)->status, 200);
  ASSERT_EQ(api.get("/v1/jobs/no-such-job")->status, 404);
  ASSERT_EQ(api.post_json("/v1/jobs", R"({"body": {}})")->status, 422);
  ASSERT_EQ(api.get("/no/such/route")->status, 404);
  // A request is counted by httplib's logger, which runs once its answer has gone out, on the
  // thread of its connection (each request here has its own): the client may ask for the
  // metrics before an earlier request is counted. A job's run is observed just after its end
  // is stored, so wait_status may see it finished first. Read until every series asserted
  // below is in (the counts only grow).
  std::string m;
  const auto all_in = [&] {
    return sample(m, R"(grip_http_requests_total{method="GET",route="other",status="404"})") >= 1 &&
           sample(m, R"(grip_http_requests_total{method="GET",route="/v1/jobs/{id}",status="404"})") >= 1 &&
           sample(m, R"(grip_http_requests_total{method="GET",route="/v1/jobs/{id}",status="200"})") >= 4 &&
           sample(m, R"(grip_http_request_duration_seconds_count{route="/v1/jobs"})") >= 2 &&
           sample(m, R"(grip_job_run_seconds_count{outcome="successful"})") >= 1;
  };
  for (int tries = 0; tries < 250; ++tries) {
    m = api.get("/v1/metrics")->body;
    if (all_in()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }

  EXPECT_EQ(sample(m, R"(grip_http_requests_total{method="POST",route="/v1/jobs",status="201"})"), 1) << m;
  EXPECT_EQ(sample(m, R"(grip_http_requests_total{method="POST",route="/v1/jobs",status="422"})"), 1);
  EXPECT_EQ(sample(m, R"(grip_http_requests_total{method="GET",route="/v1/jobs/{id}",status="404"})"), 1);
  EXPECT_EQ(sample(m, R"(grip_http_requests_total{method="GET",route="other",status="404"})"), 1);
  // The three reads and wait_status's polls, all 200.
  EXPECT_GE(sample(m, R"(grip_http_requests_total{method="GET",route="/v1/jobs/{id}",status="200"})"), 4);
  // Latency per route: the POSTs (201 and 422) in the submit route's histogram.
  EXPECT_EQ(sample(m, R"(grip_http_request_duration_seconds_count{route="/v1/jobs"})"), 2);
  EXPECT_EQ(sample(m, R"(grip_http_request_duration_seconds_bucket{route="/v1/jobs",le="+Inf"})"), 2);
  // One job waited in the queue and ran to success.
  EXPECT_EQ(sample(m, "grip_job_queue_wait_seconds_count"), 1);
  EXPECT_EQ(sample(m, R"(grip_job_run_seconds_count{outcome="successful"})"), 1);
  EXPECT_EQ(sample(m, R"(grip_job_run_seconds_bucket{outcome="successful",le="+Inf"})"), 1);
  // SQLite does not measure round trips or bytes: no such series.
  EXPECT_EQ(m.find("grip_db_round_trips_total"), std::string::npos);
  EXPECT_EQ(m.find("grip_db_bytes_total"), std::string::npos);
}

TEST(Observability, TheRequestIdIsEchoedAttachedToTheJobAndLoggedWithTheClientInUtc) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {}, dir.path() / "serve.log");
  const Api api(server.port());
  const json scene = json::parse(read_text(source_dir() / "tests" / "load" / "small-job.json"));
  auto r = api.post_json("/v1/jobs", scene.dump(), {{"X-Request-Id", "client-chosen-42"}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 201);
  EXPECT_EQ(r->get_header_value("X-Request-Id"), "client-chosen-42");
  const std::string id = json::parse(r->body)["jobID"];
  EXPECT_EQ(api.job(id)["request_id"], "client-chosen-42");
  // Without one (or with an unusable one), the server makes one.
  auto made = api.get("/v1/health", {{"X-Request-Id", std::string(200, 'x')}});
  ASSERT_TRUE(made);
  EXPECT_TRUE(std::regex_match(made->get_header_value("X-Request-Id"), std::regex("[0-9a-f]{16}")))
      << made->get_header_value("X-Request-Id");
  auto problem = api.get("/v1/jobs/nope");
  EXPECT_FALSE(problem->get_header_value("X-Request-Id").empty());
  api.wait_status(id, {"successful"});
  const std::string log = server.log();
  // 2026-11-28T06:01:02.345Z info POST /v1/jobs 201 12.3 ms request client-chosen-42 client 127.0.0.1
  EXPECT_TRUE(std::regex_search(
      log,
      std::regex(
          R"(\n\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z info POST /v1/jobs 201 [0-9.]+ ms request client-chosen-42 client 127\.0\.0\.1\n)")))
      << log;
  EXPECT_NE(log.find("accepted: "), std::string::npos);
  EXPECT_TRUE(std::regex_search(log, std::regex("job " + id + " accepted: .*\\(request client-chosen-42\\)"))) << log;
}

TEST(Observability, JsonLogsAreOneObjectALine) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--log-format", "json"}, dir.path() / "serve.log");
  const Api api(server.port());
  ASSERT_EQ(api.get("/v1/jobs/\"quoted\"", {{"X-Request-Id", "r-1"}})->status, 404);
  // The request's line is written after its answer is sent.
  for (int i = 0; i < 100 && server.log().find("request r-1") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::istringstream lines(server.log());
  std::string line;
  int objects = 0;
  bool request_line = false;
  while (std::getline(lines, line)) {
    const json j = json::parse(line, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << "not JSON: " << line;
    ASSERT_TRUE(j.contains("time") && j.contains("level") && j.contains("message")) << line;
    EXPECT_TRUE(
        std::regex_match(j["time"].get<std::string>(), std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z)")));
    ++objects;
    request_line |= j["message"].get<std::string>().find("GET /v1/jobs/\"quoted\" 404") == 0 &&
                    j["message"].get<std::string>().find("request r-1 client 127.0.0.1") != std::string::npos;
  }
  EXPECT_GT(objects, 3);
  EXPECT_TRUE(request_line) << server.log();
}

}  // namespace
}  // namespace grip::testing
