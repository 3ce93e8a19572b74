// The service over HTTP: the real `grip serve` on a free loopback port.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <set>
#include <thread>

#include "grip_process.hpp"
#include "schema_check.hpp"

namespace grip::testing {
namespace {

// Event ids 1, 2, ..., n: nothing missed, nothing repeated.
void expect_consecutive_ids(const std::vector<SseEvent>& events, std::int64_t first = 1) {
  for (size_t i = 0; i < events.size(); ++i)
    ASSERT_EQ(events[i].id, first + static_cast<std::int64_t>(i)) << "event " << i;
}

void expect_problem(const httplib::Result& r, int status, const std::string& type_suffix) {
  ASSERT_TRUE(r) << "no response";
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
  const json p = json::parse(r->body);
  EXPECT_EQ(p["status"], status);
  EXPECT_EQ(p["type"], "urn:grip:problem:" + type_suffix) << r->body;
  EXPECT_FALSE(p["title"].get<std::string>().empty());
  EXPECT_FALSE(p["detail"].get<std::string>().empty());
  ASSERT_TRUE(p["errors"].is_array());
  ASSERT_FALSE(p["errors"].empty());
  for (const auto& e : p["errors"]) {
    EXPECT_TRUE(e.contains("pointer")) << e;
    EXPECT_FALSE(e.value("detail", std::string()).empty()) << e;
  }
}

std::set<std::string> pointers(const httplib::Result& r) {
  std::set<std::string> out;
  const json problem = json::parse(r->body);
  for (const auto& e : problem["errors"]) out.insert(e["pointer"].get<std::string>());
  return out;
}

// Names and contents of a ustar archive.
std::map<std::string, std::string> untar(const std::string& tar) {
  std::map<std::string, std::string> files;
  size_t at = 0;
  while (at + 512 <= tar.size() && tar[at] != '\0') {
    const std::string name(tar.c_str() + at);
    const size_t size = std::stoul(tar.substr(at + 124, 11), nullptr, 8);
    files[name] = tar.substr(at + 512, size);
    at += 512 + (size + 511) / 512 * 512;
  }
  return files;
}

void expect_valid(const std::string& schema, const json& doc) {
  if (auto errors = schema_errors(schema, doc)) {
    EXPECT_TRUE(errors->empty()) << schema << ": " << (errors->empty() ? "" : errors->front());
  }
}

struct Server {
  TempDir dir;
  std::unique_ptr<ServerProcess> process;
  explicit Server(std::vector<std::string> args = {}) {
    process = std::make_unique<ServerProcess>(dir.path() / "grip.sqlite", std::move(args), dir.path() / "server.log");
  }
  Api api(std::optional<std::string> token = std::nullopt) const { return Api(process->port(), std::move(token)); }
};

TEST(Service, PaperExamplesStreamEveryIterationAndGiveResultsInAllFormats) {
  Server server;
  const Api api = server.api();
  // The paper's two examples (4.2 and 4.1), each as soon as its file exists, and two bodies
  // in contact (issue 19: the service carries their result as it is).
  std::vector<fs::path> examples;
  for (const char* name : {"beam-on-cylinder.json", "sheet-stretching.json", "two-cylinders.json"})
    if (fs::exists(examples_dir() / name)) examples.push_back(examples_dir() / name);
  ASSERT_FALSE(examples.empty());
  for (const fs::path& example : examples) {
    SCOPED_TRACE(example.filename().string());
    const json scene = json::parse(read_text(example));
    expect_valid("scene", scene);
    const std::string id = api.submit(scene);

    const Stream stream = follow(api, id);
    ASSERT_EQ(stream.status, 200);
    ASSERT_TRUE(stream.ended);
    expect_consecutive_ids(stream.events);
    ASSERT_EQ(stream.events.front().type, "step_started");
    ASSERT_EQ(stream.events.back().type, "job_finished") << stream.events.back().data;
    for (const auto& e : stream.events) {
      EXPECT_EQ(e.object()["type"], e.type);
      expect_valid("event", e.object());
    }

    const json doc = api.job(id);
    EXPECT_EQ(doc["status"], "successful");
    EXPECT_EQ(doc["progress"], 100);
    expect_valid("job", doc);

    auto r = api.get("/v1/jobs/" + id + "/result");
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200);
    EXPECT_EQ(r->get_header_value("Content-Type"), "application/json");
    const json result = json::parse(r->body);
    expect_valid("result", result);
    const json& steps = result["steps"];
    ASSERT_FALSE(steps.empty());

    // The streamed iterations are the result's contact error history, step by step.
    std::vector<json> iterations;
    size_t started = 0, finished = 0;
    for (const auto& e : stream.events) {
      if (e.type == "iteration") iterations.push_back(e.object());
      started += e.type == "step_started";
      finished += e.type == "step_finished";
    }
    EXPECT_EQ(started, steps.size());
    EXPECT_EQ(finished, steps.size());
    size_t next = 0;
    for (const json& step : steps) {
      for (const json& h : step["history"]) {
        ASSERT_LT(next, iterations.size());
        json ev = iterations[next++];
        EXPECT_EQ(ev["step"], step["step"]);
        ev.erase("type");
        ev.erase("step");
        EXPECT_EQ(ev, h);
      }
    }
    EXPECT_EQ(next, iterations.size());

    // Convergence: the same history as JSON and CSV.
    r = api.get("/v1/jobs/" + id + "/convergence");
    ASSERT_EQ(r->status, 200);
    const json conv = json::parse(r->body);
    ASSERT_EQ(conv["iterations"].size(), iterations.size());
    for (size_t i = 0; i < iterations.size(); ++i) {
      json ev = iterations[i];
      ev.erase("type");
      EXPECT_EQ(conv["iterations"][i], ev);
    }
    r = api.get("/v1/jobs/" + id + "/convergence?format=csv");
    ASSERT_EQ(r->status, 200);
    EXPECT_EQ(std::count(r->body.begin(), r->body.end(), '\n'), static_cast<long>(iterations.size()) + 1);

    // NDJSON carries the same objects.
    r = api.get("/v1/jobs/" + id + "/events?format=ndjson");
    ASSERT_EQ(r->status, 200);
    std::istringstream lines(r->body);
    std::string line;
    size_t k = 0;
    while (std::getline(lines, line)) {
      if (line.empty()) continue;  // heartbeat
      ASSERT_LT(k, stream.events.size());
      EXPECT_EQ(line, stream.events[k++].data);
    }
    EXPECT_EQ(k, stream.events.size());

    // CSV tables: one row per step and item.
    size_t node_rows = 0, point_rows = 0;
    for (const json& step : steps) {
      node_rows += step.value("nodes", json::array()).size();
      point_rows += step.value("contact_points", json::array()).size();
    }
    for (const std::string table : {"steps", "nodes", "elements", "contact_points", "history"}) {
      r = api.get("/v1/jobs/" + id + "/result?format=csv&table=" + table);
      ASSERT_EQ(r->status, 200) << table;
      EXPECT_EQ(r->get_header_value("Content-Type"), "text/csv; charset=utf-8");
      const long rows = std::count(r->body.begin(), r->body.end(), '\n') - 1;
      if (table == "steps") EXPECT_EQ(rows, static_cast<long>(steps.size()));
      if (table == "nodes") EXPECT_EQ(rows, static_cast<long>(node_rows));
      if (table == "contact_points") EXPECT_EQ(rows, static_cast<long>(point_rows));
      if (table == "history") EXPECT_EQ(rows, static_cast<long>(iterations.size()));
    }
    r = api.get("/v1/jobs/" + id + "/result?format=csv");
    ASSERT_EQ(r->status, 200);
    const std::string header = result.contains("bodies") ? "step,load_factor,body,node" : "step,load_factor,node";
    EXPECT_EQ(r->body.substr(0, r->body.find('\n')).rfind(header, 0), 0u) << r->body.substr(0, 80);

    // VTK: a .pvd collection over one .vtu per step, and the legacy .vtk series.
    r = api.get("/v1/jobs/" + id + "/result?format=vtk");
    ASSERT_EQ(r->status, 200);
    EXPECT_EQ(r->get_header_value("Content-Type"), "application/x-tar");
    const auto files = untar(r->body);
    size_t vtu = 0, vtk = 0;
    std::string pvd;
    for (const auto& [name, content] : files) {
      if (name.ends_with(".vtu")) {
        ++vtu;
        EXPECT_NE(content.find("<UnstructuredGrid>"), std::string::npos);
      }
      if (name.ends_with(".vtk")) {
        ++vtk;
        EXPECT_EQ(content.rfind("# vtk DataFile Version 3.0", 0), 0u);
      }
      if (name.ends_with(".pvd")) pvd = content;
    }
    EXPECT_EQ(vtu, steps.size());
    EXPECT_EQ(vtk, steps.size());
    EXPECT_EQ(static_cast<size_t>(std::count(pvd.begin(), pvd.end(), '\n')), steps.size() + 5);
    r = api.get("/v1/jobs/" + id + "/result?format=vtk&step=" + std::to_string(steps.size()));
    ASSERT_EQ(r->status, 200);
    EXPECT_NE(r->body.find("POINTS " + std::to_string(steps.back()["nodes"].size()) + " double"), std::string::npos);
  }
  // The server still serves.
  EXPECT_EQ(api.get("/v1/health")->status, 200);
}

TEST(Service, TwentyConcurrentSubmissionsAndStreamsWhileHealthAnswers) {
  Server server;
  const Api api = server.api();
  constexpr int kJobs = 20;
  std::vector<Stream> streams(kJobs);
  std::vector<std::string> ids(kJobs);
  std::atomic<int> done{0};
  std::mutex failures_mutex;
  std::vector<std::string> failures;
  std::vector<std::thread> clients;
  for (int i = 0; i < kJobs; ++i)
    clients.emplace_back([&, i] {
      try {
        ids[i] = api.submit(beam_scene(10 + i, 4 + i % 4));
        streams[i] = follow(api, ids[i]);
      } catch (const std::exception& e) {
        std::lock_guard lock(failures_mutex);
        failures.push_back(e.what());
      }
      ++done;
    });
  int health_checks = 0, healthy = 0;
  double slowest_ms = 0;
  while (done < kJobs) {
    const auto t0 = std::chrono::steady_clock::now();
    auto r = api.get("/v1/health");
    slowest_ms =
        std::max(slowest_ms, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    ++health_checks;
    healthy += r && r->status == 200;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  for (auto& t : clients) t.join();
  ASSERT_TRUE(failures.empty()) << failures.front() << "\n" << server.process->log();
  EXPECT_EQ(healthy, health_checks);
  std::printf("[ info ] %d health checks during 20 jobs + 20 streams, slowest %.1f ms\n", health_checks, slowest_ms);
  for (int i = 0; i < kJobs; ++i) {
    SCOPED_TRACE(i);
    ASSERT_EQ(streams[i].status, 200);
    ASSERT_TRUE(streams[i].ended);
    expect_consecutive_ids(streams[i].events);
    EXPECT_EQ(streams[i].events.back().type, "job_finished");
    EXPECT_EQ(api.job(ids[i])["status"], "successful");
    const json result = json::parse(api.get("/v1/jobs/" + ids[i] + "/result")->body);
    size_t history = 0;
    for (const auto& s : result["steps"]) history += s["history"].size();
    EXPECT_EQ(history, static_cast<size_t>(std::count_if(streams[i].events.begin(), streams[i].events.end(),
                                                         [](const SseEvent& e) { return e.type == "iteration"; })));
  }
}

TEST(Service, ResumingWithLastEventIdMissesAndRepeatsNothing) {
  Server server;
  const Api api = server.api();
  const std::string id = api.submit(json::parse(read_text(examples_dir() / "beam-on-cylinder.json")));
  // Read part of the stream (live or replayed), drop the connection, resume.
  const Stream first = follow(api, id, std::nullopt, 40);
  ASSERT_EQ(first.events.size(), 40u);
  expect_consecutive_ids(first.events);
  const Stream rest = follow(api, id, first.events.back().id);
  ASSERT_TRUE(rest.ended);
  expect_consecutive_ids(rest.events, 41);
  // The two parts are exactly the full replay.
  const Stream full = follow(api, id);
  ASSERT_EQ(full.events.size(), first.events.size() + rest.events.size());
  for (size_t i = 0; i < full.events.size(); ++i) {
    const SseEvent& part = i < 40 ? first.events[i] : rest.events[i - 40];
    EXPECT_EQ(part.id, full.events[i].id);
    EXPECT_EQ(part.data, full.events[i].data);
  }
  // Resuming after the terminal event: nothing more, the stream ends.
  const Stream after_end = follow(api, id, full.events.back().id);
  EXPECT_EQ(after_end.status, 200);
  EXPECT_TRUE(after_end.events.empty());
  // ?after= does the same for NDJSON.
  auto r = api.get("/v1/jobs/" + id + "/events?format=ndjson&after=" + std::to_string(full.events.size() - 1));
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(r->body, full.events.back().data + "\n");
  auto bad = api.get("/v1/jobs/" + id + "/events", {{"Last-Event-ID", "abc"}});
  expect_problem(bad, 400, "bad-last-event-id");
}

TEST(Service, DismissStopsARunningJobAndFreesItsWorker) {
  Server server({"--workers", "1", "--streams", "2"});
  const Api api = server.api();
  const std::string running = api.submit(beam_scene(40, 4000));  // about 1.7 s: still running when dismissed
  const std::string queued = api.submit(beam_scene(10, 4));
  const std::string dropped = api.submit(beam_scene(10, 4));
  // Running: some iterations streamed.
  const Stream seen = follow(api, running, std::nullopt, 8);
  ASSERT_EQ(seen.events.size(), 8u);
  auto r = api.get("/v1/jobs/" + running + "/result");
  expect_problem(r, 404, "result-not-ready");

  // Stream cap: two open streams, a third is refused (after the first stream is closed).
  ASSERT_TRUE(wait_open_streams(api, 0));
  std::vector<std::thread> holders;
  std::vector<Stream> held(2);
  for (int i = 0; i < 2; ++i) holders.emplace_back([&, i] { held[i] = follow(api, running, seen.events.back().id); });
  ASSERT_TRUE(wait_open_streams(api, 2));
  r = api.get("/v1/jobs/" + running + "/events");
  expect_problem(r, 503, "too-many-streams");
  EXPECT_FALSE(r->get_header_value("Retry-After").empty());

  // Dismiss the queued one: it never runs.
  r = api.del("/v1/jobs/" + dropped);
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(json::parse(r->body)["status"], "dismissed");

  // Dismiss the running one.
  r = api.del("/v1/jobs/" + running);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(json::parse(r->body)["status"], "dismissed");
  for (auto& t : holders) t.join();
  for (const Stream& s : held) {
    ASSERT_TRUE(s.ended);
    EXPECT_EQ(s.events.back().type, "job_failed");
    EXPECT_EQ(s.events.back().object()["reason"], "dismissed");
  }
  const Stream all = follow(api, running);
  expect_consecutive_ids(all.events);
  const long steps_finished =
      std::count_if(all.events.begin(), all.events.end(), [](const SseEvent& e) { return e.type == "step_finished"; });
  EXPECT_LT(steps_finished, 4000);
  EXPECT_EQ(
      std::count_if(all.events.begin(), all.events.end(), [](const SseEvent& e) { return e.type == "job_finished"; }),
      0);
  const json doc = api.job(running);
  EXPECT_EQ(doc["status"], "dismissed");
  EXPECT_TRUE(doc.contains("finished"));
  expect_problem(api.get("/v1/jobs/" + running + "/result"), 404, "no-result");

  // The worker takes the next job.
  EXPECT_EQ(api.wait_status(queued, {"successful", "failed", "dismissed"})["status"], "successful");
  const Stream never = follow(api, dropped);
  ASSERT_EQ(never.events.size(), 1u);
  EXPECT_EQ(never.events[0].type, "job_failed");

  // Deleting a finished job removes it.
  ASSERT_EQ(api.del("/v1/jobs/" + running)->status, 200);
  expect_problem(api.get("/v1/jobs/" + running), 404, "job-not-found");
}

TEST(Service, BadRequestsGetTheirStatusAndProblemDocument) {
  Server server({"--max-body", "65536", "--token", "s3cret", "--max-nodes", "500", "--max-steps", "200"});
  const Api anonymous = server.api();
  const Api api = server.api("s3cret");
  const json beam = beam_scene(10, 4);

  // Token: required everywhere but health.
  EXPECT_EQ(anonymous.get("/v1/health")->status, 200);
  auto r = anonymous.get("/v1/jobs");
  expect_problem(r, 401, "unauthorized");
  EXPECT_EQ(r->get_header_value("WWW-Authenticate").rfind("Bearer", 0), 0u);
  expect_problem(Api(server.process->port(), "wrong").get("/v1/jobs"), 401, "unauthorized");
  expect_problem(anonymous.post_json("/v1/jobs", beam.dump()), 401, "unauthorized");
  expect_problem(anonymous.get("/v1/metrics"), 401, "unauthorized");

  // Malformed JSON.
  r = api.post_json("/v1/jobs", "{\"body\": ");
  expect_problem(r, 400, "malformed-json");
  // Schema-invalid and physically invalid scenes: every issue with its pointer.
  json bad = beam;
  bad["body"]["model"] = "nonsense";
  bad["steps"] = "many";
  r = api.post_json("/v1/jobs", bad.dump());
  expect_problem(r, 422, "invalid-scene");
  EXPECT_TRUE(pointers(r).count("/body/model")) << r->body;
  bad = beam;
  bad["body"]["material"]["young"] = -1;
  r = api.post_json("/v1/jobs", bad.dump());
  expect_problem(r, 422, "invalid-scene");
  EXPECT_EQ(pointers(r), std::set<std::string>{"/body/material/young"});
  r = api.post_json("/v1/jobs", "[1, 2]");
  expect_problem(r, 422, "invalid-scene");
  // Over the job limits.
  r = api.post_json("/v1/jobs", beam_scene(600, 4).dump());
  expect_problem(r, 422, "invalid-scene");
  EXPECT_EQ(pointers(r), std::set<std::string>{"/body/mesh"});
  r = api.post_json("/v1/jobs", beam_scene(10, 300).dump());
  expect_problem(r, 422, "invalid-scene");
  EXPECT_EQ(pointers(r), std::set<std::string>{"/steps"});
  // Oversize body, wrong content type.
  json big = beam;
  big["description"] = std::string(100000, 'x');
  expect_problem(api.post_json("/v1/jobs", big.dump()), 413, "payload-too-large");
  r = api.client().Post("/v1/jobs", beam.dump(), "text/plain");
  expect_problem(r, 415, "unsupported-media-type");
  // Unknown job and route.
  for (const std::string path :
       {"/v1/jobs/nope", "/v1/jobs/nope/events", "/v1/jobs/nope/result", "/v1/jobs/nope/convergence"})
    expect_problem(api.get(path), 404, "job-not-found");
  expect_problem(api.del("/v1/jobs/nope"), 404, "job-not-found");
  expect_problem(api.get("/v1/nothing-here"), 404, "not-found");
  // Bad query parameters.
  expect_problem(api.get("/v1/jobs?status=sleeping"), 400, "bad-parameter");
  expect_problem(api.get("/v1/jobs?cursor=garbage"), 400, "bad-parameter");
  expect_problem(api.get("/v1/jobs?limit=0"), 400, "bad-parameter");

  // Still serving: a good scene is solved.
  EXPECT_EQ(api.get("/v1/ready")->status, 200);
  const std::string id = api.submit(beam);
  EXPECT_EQ(api.wait_status(id, {"successful", "failed"})["status"], "successful");
  expect_problem(api.get("/v1/jobs/" + id + "/result?format=xml"), 400, "bad-parameter");
  expect_problem(api.get("/v1/jobs/" + id + "/result?format=csv&table=nope"), 400, "bad-parameter");
}

TEST(Service, JobsOverTheIterationOrTimeLimitFailWithThatReason) {
  {
    // The beam needs 53 real solves: a limit well below them.
    Server server({"--max-iterations", "30"});
    const Api api = server.api();
    const std::string id = api.submit(json::parse(read_text(examples_dir() / "beam-on-cylinder.json")));
    const json doc = api.wait_status(id, {"successful", "failed"});
    EXPECT_EQ(doc["status"], "failed");
    EXPECT_EQ(doc["failure"]["kind"], "job_limit") << doc;
    EXPECT_NE(doc["message"].get<std::string>().find("limit: "), std::string::npos) << doc;
    EXPECT_NE(doc["message"].get<std::string>().find("--max-iterations"), std::string::npos) << doc;
    const Stream s = follow(api, id);
    EXPECT_EQ(s.events.back().object()["reason"], doc["message"]);
    // Stopped at the first check after 30 real solves: within one update's trials of it.
    int solves = 0;
    for (const SseEvent& e : s.events)
      if (e.type == "iteration") solves += e.object()["trials"].get<int>();
    EXPECT_EQ(solves, doc["iterations"].get<int>());
    EXPECT_GE(solves, 30);
    EXPECT_LE(solves, 30 + 11);
    EXPECT_EQ(api.get("/v1/health")->status, 200);
    // 39 contact iterations: under the limit.
    EXPECT_EQ(api.wait_status(api.submit(beam_scene(10, 3)), {"successful", "failed"})["status"], "successful");
  }
  {
    Server server({"--max-seconds", "0.2"});
    const Api api = server.api();
    // 4000 steps take about 1.7 s here: well over the limit (400 steps took 0.17 s).
    const json doc = api.wait_status(api.submit(beam_scene(40, 4000)), {"successful", "failed"});
    EXPECT_EQ(doc["status"], "failed");
    EXPECT_EQ(doc["failure"]["kind"], "job_limit") << doc;
    EXPECT_NE(doc["message"].get<std::string>().find(
                  "limit: the run reached this service's wall-time limit (--max-seconds 0.2)"),
              std::string::npos)
        << doc;
    EXPECT_EQ(api.get("/v1/health")->status, 200);
  }
}

TEST(Service, FullQueueGives503WithRetryAfterAndDropsNothingAccepted) {
  Server server({"--workers", "1", "--queue", "2"});
  const Api api = server.api();
  const std::string busy = api.submit(beam_scene(40, 60));
  api.wait_status(busy, {"running"});
  const std::string a = api.submit(beam_scene(10, 3));
  const std::string b = api.submit(beam_scene(12, 3));
  auto r = api.post_json("/v1/jobs", beam_scene(14, 3).dump());
  expect_problem(r, 503, "queue-full");
  const int retry = std::stoi(r->get_header_value("Retry-After"));
  EXPECT_GE(retry, 1);
  for (const auto& id : {busy, a, b})
    EXPECT_EQ(api.wait_status(id, {"successful", "failed", "dismissed"})["status"], "successful");
  const std::string c = api.submit(beam_scene(14, 3));
  EXPECT_EQ(api.wait_status(c, {"successful", "failed"})["status"], "successful");
  // Three listed as successful plus the one after: nothing accepted was dropped.
  const json list = json::parse(api.get("/v1/jobs?status=successful")->body);
  EXPECT_EQ(list["jobs"].size(), 4u);
}

TEST(Service, IdempotencyKeyPagingAndOgcAliases) {
  Server server;
  const Api api = server.api();
  const json beam = beam_scene(10, 2);
  // Idempotency-Key: the same job again; another scene with the key is refused.
  auto r1 = api.post_json("/v1/jobs", beam.dump(), {{"Idempotency-Key", "k-1"}});
  auto r2 = api.post_json("/v1/jobs", beam.dump(), {{"Idempotency-Key", "k-1"}});
  ASSERT_EQ(r1->status, 201);
  ASSERT_EQ(r2->status, 201);
  EXPECT_EQ(json::parse(r1->body)["jobID"], json::parse(r2->body)["jobID"]);
  EXPECT_EQ(r2->get_header_value("Idempotent-Replayed"), "true");
  EXPECT_EQ(r1->get_header_value("Location"), "/v1/jobs/" + json::parse(r1->body)["jobID"].get<std::string>());
  expect_problem(api.post_json("/v1/jobs", beam_scene(11, 2).dump(), {{"Idempotency-Key", "k-1"}}), 422,
                 "idempotency-key-reused");

  // Paging: newest first, every job exactly once through the next links.
  std::vector<std::string> submitted = {json::parse(r1->body)["jobID"]};
  for (int i = 0; i < 6; ++i) submitted.push_back(api.submit(beam_scene(10, 1 + i % 2)));
  std::vector<std::string> listed;
  std::string next = "/v1/jobs?limit=3";
  while (!next.empty()) {
    const json page = json::parse(api.get(next)->body);
    EXPECT_LE(page["jobs"].size(), 3u);
    for (const auto& j : page["jobs"]) listed.push_back(j["jobID"]);
    next.clear();
    for (const auto& l : page["links"])
      if (l["rel"] == "next") next = l["href"];
  }
  std::reverse(submitted.begin(), submitted.end());
  EXPECT_EQ(listed, submitted);

  // OGC API - Processes.
  auto r = api.get("/processes");
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(json::parse(r->body)["processes"][0]["id"], "contact2d");
  r = api.get("/processes/contact2d");
  ASSERT_EQ(r->status, 200);
  EXPECT_TRUE(json::parse(r->body)["inputs"].contains("scene"));
  r = api.post_json("/processes/contact2d/execution", json{{"inputs", {{"scene", beam}}}}.dump());
  ASSERT_EQ(r->status, 201) << r->body;
  const std::string id = json::parse(r->body)["jobID"];
  EXPECT_EQ(api.wait_status(id, {"successful", "failed"})["status"], "successful");
  r = api.get("/jobs/" + id);
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(json::parse(r->body)["status"], "successful");
  EXPECT_EQ(api.get("/jobs/" + id + "/results")->status, 200);
  bool has_results_link = false;
  const json ogc_doc = json::parse(r->body);
  for (const auto& l : ogc_doc["links"])
    has_results_link |= l["rel"] == "http://www.opengis.net/def/rel/ogc/1.0/results";
  EXPECT_TRUE(has_results_link);
  json wrong = {{"inputs", {{"scene", beam}}}};
  wrong["inputs"]["scene"]["body"]["material"]["young"] = 0;
  r = api.post_json("/processes/contact2d/execution", wrong.dump());
  expect_problem(r, 422, "invalid-scene");
  EXPECT_EQ(pointers(r), std::set<std::string>{"/inputs/scene/body/material/young"});

  // Schemas and examples as documents; the paper's examples first.
  r = api.get("/v1/examples");
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(json::parse(r->body)["items"][0]["name"], "beam-on-cylinder");
  r = api.get("/v1/examples/beam-on-cylinder");
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(json::parse(r->body), json::parse(read_text(examples_dir() / "beam-on-cylinder.json")));
  expect_problem(api.get("/v1/examples/..%2Fsecret"), 404, "not-found");
  EXPECT_EQ(api.get("/v1/schemas")->status, 200);

  // Metrics: Prometheus text.
  r = api.get("/v1/metrics");
  ASSERT_EQ(r->status, 200);
  for (const char* name : {"grip_jobs{status=\"successful\"}", "grip_queue_depth", "grip_open_streams",
                           "grip_solve_seconds_total", "grip_contact_iterations_total"})
    EXPECT_NE(r->body.find(name), std::string::npos) << name;
}

TEST(Service, HealthcheckCommandProbesTheServer) {
  int port = 0;
  {
    Server server;
    port = server.process->port();
    const std::string cmd = std::string(GRIP_BINARY) + " healthcheck --port " + std::to_string(port) + " 2>/dev/null";
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_EQ(server.process->terminate(std::chrono::seconds(30)), 0);
  }
  const std::string cmd = std::string(GRIP_BINARY) + " healthcheck --port " + std::to_string(port) + " 2>/dev/null";
  EXPECT_NE(std::system(cmd.c_str()), 0);
}

}  // namespace
}  // namespace grip::testing
