#include "server/job_service.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "server/util.hpp"
#include "solver/io/result.hpp"

namespace grip::server {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

bool is_terminal_event(const std::string& type) {
  return type == "job_finished" || type == "job_failed";
}

struct JobService::ActiveJob {
  explicit ActiveJob(std::string job_id) : id(std::move(job_id)) {}
  const std::string id;
  bool taken = false;  // by a worker (guarded by the service mutex)
  std::atomic<bool> dismissed{false};
  std::atomic<std::int64_t> last_seq{0};  // the last event sequence number given out
  std::mutex progress_mutex;
  std::optional<Progress> progress;  // while running
};

namespace {

json failed_event(const std::string& reason) {
  return {{"type", "job_failed"}, {"reason", reason}};
}

StoredEvent stored(std::int64_t seq, const json& event) {
  return {seq, event.at("type").get<std::string>(), event.dump()};
}

// The fewest nodes a generated mesh ({"rectangle" | "half_disc": {"divisions": [a, b]}}) can
// have: (a + 1)(b + 1). Building a mesh far over the node limit before counting its nodes
// held the HTTP thread for minutes (a 1000 x 1000 rectangle).
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
    return (a + 1) * (b + 1);
  }
  return std::nullopt;
}

}  // namespace

JobService::JobService(Store& store, ServiceOptions options)
    : store_(store), options_(std::move(options)) {
  if (options_.workers <= 0)
    options_.workers = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  options_.queue_capacity = std::max(1, options_.queue_capacity);
}

JobService::~JobService() {
  if (started_) shutdown(std::chrono::milliseconds(0));
}

void JobService::start() {
  const std::vector<std::string> accepted = store_.recover(now_iso8601(), failed_event("dismissed").dump());
  {
    std::lock_guard lock(mutex_);
    for (const auto& id : accepted) {
      const auto rec = store_.job(id);
      {
        std::lock_guard ev(events_mutex_);
        committed_[id] = rec ? rec->last_seq : 0;
      }
      active_[id] = std::make_shared<ActiveJob>(id);
      queue_.push_back(id);
    }
  }
  if (!accepted.empty()) spdlog::info("recovered {} accepted job(s), queued in creation order", accepted.size());
  writer_ = std::thread([this] { writer_loop(); });
  for (int i = 0; i < options_.workers; ++i) workers_.emplace_back([this] { worker_loop(); });
  started_ = true;
}

std::optional<SubmitResult> JobService::replay(const std::optional<std::string>& key,
                                              const std::string& scene) {
  if (!key) return std::nullopt;
  auto existing = store_.job_by_idempotency_key(*key);
  if (!existing) return std::nullopt;
  if (existing->scene != scene)
    throw IdempotencyConflict("Idempotency-Key '" + *key + "' was used before with a different scene");
  existing->scene.clear();
  return SubmitResult{JobView{*existing, std::nullopt}, true};
}

