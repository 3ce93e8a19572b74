// The job API without sockets: JobService over a SQLite store in a temporary folder.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>

// Eigen (through the solver) before httplib.h, whose <resolv.h> defines `_res`.
#include "server/compression.hpp"
#include "server/job_service.hpp"
#include "server/sqlite_store.hpp"
#include "server/util.hpp"
#include "solver/io/scene.hpp"
// clang-format off
#include "grip_process.hpp"
#include "tests/support/scenes.hpp"
#include "tests/support/turned_disc.hpp"
// clang-format on

namespace grip::testing {
namespace {

using server::EventBatch;
using server::JobService;
using server::JobStatus;
using server::ServiceOptions;
using server::SqliteStore;

// Waits for a job to finish; its stored events.
std::vector<server::StoredEvent> events_to_end(JobService& service, const std::string& id) {
  std::vector<server::StoredEvent> all;
  std::int64_t after = 0;
  for (int rounds = 0; rounds < 10000; ++rounds) {
    const EventBatch b = service.wait_events(id, after, std::chrono::milliseconds(1000));
    EXPECT_TRUE(b.found);
    for (const auto& e : b.events) {
      all.push_back(e);
      after = e.seq;
    }
    if (b.ended) return all;
  }
  ADD_FAILURE() << "no terminal event";
  return all;
}

// A SQLite store that counts the event reads that found nothing.
class CountingStore : public SqliteStore {
 public:
  using SqliteStore::SqliteStore;
  std::vector<server::StoredEvent> events_after(const std::string& id, std::int64_t after, int limit,
                                                std::string_view type) override {
    auto events = SqliteStore::events_after(id, after, limit, type);
    ++reads;
    if (events.empty()) ++empty_reads;
    return events;
  }
  std::atomic<int> reads{0}, empty_reads{0};
};

TEST(JobService, AStreamKeepingItsPlaceGetsEveryEventOnceAndReadsAgainOnlyAfterAnAnnouncement) {
  TempDir dir;
  CountingStore store((dir.path() / "grip.sqlite").string());
  ServiceOptions options;
  options.workers = 1;
  // In lockstep: the run makes event k once the reader has event k - 1, so every event is
  // stored and announced alone, and each read after the first finds one event at most.
  std::mutex m;
  std::condition_variable cv;
  std::int64_t received = 0;
  options.event_tap = [&](const std::string&, std::int64_t seq, const nlohmann::json&) {
    std::unique_lock lock(m);
    EXPECT_TRUE(cv.wait_for(lock, std::chrono::seconds(30), [&] { return received >= seq - 1; })) << seq;
  };
  JobService service(store, options);
  service.start();
  const std::string id = service.submit(beam_scene(10, 3)).job.record.id;
  std::uint64_t seen = 0;
  std::int64_t after = 0;
  int batches = 0;
  bool ended = false;
  for (int calls = 0; calls < 10000 && !ended; ++calls) {
    const EventBatch b = service.wait_events(id, after, std::chrono::milliseconds(1000), 256, &seen);
    ASSERT_TRUE(b.found);
    for (const auto& e : b.events) {
      EXPECT_EQ(e.seq, after + 1) << "every event once, in order";
      after = e.seq;
    }
    batches += b.events.empty() ? 0 : 1;
    ended = b.ended;
    {
      std::lock_guard lock(m);
      received = after;
    }
    cv.notify_all();
  }
  ASSERT_TRUE(ended);
  EXPECT_GE(after, 10);
  EXPECT_GE(batches, after - 1);  // the lockstep held: about one event a batch
  // Reads that found nothing: the first (the job not started yet) and those woken by the claim's
  // announcement or a timeout; not one after each batch (without `seen`, one each).
  std::printf("[ info ] %lld events in %d batches: %d reads of the store, %d found nothing\n",
              static_cast<long long>(after), batches, store.reads.load(), store.empty_reads.load());
  EXPECT_LE(store.empty_reads.load(), 4);
  EXPECT_EQ(service.job(id)->record.status, JobStatus::successful);
}

TEST(JobService, DismissalStopsARunningJobWithinOneIterationAndFreesTheWorker) {
  TempDir dir;
  SqliteStore store((dir.path() / "grip.sqlite").string());
  std::mutex m;
  std::string victim;
  std::int64_t dismissed_at = 0;
  JobService* self = nullptr;
  ServiceOptions options;
  options.workers = 1;
  int iterations = 0;
  // Dismiss from inside the run, at its fifth contact iteration: exact, no timing involved.
  options.event_tap = [&](const std::string& id, std::int64_t seq, const nlohmann::json& ev) {
    std::lock_guard lock(m);
    if (id != victim || ev["type"] != "iteration" || ++iterations != 5) return;
    dismissed_at = seq;
    const auto [outcome, view] = self->dismiss(id);
    EXPECT_EQ(outcome, server::DismissOutcome::dismissed);
    EXPECT_EQ(view->record.status, JobStatus::dismissed);
  };
  JobService service(store, options);
  self = &service;
  service.start();
  {
    std::lock_guard lock(m);
    victim = service.submit(beam_scene(40, 400)).job.record.id;
  }
  const std::string next = service.submit(beam_scene(10, 3)).job.record.id;
  const auto events = events_to_end(service, victim);
  ASSERT_GT(dismissed_at, 0);
  int after_dismissal = 0;
  for (const auto& e : events)
    if (e.seq > dismissed_at && e.type == "iteration") ++after_dismissal;
  EXPECT_LE(after_dismissal, 1);
  EXPECT_EQ(events.back().type, "job_failed");
  EXPECT_EQ(nlohmann::json::parse(events.back().data)["reason"], "dismissed");
  EXPECT_EQ(service.job(victim)->record.status, JobStatus::dismissed);
  EXPECT_FALSE(service.result(victim));
  // The worker went on to the next job.
  events_to_end(service, next);
  EXPECT_EQ(service.job(next)->record.status, JobStatus::successful);
}

// Runs `scene` as a job that must fail with `reason` (the text after "step k failed: "); its
// stored result.
nlohmann::json failed_job_result(const nlohmann::json& scene, const std::string& reason) {
  TempDir dir;
  SqliteStore store((dir.path() / "grip.sqlite").string());
  JobService service(store, ServiceOptions{});
  service.start();
  const std::string id = service.submit(scene).job.record.id;
  const auto events = events_to_end(service, id);
  EXPECT_EQ(events.back().type, "job_failed");
  const std::string said = nlohmann::json::parse(events.back().data)["reason"];
  EXPECT_NE(said.find(reason), std::string::npos) << said;
  EXPECT_EQ(service.job(id)->record.status, JobStatus::failed);
  const auto result = service.result(id);
  if (!result) {
    ADD_FAILURE() << "no result stored for the failed job";
    return nlohmann::json::object();
  }
  return nlohmann::json::parse(server::stored_text(*result));  // stored compressed
}

// A body held only by contact under a shear load above mu N
// (docs/algorithm.md#bodies-held-only-by-contact): a failed job whose reason says why, with the
// steps solved before it in its result.
TEST(JobService, AShearLoadAboveWhatFrictionHoldsFailsTheJobWithItsReason) {
  const nlohmann::json r = failed_job_result(
      block_under_shear(), "step 7 failed: the shear load exceeds what friction can hold: Q / (mu N) = 1.05");
  ASSERT_EQ(r["steps"].size(), 7u);
  for (int k = 0; k < 6; ++k) EXPECT_TRUE(r["steps"][k]["converged"].get<bool>());
  EXPECT_EQ(r["effects"]["held_by_contact"].size(), 3u);
}

// A couple beyond what friction holds on a disc squeezed between two flats (the normal forces
// come from its deformation, so no check before solving decides it): a failed job whose reason
// says why, with the two steps solved before it in its result, and no fields for the failed step.
TEST(JobService, ACoupleAboveWhatFrictionHoldsFailsTheJobWithItsReason) {
  const nlohmann::json r = failed_job_result(
      turned_beyond_the_limit(), "step 3 failed: the couple exceeds what friction can hold: M / (mu sum N r) = 1.06");
  ASSERT_EQ(r["steps"].size(), 3u);
  for (int k = 0; k < 2; ++k) EXPECT_TRUE(r["steps"][k]["converged"].get<bool>());
  EXPECT_FALSE(r["steps"][2]["converged"].get<bool>());
  EXPECT_FALSE(r["steps"][2].contains("nodes"));
  EXPECT_EQ(r["steps"][2]["cuts"], 0);
}

TEST(JobService, RecoveryRunsInterruptedJobsAgainAboveTheirOldEventIds) {
  TempDir dir;
  const std::string path = (dir.path() / "grip.sqlite").string();
  const nlohmann::json scene = beam_scene(10, 3);
  {
    // A store as a crash leaves it: one job running with three events, one accepted.
    SqliteStore store(path);
    for (const char* id : {"a-running", "b-accepted"}) {
      server::JobRecord rec;
      rec.id = id;
      rec.scene = scene.dump();
      rec.created = rec.updated = "2025-01-01T00:00:00.000Z";
      rec.steps = 3;
      rec.nodes = 11;
      store.insert_job(rec);
    }
    const auto claimed = store.claim_job("crashed", "2025-01-01T00:00:01.000Z", 60);
    ASSERT_TRUE(claimed);
    ASSERT_EQ(claimed->id, "a-running");
    std::vector<server::NewEvent> events;
    for (int k = 1; k <= 3; ++k)
      events.push_back({{"a-running", claimed->generation},
                        {k, "step_started", R"({"type":"step_started","step":1,"load_factor":0.1})"}});
    EXPECT_TRUE(store.append_events(events).empty());
  }
  SqliteStore store(path);
  JobService service(store, ServiceOptions{});
  service.start();
  const auto events = events_to_end(service, "a-running");
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.front().seq, 4);  // the interrupted run's ids are not given again
  for (size_t i = 1; i < events.size(); ++i) EXPECT_EQ(events[i].seq, events[i - 1].seq + 1);
  EXPECT_EQ(events.back().type, "job_finished");
  EXPECT_EQ(service.job("a-running")->record.attempts, 2);
  events_to_end(service, "b-accepted");
  EXPECT_EQ(service.job("b-accepted")->record.status, JobStatus::successful);
}

TEST(JobService, InvalidScenesAndLimitsThrowWithPointers) {
  TempDir dir;
  SqliteStore store((dir.path() / "grip.sqlite").string());
  ServiceOptions options;
  options.limits.max_nodes = 20;
  JobService service(store, options);
  service.start();
  try {
    service.submit(beam_scene(30, 2));
    FAIL() << "over the node limit";
  } catch (const SceneErrors& e) {
    ASSERT_EQ(e.issues().size(), 1u);
    EXPECT_EQ(e.issues()[0].pointer, "/body/mesh");
  }
  nlohmann::json bad = beam_scene(10, 2);
  bad["body"]["material"]["young"] = -1;
  EXPECT_THROW(service.submit(bad), SceneErrors);
  EXPECT_TRUE(service.list(std::nullopt, 10, std::nullopt).jobs.empty());  // nothing stored
}

// The node limit counts the mesh's nodes, not only those that can touch an obstacle: an
// explicit 10 x 4 mesh has 55 nodes, 11 of them in its contact set.
TEST(JobService, TheNodeLimitCountsEveryNodeOfAnExplicitMesh) {
  nlohmann::json scene = grip::testing::example_scene("sliding-block");
  const int nx = 10, ny = 4;
  nlohmann::json nodes = nlohmann::json::array(), elements = nlohmann::json::array();
  nlohmann::json bottom = nlohmann::json::array(), top = nlohmann::json::array();
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) nodes.push_back({-10.0 + 2.0 * i, 2.5 * j});
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i;
      elements.push_back({a, a + 1, a + nx + 2, a + nx + 1});
    }
  for (int i = 0; i <= nx; ++i) {
    bottom.push_back(i);
    top.push_back(ny * (nx + 1) + i);
  }
  scene["body"]["mesh"] = {{"nodes", nodes}, {"elements", elements}, {"sets", {{"bottom", bottom}, {"top", top}}}};
  TempDir dir;
  SqliteStore store((dir.path() / "grip.sqlite").string());
  ServiceOptions options;
  options.limits.max_nodes = 40;
  JobService service(store, options);
  try {
    service.submit(scene);
    FAIL() << "55 nodes over a limit of 40";
  } catch (const SceneErrors& e) {
    ASSERT_EQ(e.issues().size(), 1u);
    EXPECT_EQ(e.issues()[0].pointer, "/body/mesh");
    EXPECT_NE(e.issues()[0].detail.find("has 55 nodes"), std::string::npos) << e.issues()[0].detail;
  }
  ServiceOptions roomy;
  roomy.limits.max_nodes = 55;
  JobService accepting(store, roomy);
  EXPECT_EQ(accepting.submit(scene).job.record.nodes, 55);
}

