// The Store contract (server/store.hpp), held against both implementations: SQLite always,
// PostgreSQL on one throwaway cluster for the whole process, a fresh database per test
// (skipped, saying why, only where no server is installed; scripts/setup.sh installs one).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <thread>

#include "server/postgres_store.hpp"
#include "server/sqlite_store.hpp"
#include "tests/integration/grip_process.hpp"
#include "tests/support/postgres_cluster.hpp"

namespace grip::testing {
namespace {

using namespace server;
using namespace std::chrono_literals;

enum class Kind { sqlite, postgresql };

// The process's cluster, started at first use; null (and why) when none can be started.
PostgresCluster* cluster(std::string* why = nullptr) {
  static std::string reason;
  static std::unique_ptr<PostgresCluster> c = [] {
    try {
      return std::make_unique<PostgresCluster>();
    } catch (const std::exception& e) {
      reason = e.what();
      return std::unique_ptr<PostgresCluster>();
    }
  }();
  if (why) *why = reason;
  return c.get();
}

class StoreContract : public ::testing::TestWithParam<Kind> {
 protected:
  void SetUp() override {
    if (GetParam() == Kind::postgresql) {
      std::string why;
      if (!cluster(&why)) GTEST_SKIP() << "no PostgreSQL cluster could be started: " << why;
      url_ = cluster()->new_database();
    } else {
      url_ = (dir_.path() / "grip.sqlite").string();
    }
  }
  // A store on the test's database; a second call opens a second instance (for PostgreSQL a
  // second client, as another replica is).
  std::unique_ptr<Store> open() {
    if (GetParam() == Kind::postgresql) return std::make_unique<PostgresStore>(url_);
    return std::make_unique<SqliteStore>(url_);
  }
  bool shared() const { return GetParam() == Kind::postgresql; }

  TempDir dir_;
  std::string url_;
};

JobRecord new_job(const std::string& id, std::optional<std::string> key = std::nullopt) {
  JobRecord r;
  r.id = id;
  r.scene = R"({"scene":")" + id + R"("})";
  r.created = r.updated = "2025-01-01T00:00:00.000Z";
  r.message = "accepted";
  r.steps = 3;
  r.nodes = 11;
  r.idempotency_key = std::move(key);
  return r;
}

NewEvent event(const JobRecord& claimed, std::int64_t seq) {
  return {{claimed.id, claimed.generation},
          {seq, "iteration", R"({"type":"iteration","m":)" + std::to_string(seq) + "}"}};
}

JobOutcome success(std::int64_t terminal_seq) {
  JobOutcome o;
  o.status = JobStatus::successful;
  o.message = "solved 3 steps";
  o.finished = "2025-01-01T00:00:02.000Z";
  o.solve_seconds = 0.5;
  o.iterations = 7;
  o.result = R"({"steps":[]})";
  o.terminal = {terminal_seq, "job_finished", R"({"type":"job_finished"})"};
  return o;
}

TEST_P(StoreContract, InsertsReadsListsAndCounts) {
  auto store = open();
  for (int i = 0; i < 5; ++i) {
    JobRecord r = new_job("job-" + std::to_string(i), i == 2 ? std::optional<std::string>("key-2") : std::nullopt);
    store->insert_job(r);
    EXPECT_GT(r.ord, 0);
  }
  JobRecord dup = new_job("job-1");
  EXPECT_THROW(store->insert_job(dup), std::runtime_error);
  JobRecord dup_key = new_job("other", "key-2");
  EXPECT_THROW(store->insert_job(dup_key), std::runtime_error);

  const auto j = store->job("job-3", true);
  ASSERT_TRUE(j);
  EXPECT_EQ(j->status, JobStatus::accepted);
  EXPECT_EQ(j->scene, R"({"scene":"job-3"})");
  EXPECT_EQ(j->steps, 3);
  EXPECT_EQ(j->nodes, 11);
  EXPECT_EQ(j->attempts, 0);
  EXPECT_FALSE(store->job("nope", false));
  const auto by_key = store->job_by_idempotency_key("key-2");
  ASSERT_TRUE(by_key);
  EXPECT_EQ(by_key->id, "job-2");
  EXPECT_EQ(by_key->scene, R"({"scene":"job-2"})");

  const JobPage first = store->list_jobs(std::nullopt, 2, std::nullopt);
  ASSERT_EQ(first.jobs.size(), 2u);
  EXPECT_EQ(first.jobs[0].id, "job-4");
  EXPECT_EQ(first.jobs[1].id, "job-3");
  ASSERT_TRUE(first.next_before);
  const JobPage rest = store->list_jobs(std::nullopt, 10, first.next_before);
  ASSERT_EQ(rest.jobs.size(), 3u);
  EXPECT_EQ(rest.jobs[2].id, "job-0");
  EXPECT_FALSE(rest.next_before);
  EXPECT_EQ(store->count_accepted(), 5);
  EXPECT_EQ(store->count_by_status()[JobStatus::accepted], 5);
  EXPECT_TRUE(store->list_jobs(JobStatus::running, 10, std::nullopt).jobs.empty());
  EXPECT_TRUE(store->ping());
}

TEST_P(StoreContract, ClaimsTakeTheOldestJobFirstAndEachJobOnceUnderConcurrency) {
  auto a = open();
  auto b = open();  // another replica (SQLite: another handle on the same file)
  constexpr int kJobs = 60;
  for (int i = 0; i < kJobs; ++i) {
    JobRecord r = new_job("job-" + std::to_string(100 + i));
    a->insert_job(r);
  }
  const auto first = a->claim_job("r0", "2025-01-01T00:00:01.000Z", 30);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->id, "job-100");
  EXPECT_EQ(first->status, JobStatus::running);
  EXPECT_EQ(first->attempts, 1);
  EXPECT_EQ(first->generation, 1);
  EXPECT_EQ(first->owner, "r0");
  EXPECT_EQ(first->scene, R"({"scene":"job-100"})");

