// Measurements printed for the record, never asserted: throughput of small jobs through the
// real binary, and the delay from a contact iteration to its event reaching a client.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <thread>

#include "server/http_server.hpp"
#include "server/job_service.hpp"
#include "server/sqlite_store.hpp"
// clang-format off
#include "grip_process.hpp"
// clang-format on

namespace grip::testing {
namespace {

using Clock = std::chrono::steady_clock;

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))];
}

TEST(Bench, ThroughputOfSmallJobs) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {}, dir.path() / "server.log");
  const Api api(server.port());
  constexpr int kJobs = 100, kClients = 4;
  const json scene = beam_scene(10, 3);
  std::vector<std::string> ids(kJobs);
  const auto t0 = Clock::now();
  std::vector<std::thread> clients;
  for (int c = 0; c < kClients; ++c)
    clients.emplace_back([&, c] {
      for (int i = c; i < kJobs; i += kClients) ids[i] = api.submit(scene);
    });
  for (auto& t : clients) t.join();
  const double submit_s = std::chrono::duration<double>(Clock::now() - t0).count();
  for (const auto& id : ids) ASSERT_EQ(api.wait_status(id, {"successful", "failed"})["status"], "successful");
  const double total_s = std::chrono::duration<double>(Clock::now() - t0).count();
  std::printf(
      "[ bench ] %d jobs (beam, 10 elements, 3 steps) from %d clients: submitted in %.3f s, "
      "all successful after %.3f s: %.0f jobs/s\n",
      kJobs, kClients, submit_s, total_s, kJobs / total_s);
}

TEST(Bench, DelayFromIterationToClient) {
  TempDir dir;
  server::SqliteStore store((dir.path() / "grip.sqlite").string());
  std::mutex m;
  std::map<std::pair<std::string, std::int64_t>, Clock::time_point> produced;
  server::ServiceOptions options;
  options.workers = 1;
  options.event_tap = [&](const std::string& job, std::int64_t seq, const nlohmann::json&) {
    const auto now = Clock::now();
    std::lock_guard lock(m);
    produced[{job, seq}] = now;
  };
  server::JobService service(store, options);
  service.start();
  server::HttpOptions http_options;
  http_options.port = 0;
  server::HttpServer http(service, http_options);
  const int port = http.bind();
  std::thread listener([&] { http.listen(); });
  const Api api(port);

  // A blocker holds the only worker until the measured job's stream is open, so that every
  // event of the measured job is live, not replayed.
  const std::string blocker = api.submit(beam_scene(40, 400));
  api.wait_status(blocker, {"running"});
  const std::string id = api.submit(json::parse(read_text(examples_dir() / "beam-on-cylinder.json")));
  std::vector<double> delays_ms;
  std::thread reader([&] {
    SseParser parser;
    auto cli = api.client(60);
    cli.Get("/v1/jobs/" + id + "/events", [&](const char* data, size_t n) {
      const auto now = Clock::now();
      bool end = false;
      for (const auto& e : parser.feed(data, n)) {
        std::lock_guard lock(m);
        auto it = produced.find({id, e.id});
        if (e.type == "iteration" && it != produced.end())
          delays_ms.push_back(std::chrono::duration<double, std::milli>(now - it->second).count());
        end = end || e.type == "job_finished" || e.type == "job_failed";
      }
      return !end;
    });
  });
  while (http.open_streams() < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  api.del("/v1/jobs/" + blocker);
  reader.join();
  http.stop();
  listener.join();
  service.shutdown(std::chrono::milliseconds(0));
  ASSERT_FALSE(delays_ms.empty());
  std::printf(
      "[ bench ] iteration -> SSE client delay over %zu live iteration events: median %.3f ms, "
      "p95 %.3f ms, max %.3f ms (each event committed to SQLite, WAL, before "
      "it is sent)\n",
      delays_ms.size(), percentile(delays_ms, 0.5), percentile(delays_ms, 0.95), percentile(delays_ms, 1.0));
}

}  // namespace
}  // namespace grip::testing