// Retry-After of a full queue is the time until a worker frees (a queue slot then frees too),
// not the time to drain the whole queue.
TEST(JobService, RetryAfterIsTheTimeUntilAWorkerFreesNotTheTimeToDrainTheQueue) {
  TempDir dir;
  SqliteStore store((dir.path() / "grip.sqlite").string());
  ServiceOptions options;
  options.workers = 1;
  options.queue_capacity = 4;
  JobService service(store, options);
  service.start();
  const nlohmann::json scene = beam_scene(40, 60);
  const std::string first = service.submit(scene).job.record.id;
  events_to_end(service, first);
  const double mean = service.job(first)->record.solve_seconds;  // the only finished run
  std::vector<std::string> ids = {service.submit(scene).job.record.id};
  while (service.job(ids[0])->record.status == JobStatus::accepted)  // claimed by the worker
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  for (int i = 0; i < 4; ++i) ids.push_back(service.submit(scene).job.record.id);  // they wait
  try {
    service.submit(scene);
    FAIL() << "the queue should be full";
  } catch (const server::QueueFull& e) {
    // Draining the queue would take 4 runs; a worker frees within one.
    EXPECT_LE(e.retry_after_seconds, static_cast<int>(std::ceil(mean)));
    EXPECT_GE(e.retry_after_seconds, 1);
    std::printf("[ info ] mean run %.2f s, Retry-After %d s (draining the queue: %.1f s)\n", mean,
                e.retry_after_seconds, 4 * mean);
  }
  for (const auto& id : ids) service.dismiss(id);
}