  std::mutex m;
  std::multiset<std::string> claimed{first->id};
  std::vector<std::thread> threads;
  for (int t = 0; t < 6; ++t)
    threads.emplace_back([&, t] {
      Store& s = t % 2 ? *b : *a;
      while (auto c = s.claim_job("r" + std::to_string(t), "2025-01-01T00:00:01.000Z", 30)) {
        std::lock_guard lock(m);
        claimed.insert(c->id);
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(claimed.size(), static_cast<size_t>(kJobs));
  EXPECT_EQ(std::set<std::string>(claimed.begin(), claimed.end()).size(), static_cast<size_t>(kJobs));
  EXPECT_EQ(a->count_accepted(), 0);
  EXPECT_EQ(b->count_by_status()[JobStatus::running], kJobs);
}

TEST_P(StoreContract, AnExpiredLeaseIsTakenOverAndTheOldRunIsFencedOut) {
  auto store = open();
  JobRecord r = new_job("job-a");
  store->insert_job(r);
  // PostgreSQL times leases by its own clock: the lease must outlast the calls before the "not
  // yet expired" check on a loaded machine (0.2 s did not, under a CI build beside a Docker build).
  const auto run1 = store->claim_job("dead", "2025-01-01T00:00:01.000Z", 2.0);
  ASSERT_TRUE(run1);
  EXPECT_TRUE(store->append_events({event(*run1, 1), event(*run1, 2), event(*run1, 3)}).empty());
  EXPECT_EQ(store->job("job-a", false)->last_seq, 3);
  EXPECT_EQ(store->requeue_expired("2025-01-01T00:00:01.100Z"), 0);  // not yet expired
  std::this_thread::sleep_for(2200ms);
  EXPECT_EQ(store->requeue_expired("2025-01-01T00:00:02.000Z"), 1);
  auto j = store->job("job-a", false);
  EXPECT_EQ(j->status, JobStatus::accepted);
  EXPECT_EQ(j->last_seq, 3);                                  // ids given out stay given out
  EXPECT_TRUE(store->events_after("job-a", 0, 100).empty());  // the interrupted run's events

  const auto run2 = store->claim_job("alive", "2025-01-01T00:00:03.000Z", 30);
  ASSERT_TRUE(run2);
  EXPECT_EQ(run2->generation, run1->generation + 1);
  EXPECT_EQ(run2->attempts, 2);
  EXPECT_EQ(run2->last_seq, 3);
  // The first run wakes up: it can write nothing.
  const auto refused = store->append_events({event(*run1, 4), event(*run2, 4), event(*run2, 5)});
  ASSERT_EQ(refused.size(), 1u);
  EXPECT_EQ(refused[0].generation, run1->generation);
  EXPECT_FALSE(store->requeue_job({"job-a", run1->generation}, "2025-01-01T00:00:04.000Z"));
  EXPECT_FALSE(store->finish_job({"job-a", run1->generation}, success(6)));
  // The current run finishes, exactly once.
  const auto finished = store->finish_job({"job-a", run2->generation}, success(6));
  ASSERT_TRUE(finished);
  EXPECT_EQ(finished->status, JobStatus::successful);
  EXPECT_FALSE(store->finish_job({"job-a", run2->generation}, success(7)));
  j = store->job("job-a", false);
  EXPECT_EQ(j->status, JobStatus::successful);
  // What finish_job says it stored is what the job reports (the scene and events at least).
  EXPECT_EQ(finished->stored_bytes, j->stored_bytes);
  EXPECT_GT(j->stored_bytes, 0);
  EXPECT_EQ(j->last_seq, 6);
  EXPECT_EQ(j->iterations, 7);
  EXPECT_EQ(j->owner, "alive");
  const auto events = store->events_after("job-a", 0, 100);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].seq, 4);
  EXPECT_EQ(events[2].seq, 6);
  EXPECT_EQ(events[2].type, "job_finished");
  EXPECT_EQ(store->events_after("job-a", 0, 100, "iteration").size(), 2u);
  EXPECT_EQ(store->events_after("job-a", 4, 1).at(0).seq, 5);
  EXPECT_EQ(store->result("job-a"), R"({"steps":[]})");
}

TEST_P(StoreContract, RenewedLeasesHoldAndReportDismissals) {
  auto store = open();
  JobRecord r = new_job("job-b");
  store->insert_job(r);
  const auto run = store->claim_job("me", "2025-01-01T00:00:01.000Z", 0.3);
  ASSERT_TRUE(run);
  const std::vector<Lease> mine = {{"job-b", run->generation}};
  LeaseRenewal renewal = store->renew_leases("me", mine, 60);
  ASSERT_EQ(renewal.held.size(), 1u);
  EXPECT_EQ(renewal.held[0].job_id, "job-b");
  EXPECT_EQ(renewal.held[0].generation, run->generation);
  EXPECT_TRUE(renewal.dismissed.empty());
  EXPECT_TRUE(store->renew_leases("someone-else", mine, 60).held.empty());
  EXPECT_TRUE(store->renew_leases("me", {{"job-b", run->generation + 1}}, 60).held.empty());
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(store->requeue_expired("2025-01-01T00:00:02.000Z"), 0);

  const auto [outcome, doc] = store->dismiss_job("job-b", "2025-01-01T00:00:03.000Z");
  EXPECT_EQ(outcome, DismissOutcome::dismissed);
  EXPECT_EQ(doc->status, JobStatus::dismissed);
  EXPECT_TRUE(doc->finished.empty());  // its runner finishes it
  renewal = store->renew_leases("me", mine, 60);
  ASSERT_EQ(renewal.dismissed.size(), 1u);
  // The run ends as it was about to succeed: dismissed wins, no result.
  EXPECT_EQ(store->finish_job({"job-b", run->generation}, success(1))->status, JobStatus::dismissed);
  const auto events = store->events_after("job-b", 0, 10);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].type, "job_failed");
  EXPECT_EQ(events[0].data, kDismissedEvent);
  EXPECT_FALSE(store->result("job-b"));
  EXPECT_FALSE(store->job("job-b", false)->finished.empty());
}

