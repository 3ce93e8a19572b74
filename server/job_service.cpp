#include "server/job_service.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <tuple>

#include "server/compression.hpp"
#include "server/util.hpp"
#include "solver/io/result.hpp"
#include "solver/model/number_text.hpp"

namespace grip::server {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

bool is_terminal_event(const std::string& type) { return type == "job_finished" || type == "job_failed"; }

struct JobService::ActiveJob {
  explicit ActiveJob(Lease l) : lease(std::move(l)), id(lease.job_id) {}
  const Lease lease;
  const std::string& id;
  const Clock::time_point started = Clock::now();
  std::atomic<bool> dismissed{false};
  std::atomic<bool> lost{false};          // the lease went to another run: write nothing more
  std::atomic<bool> finishing{false};     // its end is being stored: a renewal may miss it
  std::atomic<std::int64_t> last_seq{0};  // the last event sequence number given out
  std::int64_t stored_seq = 0;            // the last one stored (guarded by events_mutex_)
  std::mutex progress_mutex;
  std::optional<Progress> progress;  // while running
};

namespace {

// Upper bounds of grip_job_stored_bytes' buckets (+Inf last).
const std::vector<double> kStoredBytesBuckets = {4096,    16384,   65536,    262144,
                                                 1048576, 4194304, 16777216, std::numeric_limits<double>::infinity()};

// A run that did not succeed: its status, message (the result's reason where there is one)
// and failure kind.
void failed(JobOutcome& o, FailureKind kind, std::string message, int step = 0) {
  o.status = kind == FailureKind::dismissed ? JobStatus::dismissed : JobStatus::failed;
  o.message = std::move(message);
  o.failure_kind = std::string(to_string(kind));
  o.failure_step = step;
}

// The outcome's log line (one format for every end of a run; a failure at warning).
void log_outcome(const std::string& id, JobStatus status, std::int64_t iterations, const std::string& message,
                 double seconds) {
  spdlog::log(status == JobStatus::successful ? spdlog::level::info : spdlog::level::warn,
              "job {} {} in {:.3f} s: {} contact iterations; {}", id, to_string(status), seconds, iterations, message);
}

StoredEvent stored(std::int64_t seq, const json& event) {
  return {seq, event.at("type").get<std::string>(), event.dump()};
}

// The fewest nodes a generated mesh can have: a rectangle {"divisions": [a, b]} (a + 1)(b + 1);
// a half-disc {"divisions": [ns, nt]} (ns + 1)(nt - m + 1) + (ns - 2 m - 1) m for a ring of m
// rows (plane_mesh.hpp), fewest at the most rows it can have, min(ns / 2, nt) - 1. Building a
// mesh far over the node limit before counting its nodes held the HTTP thread for minutes (a
// 1000 x 1000 rectangle).
std::optional<std::int64_t> least_generated_nodes(const json& scene) {
  if (!scene.is_object() || !scene.contains("body") || !scene["body"].is_object()) return std::nullopt;
  const json& body = scene["body"];
  if (!body.contains("mesh") || !body["mesh"].is_object()) return std::nullopt;
  for (const char* kind : {"rectangle", "half_disc"}) {
    const auto it = body["mesh"].find(kind);
    if (it == body["mesh"].end() || !it->is_object() || !it->contains("divisions")) continue;
    const json& d = (*it)["divisions"];
    if (!d.is_array() || d.size() != 2 || !d[0].is_number_integer() || !d[1].is_number_integer()) continue;
    const std::int64_t a = d[0].get<std::int64_t>(), b = d[1].get<std::int64_t>();
    if (a < 1 || b < 1 || a > 1000000 || b > 1000000) continue;  // the schema's to report
    if (std::string(kind) == "rectangle") return (a + 1) * (b + 1);
    const std::int64_t m = std::max<std::int64_t>(0, std::min(a / 2, b) - 1);
    return (a + 1) * (b - m + 1) + std::max<std::int64_t>(0, a - 2 * m - 1) * m;
  }
  return std::nullopt;
}

}  // namespace

JobService::JobService(Store& store, ServiceOptions options)
    : store_(store), options_(std::move(options)), meshes_(store) {
  if (options_.workers <= 0) options_.workers = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  options_.queue_capacity = std::max(1, options_.queue_capacity);
  options_.event_buffer = std::max<std::size_t>(16, options_.event_buffer);
  if (!(options_.lease_seconds > 0)) options_.lease_seconds = 10;
  if (options_.replica.empty()) options_.replica = default_replica_name();
}

JobService::~JobService() {
  if (started_) shutdown(std::chrono::milliseconds(0));
  store_.set_listener(nullptr);
}

void JobService::start() {
  store_.set_listener([this](const StoreChange& c) { on_change(c); });
  store_.release_leases(options_.replica);
  const int requeued = store_.requeue_expired(now_iso8601());
  if (requeued > 0) spdlog::info("requeued {} interrupted job(s)", requeued);
  {
    std::lock_guard lock(mutex_);
    work_hints_ = options_.workers;  // look for accepted jobs at once
  }
  writer_ = std::thread([this] { writer_loop(); });
  lease_thread_ = std::thread([this] { lease_loop(); });
  for (int i = 0; i < options_.workers; ++i) workers_.emplace_back([this] { worker_loop(); });
  if (options_.retention.any()) pruner_ = std::make_unique<Pruner>(store_, options_.retention, options_.prune_interval);
  started_ = true;
  spdlog::info("replica {}: lease {} s", options_.replica, options_.lease_seconds);
}

void JobService::on_change(const StoreChange& change) {
  if (change.kind == StoreChange::job) {
    {
      std::lock_guard lock(mutex_);
      ++work_hints_;
    }
    work_cv_.notify_one();
  }
  if (change.kind == StoreChange::dismissed) {
    std::shared_ptr<ActiveJob> job;
    {
      std::lock_guard lock(mutex_);
      const auto it = active_.find(change.job_id);
      if (it != active_.end()) job = it->second;
    }
    if (job) hear_dismissal(*job, "notification");
  }
  // The streams are woken after the lock is released: woken under it, each would block on it
  // at once (a futex wait and wake more per stream and event).
  std::vector<std::shared_ptr<Watch>> woken;
  {
    std::lock_guard lock(watch_mutex_);
    ++announcements_;
    auto wake = [&](const std::shared_ptr<Watch>& w) {
      w->changes = announcements_;
      woken.push_back(w);
    };
    if (change.job_id.empty()) {
      for (auto& [id, w] : watches_) wake(w);
    } else if (const auto it = watches_.find(change.job_id); it != watches_.end()) {
      wake(it->second);
    }
  }
  for (const auto& w : woken) w->cv.notify_all();
}

void JobService::hear_dismissal(ActiveJob& job, const char* how) {
  if (job.dismissed.exchange(true)) return;
  std::int64_t at = 0;
  {
    std::lock_guard lock(job.progress_mutex);
    if (job.progress) at = job.progress->iterations;
  }
  // The run stops before its next contact iteration (its stop request reads the flag).
  spdlog::info("job {}: dismissal heard at contact iteration {} ({})", job.id, at, how);
}

bool JobService::ready() {
  if (!started_ || draining_) return false;
  return store_.ping();
}

namespace {

// read_scene with the uploaded meshes (without its schema stage for a stored scene, checked
// when it was submitted); `use` gets the ids it named. Throws SceneErrors, or
// StoreUnavailable when a mesh could not be loaded for it.
Scene read_with_meshes(MeshLibrary& meshes, const json& scene, MeshUse& use, bool stored = false) {
  try {
    return stored ? read_checked_scene(scene, meshes.resolver(use)) : read_scene(scene, meshes.resolver(use));
  } catch (const SceneErrors&) {
    if (use.unavailable) std::rethrow_exception(use.unavailable);
    throw;
  }
}

}  // namespace

std::optional<SubmitResult> JobService::replay(const std::optional<std::string>& key, const std::string& scene) {
  if (!key) return std::nullopt;
  auto existing = store_.job_by_idempotency_key(*key);
  if (!existing) return std::nullopt;
  if (existing->scene != scene)
    throw IdempotencyConflict("Idempotency-Key '" + *key + "' was used before with a different scene");
  existing->scene.clear();
  return SubmitResult{JobView{*existing, std::nullopt}, true};
}

JobService::Checked JobService::check_scene(const json& scene_json) {
  const JobLimits& lim = options_.limits;
  if (const auto least = least_generated_nodes(scene_json); least && *least > lim.max_nodes)
    throw SceneErrors(std::vector<SceneIssue>{{"/body/mesh", "the body has at least " + std::to_string(*least) +
                                                                 " nodes; this service takes at most " +
                                                                 std::to_string(lim.max_nodes)}});
  Checked size;
  MeshUse meshes;
  {
    const Scene scene = read_with_meshes(meshes_, scene_json, meshes);  // throws SceneErrors
    size.nodes = scene.problem.body->node_count();
    size.steps = static_cast<int>(scene.steps.size());
  }
  size.meshes = std::move(meshes.ids);
  std::vector<SceneIssue> issues;
  if (size.nodes > lim.max_nodes)
    issues.push_back({"/body/mesh", "the body has " + std::to_string(size.nodes) +
                                        " nodes; this service takes at most " + std::to_string(lim.max_nodes)});
  if (size.steps > lim.max_steps)
    issues.push_back({scene_json.contains("stages") ? "/stages" : "/steps",
                      "the scene has " + std::to_string(size.steps) + " load steps; this service takes at most " +
                          std::to_string(lim.max_steps)});
  if (!issues.empty()) throw SceneErrors(std::move(issues));
  return size;
}

int JobService::check(const json& scene) { return check_scene(scene).nodes; }

SubmitResult JobService::submit(const json& scene_json, const std::optional<std::string>& idempotency_key,
                                const std::string& request_id) {
  if (draining_) throw ShuttingDown();
  const std::string canonical = scene_json.dump();
  if (auto earlier = replay(idempotency_key, canonical)) return *earlier;
  Checked size = check_scene(scene_json);

  const std::int64_t waiting = store_.count_accepted();
  {
    std::lock_guard lock(mutex_);
    if (waiting + reserved_ >= options_.queue_capacity) throw QueueFull(retry_after_seconds());
    ++reserved_;
  }
  struct Unreserve {
    JobService& s;
    ~Unreserve() {
      std::lock_guard lock(s.mutex_);
      --s.reserved_;
    }
  } unreserve{*this};
  JobRecord rec;
  rec.id = new_job_id();
  rec.status = JobStatus::accepted;
  rec.scene = canonical;
  rec.created = rec.updated = now_iso8601();
  rec.message = "accepted";
  rec.steps = size.steps;
  rec.nodes = size.nodes;
  rec.idempotency_key = idempotency_key;
  rec.request_id = request_id;
  rec.meshes = std::move(size.meshes);
  try {
    store_.insert_job(rec);
  } catch (const StoreUnavailable&) {
    throw;
  } catch (...) {
    // A concurrent submission with the same key won the race: answer as a replay.
    if (auto earlier = replay(idempotency_key, canonical)) return *earlier;
    throw;
  }
  spdlog::info("job {} accepted: {} nodes, {} steps (request {})", rec.id, size.nodes, size.steps,
               request_id.empty() ? "-" : request_id);
  rec.scene.clear();
  return {JobView{rec, std::nullopt}, false};
}

std::vector<JobView> JobService::with_progress(std::vector<JobRecord> records) {
  std::vector<JobView> out;
  out.reserve(records.size());
  for (auto& r : records) {
    JobView v{std::move(r), std::nullopt};
    if (v.record.status == JobStatus::running) {
      std::shared_ptr<ActiveJob> a;
      {
        std::lock_guard lock(mutex_);
        auto it = active_.find(v.record.id);
        if (it != active_.end()) a = it->second;
      }
      if (a) {
        std::lock_guard lock(a->progress_mutex);
        v.progress = a->progress;
      }
    }
    out.push_back(std::move(v));
  }
  return out;
}

std::optional<JobView> JobService::job(const std::string& id) {
  auto rec = store_.job(id);
  if (!rec) return std::nullopt;
  return with_progress({std::move(*rec)}).front();
}

JobPage JobService::list(std::optional<JobStatus> status, int limit, std::optional<std::int64_t> before) {
  return store_.list_jobs(status, limit, before);
}

std::pair<DismissOutcome, std::optional<JobView>> JobService::dismiss(const std::string& id) {
  // The store decides atomically (a job that has just finished is removed, not "dismissed");
  // the run, on whichever process, hears of it through the listener.
  auto [outcome, rec] = store_.dismiss_job(id, now_iso8601());
  if (outcome == DismissOutcome::not_found || !rec) return {DismissOutcome::not_found, std::nullopt};
  spdlog::info("job {} {}", id, outcome == DismissOutcome::removed ? "removed" : "dismissed");
  return {outcome, JobView{std::move(*rec), std::nullopt}};
}

EventBatch JobService::wait_events(const std::string& id, std::int64_t after, std::chrono::milliseconds wait, int limit,
                                   std::uint64_t* seen_before) {
  const auto deadline = Clock::now() + wait;
  std::shared_ptr<Watch> watch;
  bool read_first = true;
  {
    std::lock_guard lock(watch_mutex_);
    auto& w = watches_[id];
    if (!w) {
      w = std::make_shared<Watch>();
      w->changes = announcements_;
    }
    watch = w;
    ++watch->waiters;
    // Nothing announced since a read that found everything: wait for the next announcement.
    read_first = !seen_before || *seen_before == 0 || watch->changes != *seen_before;
  }
  if (seen_before) *seen_before = 0;
  const auto unwatch = [&](void*) {
    std::lock_guard lock(watch_mutex_);
    const auto it = watches_.find(id);
    if (--watch->waiters == 0 && it != watches_.end() && it->second == watch) watches_.erase(it);
  };
  const std::unique_ptr<void, decltype(unwatch)> watching(watch.get(), unwatch);
  if (!read_first) {
    std::unique_lock lock(watch_mutex_);
    const auto seen = watch->changes;
    const bool woke = watch->cv.wait_until(lock, deadline, [&] { return watch->changes != seen || draining_.load(); });
    if (!woke || draining_) return {};
  }
  while (true) {
    std::uint64_t seen = 0;
    {
      std::lock_guard lock(watch_mutex_);
      seen = watch->changes;
    }
    try {
      EventBatch batch;
      batch.events = store_.events_after(id, after, limit);
      if (!batch.events.empty()) {
        batch.ended = is_terminal_event(batch.events.back().type);
        if (seen_before && !batch.ended && static_cast<int>(batch.events.size()) < limit) *seen_before = seen;
        return batch;
      }
      const auto rec = store_.job(id);
      if (!rec) return {false, {}, false};
      if (is_finished(rec->status) && !rec->finished.empty()) {
        // Finished between the two reads: its terminal event (stored with the status) may be
        // new. Read once more; nothing new means the stream had everything already.
        batch.events = store_.events_after(id, after, limit);
        batch.ended = batch.events.empty() || is_terminal_event(batch.events.back().type);
        return batch;
      }
    } catch (const StoreUnavailable&) {
      // Nothing to read now; the stream waits (and pings) until the store is back.
      std::unique_lock lock(events_mutex_);
      stored_cv_.wait_until(lock, deadline, [&] { return draining_.load(); });
      return {};
    }
    std::unique_lock lock(watch_mutex_);
    const bool woke = watch->cv.wait_until(lock, deadline, [&] { return watch->changes != seen || draining_.load(); });
    if (!woke || draining_) return {};
  }
}

std::vector<StoredEvent> JobService::events(const std::string& id, std::int64_t after, int limit,
                                            std::string_view type) {
  return store_.events_after(id, after, limit, type);
}

std::optional<std::string> JobService::result(const std::string& id) { return store_.result(id); }

ServiceStats JobService::stats() {
  ServiceStats s;
  {
    std::lock_guard lock(mutex_);
    s.running = running_;
    s.workers = options_.workers;
    s.solve_seconds = solve_seconds_;
    s.iterations = iterations_;
  }
  {
    std::lock_guard lock(events_mutex_);
    s.events = events_stored_;
    s.events_waiting = pending_.size();
  }
  s.db_traffic = store_.traffic();
  s.jobs = store_.count_by_status();
  s.retention = options_.retention;
  s.pruned = pruner_ ? pruner_->pruned() : 0;
  s.disk_bytes = store_.disk_bytes();
  std::tie(s.meshes, s.mesh_bytes) = store_.mesh_totals();
  {
    std::lock_guard lock(mutex_);
    std::int64_t below = 0;
    for (size_t b = 0; b < kStoredBytesBuckets.size(); ++b) {
      below += b < stored_bytes_counts_.size() ? stored_bytes_counts_[b] : 0;
      s.stored_bytes_buckets.emplace_back(kStoredBytesBuckets[b], below);
    }
    s.stored_bytes_sum = stored_bytes_sum_;
    s.stored_bytes_count = stored_bytes_count_;
  }
  const auto it = s.jobs.find(JobStatus::accepted);
  s.queue_depth = it == s.jobs.end() ? 0 : static_cast<std::size_t>(it->second);
  return s;
}

void JobService::write_job_metrics(std::ostream& os) const {
  os << "# HELP grip_job_queue_wait_seconds From a job's acceptance to its first claim, for jobs claimed here.\n"
     << "# TYPE grip_job_queue_wait_seconds histogram\n";
  queue_wait_.write(os, "grip_job_queue_wait_seconds", "");
  os << "# HELP grip_job_run_seconds From a job's claim to its stored outcome, by outcome, for runs here.\n"
     << "# TYPE grip_job_run_seconds histogram\n";
  std::lock_guard lock(mutex_);
  for (const auto& [outcome, h] : run_seconds_by_outcome_)
    h.write(os, "grip_job_run_seconds", "outcome=\"" + outcome + "\"");
}

int JobService::retry_after_seconds() const {
  // Time until a worker frees (mutex_ held): the mean run less the longest-running job's time
  // so far; without a run here, one mean run.
  const double mean = finished_runs_ ? solve_seconds_ / static_cast<double>(finished_runs_) : 1.0;
  double wait = mean;
  for (const auto& [id, job] : active_) {
    const double elapsed = std::chrono::duration<double>(Clock::now() - job->started).count();
    wait = std::min(wait, std::max(0.0, mean - elapsed));
  }
  return std::clamp(static_cast<int>(std::ceil(wait)), 1, 300);
}

void JobService::begin_drain() {
  draining_ = true;
  {
    std::lock_guard lock(events_mutex_);
    stored_cv_.notify_all();
  }
  std::lock_guard lock(watch_mutex_);
  for (auto& [id, w] : watches_) w->cv.notify_all();
}

void JobService::shutdown(std::chrono::milliseconds grace) {
  if (!started_.exchange(false)) return;
  begin_drain();
  {
    std::unique_lock lock(mutex_);
    stop_workers_ = true;
    work_cv_.notify_all();
    if (running_ > 0) spdlog::info("waiting up to {:.1f} s for {} running job(s)", grace.count() / 1000.0, running_);
    if (!idle_cv_.wait_for(lock, grace, [&] { return running_ == 0; })) {
      spdlog::warn("grace period over: stopping {} running job(s); they run again later", running_);
      abort_runs_ = true;
    }
  }
  {
    std::lock_guard lock(events_mutex_);
    room_cv_.notify_all();
    stored_cv_.notify_all();
  }
  for (auto& w : workers_) w.join();
  workers_.clear();
  {
    std::lock_guard lock(events_mutex_);
    stop_writer_ = true;
  }
  writer_cv_.notify_all();
  if (writer_.joinable()) writer_.join();
  lease_cv_.notify_all();
  if (lease_thread_.joinable()) lease_thread_.join();
  pruner_.reset();
}

void JobService::worker_loop() {
  while (true) {
    {
      std::unique_lock lock(mutex_);
      // Announcements wake a worker; the timeout covers any that were missed (the store was
      // unreachable when they were sent).
      work_cv_.wait_for(lock, std::chrono::seconds(5), [&] { return stop_workers_ || work_hints_ > 0; });
      if (stop_workers_) return;
      work_hints_ = 0;
    }
    std::optional<JobRecord> claimed;
    try {
      claimed = store_.claim_job(options_.replica, now_iso8601(), options_.lease_seconds);
    } catch (const std::exception& e) {
      spdlog::warn("cannot claim a job: {}", e.what());
      continue;
    }
    if (!claimed) continue;
    if (const auto created = parse_iso8601(claimed->created); created && claimed->attempts == 1)
      queue_wait_.observe(
          std::max(0.0, std::chrono::duration<double>(std::chrono::system_clock::now() - *created).count()));
    auto job = std::make_shared<ActiveJob>(Lease{claimed->id, claimed->generation});
    {
      std::lock_guard lock(mutex_);
      active_[job->id] = job;
      ++running_;
      ++work_hints_;  // there may be more: let another idle worker look
    }
    work_cv_.notify_one();
    try {
      run_job(job, *claimed);
    } catch (const std::exception& e) {
      spdlog::error("job {}: {}", job->id, e.what());
      try {
        JobOutcome o;
        failed(o, FailureKind::exception, std::string("internal error: ") + e.what());
        o.finished = now_iso8601();
        finish(job, std::move(o), job->last_seq);
      } catch (const std::exception& again) {
        spdlog::error("job {} stays unfinished until its lease expires: {}", job->id, again.what());
      }
    }
    {
      std::lock_guard lock(mutex_);
      active_.erase(job->id);
      --running_;
    }
    idle_cv_.notify_all();
    if (claimed->idempotency_key) {
      std::lock_guard lock(finished_hook_mutex_);
      try {
        if (finished_hook_) finished_hook_(*claimed->idempotency_key);
      } catch (const std::exception& e) {
        spdlog::warn("job {}: after its run: {}", job->id, e.what());
      }
    }
  }
}

void JobService::set_finished_hook(std::function<void(const std::string&)> hook) {
  std::lock_guard lock(finished_hook_mutex_);
  finished_hook_ = std::move(hook);
}

void JobService::emit(const std::shared_ptr<ActiveJob>& job, std::int64_t seq, const json& event) {
  const std::string& id = job->id;
  job->last_seq = seq;
  if (options_.event_tap) options_.event_tap(id, seq, event);
  {
    std::unique_lock lock(events_mutex_);
    // A full buffer (the store unreachable for long) pauses the run instead of growing.
    room_cv_.wait(lock, [&] { return pending_.size() < options_.event_buffer || abort_runs_ || job->lost; });
    pending_.push_back({job->lease, stored(seq, event)});
  }
  writer_cv_.notify_one();
}

void JobService::flush(const std::shared_ptr<ActiveJob>& job, std::int64_t seq) {
  std::unique_lock lock(events_mutex_);
  stored_cv_.wait(lock, [&] { return job->stored_seq >= seq || job->lost || stop_writer_; });
}

void JobService::writer_loop() {
  int failures = 0;
  std::vector<NewEvent> batch;
  while (true) {
    {
      std::unique_lock lock(events_mutex_);
      writer_cv_.wait(lock, [&] { return stop_writer_ || !pending_.empty() || !batch.empty(); });
      if (stop_writer_ && pending_.empty() && batch.empty()) return;
      batch.insert(batch.end(), std::make_move_iterator(pending_.begin()), std::make_move_iterator(pending_.end()));
      pending_.clear();
    }
    room_cv_.notify_all();
    std::vector<Lease> refused;
    try {
      refused = store_.append_events(batch);
      if (failures > 0) spdlog::info("events stored again after {} failed attempt(s)", failures);
      failures = 0;
    } catch (const std::exception& e) {
      // Kept and retried: an acknowledged job's events are not dropped while this process runs.
      if (failures++ % 20 == 0) spdlog::error("storing {} event(s) failed, retrying: {}", batch.size(), e.what());
      std::unique_lock lock(events_mutex_);
      if (stop_writer_) {
        spdlog::warn("stopping with {} event(s) unstored; their runs are taken over", batch.size());
        return;
      }
      writer_cv_.wait_for(lock, std::chrono::milliseconds(std::min(2000, 50 * failures)), [&] { return stop_writer_; });
      continue;
    }
    std::vector<std::shared_ptr<ActiveJob>> jobs;
    {
      std::lock_guard lock(mutex_);
      for (const NewEvent& e : batch) {
        const auto it = active_.find(e.lease.job_id);
        if (it != active_.end() && it->second->lease.generation == e.lease.generation) jobs.push_back(it->second);
      }
    }
    {
      std::lock_guard lock(events_mutex_);
      for (const NewEvent& e : batch)
        for (const auto& j : jobs)
          if (j->id == e.lease.job_id) j->stored_seq = std::max(j->stored_seq, e.event.seq);
      for (const Lease& l : refused)
        for (const auto& j : jobs)
          if (j->id == l.job_id && !j->lost.exchange(true))
            spdlog::warn("job {}: its lease went to another run; this run stops", j->id);
      events_stored_ += static_cast<std::int64_t>(batch.size());
    }
    batch.clear();
    stored_cv_.notify_all();
  }
}

void JobService::lease_loop() {
  const auto period = std::chrono::milliseconds(static_cast<long long>(options_.lease_seconds * 1000 / 3));
  std::unique_lock lock(mutex_);
  while (!lease_cv_.wait_for(lock, period, [&] { return stop_workers_ && running_ == 0; })) {
    lock.unlock();
    try {
      std::vector<Lease> held;
      {
        std::lock_guard relock(mutex_);
        for (const auto& [id, job] : active_) held.push_back(job->lease);
      }
      const LeaseRenewal r = store_.renew_leases(options_.replica, held, options_.lease_seconds);
      std::unique_lock relock(mutex_);
      // Only the leases that were sent are judged: a job claimed after the snapshot was not
      // renewed because it was not asked for (14 of 16,500 jobs were abandoned that way and
      // waited 10 s for their own lease to expire), and one whose end is being stored is
      // no longer renewable.
      for (const Lease& sent : held) {
        const auto it = active_.find(sent.job_id);
        if (it == active_.end() || it->second->lease.generation != sent.generation) continue;
        ActiveJob& job = *it->second;
        const bool renewed = std::any_of(r.held.begin(), r.held.end(), [&](const Lease& l) {
          return l.job_id == sent.job_id && l.generation == sent.generation;
        });
        if (!renewed && !job.finishing && !job.lost.exchange(true))
          spdlog::warn("job {}: lease lost; this run stops", job.id);
        if (std::find(r.dismissed.begin(), r.dismissed.end(), job.id) != r.dismissed.end())
          hear_dismissal(job, "lease renewal");
      }
      relock.unlock();
      store_.requeue_expired(now_iso8601());
    } catch (const std::exception& e) {
      spdlog::warn("cannot renew leases: {}", e.what());
    }
    {
      std::lock_guard ev(events_mutex_);
      room_cv_.notify_all();
      stored_cv_.notify_all();
    }
    lock.lock();
  }
}

bool JobService::retry_store(const std::shared_ptr<ActiveJob>& job, const std::function<void()>& call) {
  for (int failures = 0;; ++failures) {
    try {
      call();
      return true;
    } catch (const StoreUnavailable& e) {
      if (abort_runs_ || job->lost) return false;
      if (failures % 20 == 0) spdlog::warn("job {}: store unavailable, retrying: {}", job->id, e.what());
      std::this_thread::sleep_for(std::chrono::milliseconds(std::min(2000, 50 * (failures + 1))));
    }
  }
}

void JobService::finish(const std::shared_ptr<ActiveJob>& job, JobOutcome outcome, std::int64_t last) {
  flush(job, last);  // the job's events come first
  if (job->lost) {
    spdlog::warn("job {}: run not recorded (its lease went to another run)", job->id);
    return;
  }
  if (outcome.terminal.type.empty()) {
    const json ev =
        outcome.status == JobStatus::successful ? json{{"type", "job_finished"}}
        : outcome.status == JobStatus::dismissed
            ? json::parse(kDismissedEvent)
            : json{{"type", "job_failed"},
                   {"reason", outcome.message},
                   {"failure",
                    {{"kind", outcome.failure_kind}, {"message", outcome.message}, {"step", outcome.failure_step}}}};
    outcome.terminal = stored(last + 1, ev);
  }
  std::optional<FinishStored> stored;
  job->finishing = true;
  if (!retry_store(job, [&] { stored = store_.finish_job(job->lease, outcome); })) return;
  if (!stored) {
    spdlog::warn("job {}: run not recorded (fenced: another run holds it)", job->id);
    return;
  }
  std::lock_guard lock(mutex_);
  run_seconds_by_outcome_.try_emplace(std::string(to_string(stored->status)), seconds_buckets())
      .first->second.observe(std::chrono::duration<double>(Clock::now() - job->started).count());
  // What the job stores (scene, events, result), as the store counted it.
  if (stored->stored_bytes > 0) {
    stored_bytes_counts_.resize(kStoredBytesBuckets.size());
    for (size_t b = 0; b < kStoredBytesBuckets.size(); ++b)
      if (stored->stored_bytes <= kStoredBytesBuckets[b]) {
        ++stored_bytes_counts_[b];
        break;
      }
    stored_bytes_sum_ += stored->stored_bytes;
    ++stored_bytes_count_;
  }
  if (stored->status != JobStatus::dismissed || outcome.solve_seconds > 0) {
    solve_seconds_ += outcome.solve_seconds;
    iterations_ += outcome.iterations;
    ++finished_runs_;
  }
}

void JobService::run_job(const std::shared_ptr<ActiveJob>& job, const JobRecord& rec) {
  const std::string& id = job->id;
  std::int64_t seq = rec.last_seq;
  job->last_seq = seq;
  {
    std::lock_guard lock(events_mutex_);
    job->stored_seq = seq;
  }
  spdlog::info("job {} started (attempt {}, generation {})", id, rec.attempts, rec.generation);

  JobOutcome outcome;
  std::optional<Scene> scene;
  try {
    const json stored = json::parse(rec.scene);
    // Uploaded meshes come from the store: wait for it rather than fail the job.
    for (int failures = 0; !scene; ++failures) {
      try {
        MeshUse use;
        scene.emplace(read_with_meshes(meshes_, stored, use, true));
      } catch (const StoreUnavailable& e) {
        if (abort_runs_ || job->lost) throw;
        if (failures % 20 == 0) spdlog::warn("job {}: store unavailable, retrying: {}", id, e.what());
        std::this_thread::sleep_for(std::chrono::milliseconds(std::min(2000, 50 * (failures + 1))));
      }
    }
  } catch (const SceneErrors& e) {
    failed(outcome, FailureKind::invalid_scene, std::string("invalid scene: ") + e.what());
  } catch (const std::exception& e) {
    failed(outcome, FailureKind::invalid_scene, std::string("cannot read the stored scene: ") + e.what());
  }
  if (!scene) {
    outcome.finished = now_iso8601();
    log_outcome(id, outcome.status, 0, outcome.message, 0.0);
    finish(job, std::move(outcome), seq);
    return;
  }
  const JobLimits& lim = options_.limits;
  const int steps = static_cast<int>(scene->steps.size());
  const int nodes = scene->problem.body->node_count();
  if (nodes > lim.max_nodes || steps > lim.max_steps) {
    failed(outcome, FailureKind::job_limit,
           "limit: the scene has " + std::to_string(nodes) + " nodes and " + std::to_string(steps) +
               " steps; this service takes at most " + std::to_string(lim.max_nodes) + " nodes and " +
               std::to_string(lim.max_steps) + " steps");
    outcome.finished = now_iso8601();
    log_outcome(id, outcome.status, 0, outcome.message, 0.0);
    finish(job, std::move(outcome), seq);
    return;
  }
  {
    std::lock_guard lock(job->progress_mutex);
    job->progress = Progress{};
  }

  const auto t0 = Clock::now();
  std::int64_t iterations = 0;
  enum class Stop { none, dismissed, shutdown, lost, iterations, seconds } stop = Stop::none;
  SteppingObserver observer;
  observer.step_started = [&](int step, double load_factor) {
    emit(job, ++seq, step_started_event(step, load_factor));
    std::lock_guard lock(job->progress_mutex);
    job->progress->step = step;
  };
  // Contact iterations: real solves, the events' trials (the one count: the job document, the
  // log, /metrics, the limit and the result's summary all read it).
  observer.iteration = [&](const IterationEvent& ev) {
    iterations += ev.trials;
    emit(job, ++seq, iteration_event(ev));
    std::lock_guard lock(job->progress_mutex);
    job->progress->contact_error = ev.v2;
    job->progress->iterations = iterations;
  };
  observer.step_finished = [&](const StepRecord& step) {
    emit(job, ++seq, step_finished_event(scene->problem, step, scene->output));
    std::lock_guard lock(job->progress_mutex);
    if (step.converged) job->progress->steps_done = step.index;
  };
  observer.stop_requested = [&] {
    if (job->dismissed) stop = Stop::dismissed;
    else if (job->lost) stop = Stop::lost;
    else if (abort_runs_) stop = Stop::shutdown;
    else if (iterations >= lim.max_iterations) stop = Stop::iterations;
    else if (std::chrono::duration<double>(Clock::now() - t0).count() > lim.max_seconds) stop = Stop::seconds;
    return stop != Stop::none;
  };
  observer.stop_reason = [&]() -> std::pair<FailureKind, std::string> {
    switch (stop) {
      case Stop::iterations:
        return {FailureKind::job_limit, "limit: " + std::to_string(iterations) +
                                            " contact iterations, this service's limit (--max-iterations " +
                                            std::to_string(lim.max_iterations) + ")"};
      case Stop::seconds:
        return {FailureKind::job_limit, "limit: the run reached this service's wall-time limit (--max-seconds " +
                                            number_text(lim.max_seconds) + ")"};
      case Stop::dismissed:
        return {FailureKind::dismissed, "dismissed"};
      default:
        return {FailureKind::stopped, "stopped on request"};  // shutdown or lost: not stored
    }
  };

  RunResult run;
  try {
    run = run_load_steps(scene->problem, scene->steps, scene->params, observer);
  } catch (const std::exception& e) {
    run.completed = false;
    run.reason = std::string("solver error: ") + e.what();
    run.failure = FailureKind::exception;
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();

  if (job->lost) {
    spdlog::warn("job {}: run abandoned after {:.3f} s (its lease went to another run)", id, seconds);
    return;
  }
  if (stop == Stop::shutdown && !job->dismissed) {
    flush(job, seq);
    try {
      store_.requeue_job(job->lease, now_iso8601());
    } catch (const std::exception& e) {
      spdlog::warn("job {}: not requeued ({}); another process takes it when its lease expires", id, e.what());
    }
    spdlog::info("job {} interrupted by shutdown after {:.3f} s; accepted again", id, seconds);
    return;
  }
  outcome.finished = now_iso8601();
  outcome.solve_seconds = run.seconds > 0 ? run.seconds : seconds;
  outcome.iterations = iterations;
  for (const StepRecord& s : run.steps) outcome.steps_completed += s.converged ? 1 : 0;
  if (job->dismissed) {
    failed(outcome, FailureKind::dismissed, "dismissed");
  } else if (run.completed) {
    outcome.status = JobStatus::successful;
    outcome.message = "solved " + std::to_string(steps) + " steps";
  } else {
    // The result's reason (summary.reason), a job limit's included: the run's stop request
    // named it (observer.stop_reason).
    failed(outcome, run.failure, run.reason.empty() ? "the run failed" : run.reason, run.failure_step);
  }
  if (outcome.status != JobStatus::dismissed && !run.steps.empty()) {
    try {
      // Written as it is made (write_result), not built as a JSON document first: the document
      // took several times the text's memory and more time than writing it.
      std::ostringstream text;
      write_result(text, *scene, run);
      outcome.result = zstd(std::move(text).str());  // stored and served compressed
    } catch (const std::exception& e) {
      spdlog::error("job {}: cannot build its result: {}", id, e.what());
    }
  }
  const JobStatus status = outcome.status;
  const std::string message = outcome.message;
  finish(job, std::move(outcome), seq);
  log_outcome(id, status, iterations, message, seconds);
}

}  // namespace grip::server