// The lease thread renews the leases it saw a moment before; a job claimed meanwhile was not
// among them and must not be taken for lost (issue 34: 14 of 16,500 small jobs from 8 clients
// were abandoned that way and ran again only when their 10 s lease expired). A 1 s lease
// renews every 333 ms, 30 times as often per job as the 10 s default, so thousands of claims
// fall near a renewal: every job must run once (a job abandoned by its own replica runs a
// second time, after its lease expires). The time from submission to end beyond the solve is
// printed, not judged: alone it stays under 0.1 s, but a full parallel test run on the shared
// 2 cores held some jobs 1.6 s in the queue, longer than a 1 s lease's expiry would. The
// 20,000 jobs of the load run: bench/lease_race.py, bench/results/hostile-clients.md.
TEST(JobService, ThousandsOfShortJobsFromEightClientsWithAShortLeaseEachRunOnce) {
  TempDir dir;
  SqliteStore store((dir.path() / "grip.sqlite").string());
  ServiceOptions options;
  options.workers = 2;
  options.queue_capacity = 100;
  options.lease_seconds = 1.0;
  JobService service(store, options);
  service.start();
  const nlohmann::json scene = beam_scene(4, 1);
  constexpr int kClients = 8, kJobs = 3000;
  std::atomic<int> next{0};
  std::vector<std::vector<std::string>> ids(kClients);
  std::vector<std::thread> clients;
  for (int c = 0; c < kClients; ++c)
    clients.emplace_back([&, c] {
      while (next.fetch_add(1) < kJobs) {  // each client: submit, follow to the end, again
        ids[c].push_back(service.submit(scene).job.record.id);
        events_to_end(service, ids[c].back());
      }
    });
  for (auto& t : clients) t.join();
  int rerun = 0, delayed = 0, jobs = 0;
  double worst = 0;
  for (const auto& client : ids)
    for (const auto& id : client) {
      ++jobs;
      const auto record = service.job(id)->record;
      EXPECT_EQ(record.status, JobStatus::successful) << id << ": " << record.message;
      if (record.attempts != 1) ++rerun;
      const auto created = server::parse_iso8601(record.created), finished = server::parse_iso8601(record.finished);
      ASSERT_TRUE(created && finished) << record.created << " " << record.finished;
      const double beyond = std::chrono::duration<double>(*finished - *created).count() - record.solve_seconds;
      worst = std::max(worst, beyond);
      if (beyond >= options.lease_seconds) ++delayed;
    }
  std::printf("[ info ] %d jobs, 8 clients: at most %.3f s from submission to end beyond the solve, %d over %.0f s\n",
              jobs, worst, delayed, options.lease_seconds);
  EXPECT_EQ(jobs, kJobs);
  EXPECT_EQ(rerun, 0) << "jobs run more than once (abandoned as lost, rerun after their lease expired)";
}

}  // namespace
}  // namespace grip::testing