TEST_P(StoreContract, DismissalDecidesAtomicallyByTheStoredStatus) {
  auto store = open();
  for (const char* id : {"queued", "done", "orphan"}) {
    JobRecord r = new_job(id);
    store->insert_job(r);
  }
  // Accepted: finished at once as dismissed, with its terminal event.
  auto [o1, d1] = store->dismiss_job("queued", "2025-01-01T00:00:01.000Z");
  EXPECT_EQ(o1, DismissOutcome::dismissed);
  EXPECT_EQ(d1->status, JobStatus::dismissed);
  EXPECT_EQ(d1->finished, "2025-01-01T00:00:01.000Z");
  ASSERT_EQ(store->events_after("queued", 0, 10).size(), 1u);
  EXPECT_EQ(store->events_after("queued", 0, 10)[0].seq, 1);
  EXPECT_EQ(store->count_accepted(), 2);
  // Finished: removed with its events and result (a DELETE that races the finish sees this).
  const auto done = store->claim_job("me", "2025-01-01T00:00:02.000Z", 30);
  ASSERT_EQ(done->id, "done");
  ASSERT_EQ(store->finish_job({"done", done->generation}, success(1))->status, JobStatus::successful);
  auto [o2, d2] = store->dismiss_job("done", "2025-01-01T00:00:03.000Z");
  EXPECT_EQ(o2, DismissOutcome::removed);
  EXPECT_EQ(d2->status, JobStatus::successful);
  EXPECT_FALSE(store->job("done", false));
  EXPECT_TRUE(store->events_after("done", 0, 10).empty());
  EXPECT_FALSE(store->result("done"));
  EXPECT_EQ(store->dismiss_job("done", "2025-01-01T00:00:04.000Z").first, DismissOutcome::not_found);
  // Running, dismissed, and its runner gone: finished when its lease expires.
  const auto orphan = store->claim_job("dead", "2025-01-01T00:00:05.000Z", 0.2);
  ASSERT_EQ(orphan->id, "orphan");
  EXPECT_TRUE(store->append_events({event(*orphan, 1)}).empty());
  EXPECT_EQ(store->dismiss_job("orphan", "2025-01-01T00:00:06.000Z").first, DismissOutcome::dismissed);
  std::this_thread::sleep_for(400ms);
  EXPECT_EQ(store->requeue_expired("2025-01-01T00:00:07.000Z"), 1);
  const auto j = store->job("orphan", false);
  EXPECT_EQ(j->status, JobStatus::dismissed);
  EXPECT_EQ(j->finished, "2025-01-01T00:00:07.000Z");
  const auto events = store->events_after("orphan", 0, 10);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].seq, 2);
  EXPECT_EQ(events[1].data, kDismissedEvent);
}