SubmitResult JobService::submit(const json& scene_json,
                                const std::optional<std::string>& idempotency_key) {
  if (draining_) throw ShuttingDown();
  const std::string canonical = scene_json.dump();
  if (auto earlier = replay(idempotency_key, canonical)) return *earlier;
  const JobLimits& lim = options_.limits;
  if (const auto least = least_generated_nodes(scene_json); least && *least > lim.max_nodes)
    throw SceneErrors(std::vector<SceneIssue>{
        {"/body/mesh", "the body has at least " + std::to_string(*least) +
                           " nodes; this service takes at most " + std::to_string(lim.max_nodes)}});
  const Scene scene = read_scene(scene_json);  // throws SceneErrors
  const int nodes = scene.problem.body->site_count();
  const int steps = static_cast<int>(scene.steps.size());
  std::vector<SceneIssue> issues;
  if (nodes > lim.max_nodes)
    issues.push_back({"/body/mesh", "the body has " + std::to_string(nodes) +
                                        " nodes; this service takes at most " +
                                        std::to_string(lim.max_nodes)});
  if (steps > lim.max_steps)
    issues.push_back({scene.effective.contains("stages") ? "/stages" : "/steps",
                      "the scene has " + std::to_string(steps) +
                          " load steps; this service takes at most " +
                          std::to_string(lim.max_steps)});
  if (!issues.empty()) throw SceneErrors(std::move(issues));

  {
    std::lock_guard lock(mutex_);
    if (queue_.size() + reserved_ >= static_cast<size_t>(options_.queue_capacity))
      throw QueueFull(retry_after_seconds());
    ++reserved_;
  }
  JobRecord rec;
  rec.id = new_job_id();
  rec.status = JobStatus::accepted;
  rec.scene = canonical;
  rec.created = rec.updated = now_iso8601();
  rec.message = "accepted";
  rec.steps = steps;
  rec.nodes = nodes;
  rec.idempotency_key = idempotency_key;
  try {
    store_.insert_job(rec);
  } catch (...) {
    {
      std::lock_guard lock(mutex_);
      --reserved_;
    }
    // A concurrent submission with the same key won the race: answer as a replay.
    if (auto earlier = replay(idempotency_key, canonical)) return *earlier;
    throw;
  }
  {
    std::lock_guard lock(mutex_);
    --reserved_;
    {
      std::lock_guard ev(events_mutex_);
      committed_[rec.id] = 0;
    }
    active_[rec.id] = std::make_shared<ActiveJob>(rec.id);
    queue_.push_back(rec.id);
  }
  queue_cv_.notify_one();
  spdlog::info("job {} accepted: {} nodes, {} steps", rec.id, nodes, steps);
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

JobPage JobService::list(std::optional<JobStatus> status, int limit,
                         std::optional<std::int64_t> before) {
  return store_.list_jobs(status, limit, before);
}

std::pair<DismissOutcome, std::optional<JobView>> JobService::dismiss(const std::string& id) {
  std::shared_ptr<ActiveJob> active;
  bool queued = false;
  {
    std::lock_guard lock(mutex_);
    auto it = active_.find(id);
    if (it != active_.end()) {
      active = it->second;
      active->dismissed = true;
      if (!active->taken) {
        queued = true;
        queue_.erase(std::remove(queue_.begin(), queue_.end(), id), queue_.end());
      }
    }
  }
  if (active) {
    store_.mark_dismissed(id, now_iso8601());
    if (queued) {
      // Never started: finish it here. Its worker (none) cannot.
      // Never started, so no events are on their way: the stored last_seq is the last.
      JobOutcome o;
      o.status = JobStatus::dismissed;
      o.message = "dismissed before it started";
      o.finished = now_iso8601();
      const auto rec = store_.job(id);
      finish(active, std::move(o), rec ? rec->last_seq : 0);
    }
    spdlog::info("job {} dismissed ({})", id, queued ? "queued" : "running");
    auto view = job(id);
    if (view) {
      view->record.status = JobStatus::dismissed;
      view->progress.reset();
    }
    return {DismissOutcome::dismissed, view};
  }
  auto rec = store_.job(id);
  if (!rec) return {DismissOutcome::not_found, std::nullopt};
  if (!is_finished(rec->status)) {
    // Accepted or running in the store but unknown here: another process's job (a shared
    // store) or a race with its worker finishing. Mark it; its owner finishes it.
    store_.mark_dismissed(id, now_iso8601());
    rec->status = JobStatus::dismissed;
    return {DismissOutcome::dismissed, JobView{*rec, std::nullopt}};
  }
  store_.delete_job(id);
  spdlog::info("job {} removed", id);
  return {DismissOutcome::removed, JobView{*rec, std::nullopt}};
}

EventBatch JobService::wait_events(const std::string& id, std::int64_t after,
                                   std::chrono::milliseconds wait, int limit) {
  const auto deadline = Clock::now() + wait;
  while (true) {
    std::uint64_t generation = 0;
    {
      std::unique_lock lock(events_mutex_);
      generation = generation_;
      auto it = committed_.find(id);
      if (it != committed_.end() && it->second <= after) {
        // An active job with nothing new stored yet.
        const bool woke = committed_cv_.wait_until(
            lock, deadline, [&] { return generation_ != generation || draining_.load(); });
        if (!woke || draining_) return {};
        continue;
      }
    }
    EventBatch batch;
    batch.events = store_.events_after(id, after, limit);
    if (!batch.events.empty()) {
      batch.ended = is_terminal_event(batch.events.back().type);
      return batch;
    }
    const auto rec = store_.job(id);
    if (!rec) return {false, {}, false};
    if (is_finished(rec->status) && !rec->finished.empty()) return {true, {}, true};
    // Accepted but not known here yet (between store and queue), or another process's job.
    std::unique_lock lock(events_mutex_);
    const bool woke = committed_cv_.wait_until(
        lock, deadline, [&] { return generation_ != generation || draining_.load(); });
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
    s.queue_depth = queue_.size();
    s.running = running_;
    s.workers = options_.workers;
    s.solve_seconds = solve_seconds_;
    s.iterations = iterations_;
  }
  {
    std::lock_guard lock(events_mutex_);
    s.events = events_stored_;
  }
  s.jobs = store_.count_by_status();
  return s;
}

int JobService::retry_after_seconds() const {
  // Expected wait for one queue slot: the queue ahead shared by the workers (mutex_ held).
  const double mean = finished_runs_ ? solve_seconds_ / static_cast<double>(finished_runs_) : 1.0;
  const double wait = mean * static_cast<double>(queue_.size()) / options_.workers;
  return std::clamp(static_cast<int>(std::ceil(wait)), 1, 300);
}

void JobService::begin_drain() {
  draining_ = true;
  std::lock_guard lock(events_mutex_);
  committed_cv_.notify_all();
}

void JobService::shutdown(std::chrono::milliseconds grace) {
  if (!started_.exchange(false)) return;
  begin_drain();
  {
    std::unique_lock lock(mutex_);
    stop_workers_ = true;
    queue_cv_.notify_all();
    if (running_ > 0)
      spdlog::info("waiting up to {:.1f} s for {} running job(s)", grace.count() / 1000.0, running_);
    if (!idle_cv_.wait_for(lock, grace, [&] { return running_ == 0; })) {
      spdlog::warn("grace period over: stopping {} running job(s); they run again at the next start",
                   running_);
      abort_runs_ = true;
    }
  }
  for (auto& w : workers_) w.join();
  workers_.clear();
  {
    std::lock_guard lock(events_mutex_);
    stop_writer_ = true;
  }
  writer_cv_.notify_all();
  if (writer_.joinable()) writer_.join();
}

void JobService::worker_loop() {
  while (true) {
    std::shared_ptr<ActiveJob> job;
    {
      std::unique_lock lock(mutex_);
      queue_cv_.wait(lock, [&] { return stop_workers_ || !queue_.empty(); });
      if (stop_workers_) return;
      const std::string id = queue_.front();
      queue_.pop_front();
      auto it = active_.find(id);
      if (it == active_.end()) continue;
      job = it->second;
      job->taken = true;
      ++running_;
    }
    try {
      run_job(job);
    } catch (const std::exception& e) {
      // Most likely the store failed; try to leave the job failed rather than running.
      spdlog::error("job {}: {}", job->id, e.what());
      try {
        JobOutcome o;
        o.status = JobStatus::failed;
        o.message = std::string("internal error: ") + e.what();
        o.finished = now_iso8601();
        finish(job, std::move(o), job->last_seq);
      } catch (const std::exception& again) {
        spdlog::error("job {} stays unfinished until the next start: {}", job->id, again.what());
        forget(job->id);
      }
    }
    {
      std::lock_guard lock(mutex_);
      --running_;
    }
    idle_cv_.notify_all();
  }
}

void JobService::emit(const std::shared_ptr<ActiveJob>& job, std::int64_t seq, const json& event) {
  const std::string& id = job->id;
  job->last_seq = seq;
  if (options_.event_tap) options_.event_tap(id, seq, event);
  {
    std::lock_guard lock(events_mutex_);
    pending_.push_back({id, stored(seq, event)});
  }
  writer_cv_.notify_one();
}

void JobService::flush(const std::string& id, std::int64_t seq) {
  std::unique_lock lock(events_mutex_);
  committed_cv_.wait(lock, [&] {
    auto it = committed_.find(id);
    return it == committed_.end() || it->second >= seq;
  });
}

void JobService::writer_loop() {
  int failures = 0;
  std::vector<NewEvent> batch;
  while (true) {
    {
      std::unique_lock lock(events_mutex_);
      writer_cv_.wait(lock, [&] { return stop_writer_ || !pending_.empty() || !batch.empty(); });
      if (stop_writer_ && pending_.empty() && batch.empty()) return;
      batch.insert(batch.end(), std::make_move_iterator(pending_.begin()),
                   std::make_move_iterator(pending_.end()));
      pending_.clear();
    }
    try {
      store_.append_events(batch);
      failures = 0;
    } catch (const std::exception& e) {
      if (++failures < 5) {
        spdlog::error("storing {} event(s) failed, retrying: {}", batch.size(), e.what());
        std::this_thread::sleep_for(std::chrono::milliseconds(100 * failures));
        continue;
      }
      spdlog::critical("dropping {} event(s) that could not be stored: {}", batch.size(), e.what());
      failures = 0;
    }
    {
      std::lock_guard lock(events_mutex_);
      for (const NewEvent& e : batch) {
        auto it = committed_.find(e.job_id);
        if (it != committed_.end()) it->second = std::max(it->second, e.event.seq);
      }
      events_stored_ += static_cast<std::int64_t>(batch.size());
      ++generation_;
    }
    batch.clear();
    committed_cv_.notify_all();
  }
}

void JobService::forget(const std::string& id) {
  {
    std::lock_guard lock(events_mutex_);
    committed_.erase(id);
    ++generation_;
  }
  committed_cv_.notify_all();
  std::lock_guard lock(mutex_);
  active_.erase(id);
}

void JobService::finish(const std::shared_ptr<ActiveJob>& job, JobOutcome outcome,
                        std::int64_t last) {
  flush(job->id, last);  // the job's events come first
  if (!outcome.terminal) {
    const json ev = outcome.status == JobStatus::successful
                        ? json{{"type", "job_finished"}}
                        : failed_event(outcome.status == JobStatus::dismissed ? "dismissed"
                                                                              : outcome.message);
    outcome.terminal = stored(last + 1, ev);
  }
  store_.finish_job(job->id, outcome);
  {
    std::lock_guard lock(mutex_);
    if (outcome.status != JobStatus::dismissed || outcome.solve_seconds > 0) {
      solve_seconds_ += outcome.solve_seconds;
      iterations_ += outcome.iterations;
      ++finished_runs_;
    }
  }
  forget(job->id);
}

void JobService::run_job(const std::shared_ptr<ActiveJob>& job) {
  const std::string& id = job->id;
  const std::string started = now_iso8601();
  if (job->dismissed || !store_.start_job(id, started)) {
    const auto rec = store_.job(id);
    if (rec && rec->status == JobStatus::dismissed && rec->finished.empty()) {
      JobOutcome o;
      o.status = JobStatus::dismissed;
      o.message = "dismissed before it started";
      o.finished = now_iso8601();
      finish(job, std::move(o), rec->last_seq);
    } else {
      forget(id);
    }
    return;
  }
  const auto rec = store_.job(id, true);
  std::int64_t seq = rec ? rec->last_seq : 0;
  job->last_seq = seq;
  {
    std::lock_guard lock(events_mutex_);
    committed_[id] = std::max(committed_[id], seq);
  }
  spdlog::info("job {} started (attempt {})", id, rec ? rec->attempts : 1);

  JobOutcome outcome;
  std::optional<Scene> scene;
  try {
    scene.emplace(read_scene(json::parse(rec->scene)));
  } catch (const SceneErrors& e) {
    outcome.status = JobStatus::failed;
    outcome.message = std::string("invalid scene: ") + e.what();
  } catch (const std::exception& e) {
    outcome.status = JobStatus::failed;
    outcome.message = std::string("cannot read the stored scene: ") + e.what();
  }
  if (!scene) {
    outcome.finished = now_iso8601();
    finish(job, std::move(outcome), seq);
    return;
  }
  const JobLimits& lim = options_.limits;
  const int steps = static_cast<int>(scene->steps.size());
  const int nodes = scene->problem.body->site_count();
  if (nodes > lim.max_nodes || steps > lim.max_steps) {
    outcome.status = JobStatus::failed;
    outcome.message = "limit: the scene is over this service's node or step limit";
    outcome.finished = now_iso8601();
    finish(job, std::move(outcome), seq);
    return;
  }
  {
    std::lock_guard lock(job->progress_mutex);
    job->progress = Progress{};
  }

  const auto t0 = Clock::now();
  std::int64_t iterations = 0;
  enum class Stop { none, dismissed, shutdown, iterations, seconds } stop = Stop::none;
  SteppingObserver observer;
  observer.step_started = [&](int step, double load_factor) {
    emit(job, ++seq, step_started_event(step, load_factor));
    std::lock_guard lock(job->progress_mutex);
    job->progress->step = step;
  };
  observer.iteration = [&](const IterationEvent& ev) {
    ++iterations;
    emit(job, ++seq, iteration_event(ev));
    std::lock_guard lock(job->progress_mutex);
    job->progress->contact_error = ev.v2;
    job->progress->iterations = iterations;
  };
  observer.step_finished = [&](const StepRecord& step) {
    emit(job, ++seq, step_finished_event(step));
    std::lock_guard lock(job->progress_mutex);
    if (step.converged) job->progress->steps_done = step.index;
  };
  observer.stop_requested = [&] {
    if (job->dismissed) stop = Stop::dismissed;
    else if (abort_runs_) stop = Stop::shutdown;
    else if (iterations >= lim.max_iterations) stop = Stop::iterations;
    else if (std::chrono::duration<double>(Clock::now() - t0).count() > lim.max_seconds)
      stop = Stop::seconds;
    return stop != Stop::none;
  };

  RunResult run;
  try {
    run = run_load_steps(scene->problem, scene->steps, scene->params, observer);
  } catch (const std::exception& e) {
    run.completed = false;
    run.reason = std::string("solver error: ") + e.what();
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();

  if (stop == Stop::shutdown && !job->dismissed) {
    flush(id, seq);
    store_.requeue_job(id, now_iso8601());
    forget(id);
    spdlog::info("job {} interrupted by shutdown after {:.3f} s; accepted again", id, seconds);
    return;
  }
  outcome.finished = now_iso8601();
  outcome.solve_seconds = run.seconds > 0 ? run.seconds : seconds;
  outcome.iterations = iterations;
  if (job->dismissed) {
    outcome.status = JobStatus::dismissed;
    outcome.message = "dismissed";
  } else if (run.completed) {
    outcome.status = JobStatus::successful;
    outcome.message = "solved " + std::to_string(steps) + " steps";
  } else {
    outcome.status = JobStatus::failed;
    if (stop == Stop::iterations)
      outcome.message = "limit: more than " + std::to_string(lim.max_iterations) +
                        " contact iterations";
    else if (stop == Stop::seconds)
      outcome.message = "limit: more than " + std::to_string(lim.max_seconds) + " s of wall time";
    else
      outcome.message = run.reason.empty() ? "the run failed" : run.reason;
  }
  if (outcome.status != JobStatus::dismissed && !run.steps.empty()) {
    try {
      outcome.result = result_json(*scene, run).dump();
    } catch (const std::exception& e) {
      spdlog::error("job {}: cannot build its result: {}", id, e.what());
    }
  }
  const std::string status(to_string(outcome.status));
  const std::string message = outcome.message;
  finish(job, std::move(outcome), seq);
  spdlog::info("job {} {} in {:.3f} s: {} contact iterations; {}", id, status, seconds, iterations,
               message);
}

}  // namespace grip::server