TEST_P(StoreContract, ListenersHearEveryChangeFromEveryInstance) {
  auto writer = open();
  auto reader = shared() ? open() : nullptr;
  Store& listening = reader ? *reader : *writer;
  std::mutex m;
  std::condition_variable cv;
  std::vector<StoreChange> heard;
  listening.set_listener([&](const StoreChange& c) {
    std::lock_guard lock(m);
    heard.push_back(c);
    cv.notify_all();
  });
  auto wait_for = [&](StoreChange::Kind kind, const std::string& id) {
    std::unique_lock lock(m);
    return cv.wait_for(lock, 10s, [&] {
      for (const auto& c : heard)
        if (c.kind == kind && c.job_id == id) return true;
      return false;
    });
  };
  JobRecord r = new_job("job-n");
  writer->insert_job(r);
  EXPECT_TRUE(wait_for(StoreChange::job, "job-n"));
  const auto run = writer->claim_job("w", "2025-01-01T00:00:01.000Z", 30);
  ASSERT_TRUE(run);
  writer->append_events({event(*run, 1)});
  EXPECT_TRUE(wait_for(StoreChange::events, "job-n"));
  writer->dismiss_job("job-n", "2025-01-01T00:00:02.000Z");
  EXPECT_TRUE(wait_for(StoreChange::dismissed, "job-n"));
  listening.set_listener(nullptr);
}

TEST_P(StoreContract, AReopenedStoreKeepsEverythingAndFreesWhatTheDeadProcessHeld) {
  std::int64_t generation = 0;
  {
    auto store = open();
    for (const char* id : {"running", "waiting"}) {
      JobRecord r = new_job(id);
      store->insert_job(r);
    }
    const auto run = store->claim_job("old-process", "2025-01-01T00:00:01.000Z", 600);
    ASSERT_TRUE(run);
    generation = run->generation;
    store->append_events({event(*run, 1), event(*run, 2)});
  }
  auto store = open();
  // Embedded (one process per file): opening the file frees every lease at once. Shared:
  // other replicas' leases hold until they expire, unless the owner's name starts again.
  if (shared()) {
    EXPECT_EQ(store->requeue_expired("2025-01-01T00:00:04.000Z"), 0);
    store->release_leases("old-process");
  }
  EXPECT_EQ(store->requeue_expired("2025-01-01T00:00:05.000Z"), 1);
  const auto j = store->job("running", false);
  EXPECT_EQ(j->status, JobStatus::accepted);
  EXPECT_EQ(j->last_seq, 2);
  EXPECT_EQ(store->count_accepted(), 2);
  const auto again = store->claim_job("new-process", "2025-01-01T00:00:06.000Z", 30);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->id, "running");  // still the oldest
  EXPECT_EQ(again->generation, generation + 1);
  EXPECT_EQ(again->attempts, 2);
}

// Runs job `id` to its end: claimed, `events` events, finished as `status` at `finished` with
// `result` (dismissed: dismissed first while running).
void run_to_end(Store& store, const std::string& id, JobStatus status, const std::string& finished,
                std::optional<std::string> result, int events = 2, std::vector<std::string> meshes = {}) {
  JobRecord r = new_job(id);
  r.meshes = std::move(meshes);
  if (!r.meshes.empty()) r.created = r.updated = finished;
  store.insert_job(r);
  const auto run = store.claim_job("me", finished, 30);
  ASSERT_TRUE(run);
  ASSERT_EQ(run->id, id);
  std::vector<NewEvent> list;
  for (int e = 1; e <= events; ++e) list.push_back(event(*run, e));
  store.append_events(list);
  if (status == JobStatus::dismissed) store.dismiss_job(id, finished);
  JobOutcome o = success(events + 1);
  o.status = status == JobStatus::dismissed ? JobStatus::successful : status;
  o.finished = finished;
  o.result = std::move(result);
  ASSERT_TRUE(store.finish_job({id, run->generation}, o));
}

TEST_P(StoreContract, ResultsAreStoredAsBytesAndEachFinishedJobCountsItsStoredBytes) {
  auto store = open();
  // Compressed results hold any byte, 0 included.
  std::string bytes = "\x1f\x8b";
  for (int i = 0; i < 256; ++i) bytes += static_cast<char>(i);
  run_to_end(*store, "job-a", JobStatus::successful, "2025-01-01T00:00:02.000Z", bytes);
  EXPECT_EQ(store->result("job-a"), bytes);
  const auto j = store->job("job-a", true);
  ASSERT_TRUE(j);
  // Its scene, its 2 events and terminal event, its result.
  const std::int64_t expected =
      static_cast<std::int64_t>(j->scene.size() + event(*j, 1).event.data.size() + event(*j, 2).event.data.size() +
                                success(3).terminal.data.size() + bytes.size());
  EXPECT_EQ(j->stored_bytes, expected);
  EXPECT_GT(store->disk_bytes(), 0);
}

TEST_P(StoreContract, RetentionRemovesTheFinishedJobsBeyondItsBoundsDismissedFirst) {
  auto store = open();
  // 6 finished jobs a second apart (a2 dismissed), one still accepted.
  const std::vector<std::pair<std::string, JobStatus>> jobs = {
      {"a0", JobStatus::successful}, {"a1", JobStatus::failed},     {"a2", JobStatus::dismissed},
      {"a3", JobStatus::successful}, {"a4", JobStatus::successful}, {"a5", JobStatus::successful}};
  for (size_t i = 0; i < jobs.size(); ++i)
    run_to_end(*store, jobs[i].first, jobs[i].second, "2025-01-01T00:00:0" + std::to_string(i) + ".000Z",
               std::string(1000, 'r'));
  JobRecord waiting = new_job("waiting");
  store->insert_job(waiting);
  auto ids = [&] {
    std::set<std::string> out;
    for (const JobRecord& r : store->list_jobs(std::nullopt, 100, std::nullopt).jobs) out.insert(r.id);
    return out;
  };
  EXPECT_EQ(store->prune(Retention{}, "2025-01-01T01:00:00.000Z"), 0);  // no bound: nothing
  // At most 4 finished jobs: the dismissed one goes first, then the oldest.
  EXPECT_EQ(store->prune(Retention{0, 4, 0}, "2025-01-01T00:00:10.000Z"), 2);
  EXPECT_EQ(ids(), (std::set<std::string>{"a1", "a3", "a4", "a5", "waiting"}));
  EXPECT_FALSE(store->result("a0"));
  EXPECT_TRUE(store->events_after("a0", 0, 100).empty());
  // Finished more than 4.5 s before 00:00:08 (before 00:03.5): a1 (00:01) and a3 (00:03).
  EXPECT_EQ(store->prune(Retention{4.5, 0, 0}, "2025-01-01T00:00:08.000Z"), 2);
  EXPECT_EQ(ids(), (std::set<std::string>{"a4", "a5", "waiting"}));
  // Room for one job's stored bytes: the newest stays.
  const std::int64_t one = store->job("a5", false)->stored_bytes;
  EXPECT_EQ(store->prune(Retention{0, 0, one + 10}, "2025-01-01T00:00:08.000Z"), 1);
  EXPECT_EQ(ids(), (std::set<std::string>{"a5", "waiting"}));
  EXPECT_EQ(store->count_accepted(), 1);  // unfinished jobs are never removed
}

MeshRecord mesh_record(const std::string& id, const std::string& created) {
  return {id, 1000, 0, R"({"nodes":4})", created};
}

TEST_P(StoreContract, MeshesAreStoredOnceAndKeptWhileAStoredJobUsesThem) {
  auto store = open();
  auto other = open();                    // another replica
  std::string data = "\x28\xb5\x2f\xfd";  // any byte, 0 included
  for (int i = 0; i < 256; ++i) data += static_cast<char>(i);
  EXPECT_TRUE(store->put_mesh(mesh_record("m-a", "2025-01-01T00:00:00.000Z"), data));
  EXPECT_FALSE(other->put_mesh(mesh_record("m-a", "2025-01-01T00:00:09.000Z"), "other bytes"));  // stored once
  const auto a = other->mesh("m-a");
  ASSERT_TRUE(a);
  EXPECT_EQ(a->bytes, 1000);
  EXPECT_EQ(a->stored, static_cast<std::int64_t>(data.size()));
  EXPECT_EQ(a->summary, R"({"nodes":4})");
  EXPECT_EQ(a->created, "2025-01-01T00:00:00.000Z");  // the first upload's
  EXPECT_EQ(other->mesh_data("m-a"), data);
  EXPECT_EQ(store->mesh_totals(), (std::pair<std::int64_t, std::int64_t>{1, static_cast<std::int64_t>(data.size())}));
  EXPECT_FALSE(store->mesh("nope"));
  EXPECT_FALSE(store->mesh_data("nope"));
  EXPECT_EQ(store->remove_mesh("nope"), MeshRemoval::not_found);

  // A job that uses it keeps it, also once finished, until the job is removed.
  run_to_end(*store, "job-a", JobStatus::successful, "2025-01-01T00:00:01.000Z", "r", 2, {"m-a"});
  EXPECT_EQ(other->remove_mesh("m-a"), MeshRemoval::in_use);
  EXPECT_EQ(store->dismiss_job("job-a", "2025-01-01T00:00:02.000Z").first, DismissOutcome::removed);
  EXPECT_EQ(other->remove_mesh("m-a"), MeshRemoval::removed);
  EXPECT_FALSE(store->mesh("m-a"));
  EXPECT_EQ(store->mesh_totals().first, 0);
}

TEST_P(StoreContract, RetentionRemovesMeshesNoStoredJobUsesOnceTheyAreOlderThanItsAgeBound) {
  auto store = open();
  // b: uploaded at 00:00, named by job-b at 00:05; c: uploaded at 00:00, never named; d: at 00:06.
  for (const auto& [id, created] :
       std::vector<std::pair<std::string, std::string>>{{"m-b", "2025-01-01T00:00:00.000Z"},
                                                        {"m-c", "2025-01-01T00:00:00.000Z"},
                                                        {"m-d", "2025-01-01T00:00:06.000Z"}})
    ASSERT_TRUE(store->put_mesh(mesh_record(id, created), "bytes of " + id));
  run_to_end(*store, "job-b", JobStatus::successful, "2025-01-01T00:00:05.000Z", "r", 2, {"m-b"});
  auto meshes = [&] {
    std::set<std::string> out;
    for (const char* id : {"m-b", "m-c", "m-d"})
      if (store->mesh(id)) out.insert(id);
    return out;
  };
  // Without an age bound no mesh goes.
  EXPECT_EQ(store->prune(Retention{0, 100, 0}, "2025-01-01T01:00:00.000Z"), 0);
  EXPECT_EQ(meshes(), (std::set<std::string>{"m-b", "m-c", "m-d"}));
  // Kept 2 s, at 00:07: job-b (finished 00:05) stays and keeps m-b; m-c goes; m-d is recent.
  EXPECT_EQ(store->prune(Retention{2, 0, 0}, "2025-01-01T00:00:07.000Z"), 0);
  EXPECT_EQ(meshes(), (std::set<std::string>{"m-b", "m-d"}));
  // At 00:20: job-b goes, and with it the last use of m-b; m-d too.
  EXPECT_EQ(store->prune(Retention{2, 0, 0}, "2025-01-01T00:00:20.000Z"), 1);
  EXPECT_EQ(meshes(), (std::set<std::string>{}));
}

TEST_P(StoreContract, PruningHandsTheSpaceBackToTheFileSystem) {
  if (shared()) GTEST_SKIP() << "PostgreSQL's space is its autovacuum's (reused, not returned)";
  auto store = open();
  const std::string big(200000, 'x');  // incompressible to SQLite: 200 KB a job
  for (int i = 0; i < 50; ++i)
    run_to_end(*store, "job-" + std::to_string(i), JobStatus::successful, "2025-01-01T00:00:00.000Z", big);
  const std::int64_t full = store->disk_bytes();
  EXPECT_GT(full, 50 * 200000);
  EXPECT_EQ(store->prune(Retention{0, 5, 0}, "2025-01-01T00:00:01.000Z"), 45);
  EXPECT_LT(store->disk_bytes(), full / 5);
}

TEST_P(StoreContract, StudiesAreStoredOnceAndReadByEveryInstance) {
  auto store = open();
  auto other = open();  // another replica
  const StudyRecord study{"study-a", "2025-01-01T00:00:00.000Z", R"({"levels":[{"job":"job-a"}]})"};
  store->insert_study(study);
  EXPECT_THROW(other->insert_study(study), std::runtime_error);
  const auto read = other->study("study-a");
  ASSERT_TRUE(read);
  EXPECT_EQ(read->id, "study-a");
  EXPECT_EQ(read->created, study.created);
  EXPECT_EQ(read->document, study.document);
  EXPECT_FALSE(store->study("nope"));
  EXPECT_TRUE(other->remove_study("study-a"));
  EXPECT_FALSE(store->remove_study("study-a"));
  EXPECT_FALSE(store->study("study-a"));
}

INSTANTIATE_TEST_SUITE_P(Stores, StoreContract, ::testing::Values(Kind::sqlite, Kind::postgresql),
                         [](const auto& info) {
                           return info.param == Kind::sqlite ? std::string("sqlite") : std::string("postgresql");
                         });

// The database going away and coming back, seen by the store: calls fail fast with
// StoreUnavailable (no hang), and everything committed before is there afterwards.
// The SQLite store's writer is opened with synchronous=NORMAL (its claims, renewals, event
// batches and submissions commit without fsync); a job's end commits FULL. A transaction of
// the other kind switches the connection for its commit and back, every time (a kept PRAGMA
// statement acts when SQLite prepares it again, which it does at each run).
int synchronous_setting(Database& db) {  // 1 NORMAL, 2 FULL
  auto st = db.prepare("PRAGMA synchronous");
  st.step();
  return static_cast<int>(st.int64(0));
}

TEST(SqliteTransaction, CommitsWithItsOwnSyncSettingAndGivesTheConnectionsBack) {
  TempDir dir;
  for (const char* own : {"NORMAL", "FULL"}) {
    Database db((dir.path() / (std::string(own) + ".sqlite")).string(), 5000, own);
    db.exec("CREATE TABLE t (x INTEGER)");
    const int home = std::string(own) == "FULL" ? 2 : 1;
    ASSERT_EQ(synchronous_setting(db), home) << own;
    for (int round = 0; round < 3; ++round)
      for (const auto sync : {Transaction::Sync::full, Transaction::Sync::relaxed}) {
        const int inside = sync == Transaction::Sync::full ? 2 : 1;
        {
          Transaction tx(db, sync);
          db.prepare("INSERT INTO t VALUES (?)").bind(1, round).run();
          EXPECT_EQ(synchronous_setting(db), inside) << own << " round " << round;
          tx.commit();
        }
        EXPECT_EQ(synchronous_setting(db), home) << own << " after a commit, round " << round;
        {
          Transaction tx(db, sync);
          EXPECT_EQ(synchronous_setting(db), inside) << own << " round " << round;
        }  // rolled back
        EXPECT_EQ(synchronous_setting(db), home) << own << " after a rollback, round " << round;
      }
    auto count = db.prepare("SELECT count(*) FROM t");
    count.step();
    EXPECT_EQ(count.int64(0), 6) << own;
  }
}

TEST(PostgresStoreOutage, CallsFailFastWhileTheDatabaseIsDownAndEverythingIsBackAfter) {
  std::string why;
  PostgresCluster* cluster = grip::testing::cluster(&why);
  if (!cluster) GTEST_SKIP() << "no PostgreSQL cluster could be started: " << why;
  PostgresStore store(cluster->new_database());
  JobRecord r = new_job("kept");
  store.insert_job(r);
  cluster->stop();
  EXPECT_FALSE(store.ping());
  for (int i = 0; i < 20; ++i) {
    JobRecord more = new_job("lost-" + std::to_string(i));
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_THROW(store.insert_job(more), StoreUnavailable);
    EXPECT_THROW(store.job("kept", false), StoreUnavailable);
    // A hang would be seconds per call (the connect timeout is 3 s).
    EXPECT_LT(std::chrono::steady_clock::now() - t0, 8s);
  }
  cluster->start();
  bool back = false;
  for (int i = 0; i < 100 && !back; ++i) {
    back = store.ping();
    if (!back) std::this_thread::sleep_for(100ms);
  }
  ASSERT_TRUE(back);
  EXPECT_EQ(store.job("kept", false)->status, JobStatus::accepted);
  EXPECT_EQ(store.count_accepted(), 1);
}

}  // namespace
}  // namespace grip::testing
