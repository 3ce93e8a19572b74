#pragma once
// The job API under the HTTP layer: submit a scene, read a job, dismiss it, follow its events.
// Plain C++, testable without sockets.
//
// Design:
// - The store holds the queue: a worker claims the oldest accepted job from it (a lease with
//   a generation, renewed by a lease thread) and runs it with run_load_steps. HTTP threads
//   never solve. Several processes may share one store (PostgreSQL): any of them accepts,
//   answers and dismisses any job, and their workers share the queue.
// - Events are numbered per job (seq = the SSE id) on the worker and handed to one writer
//   thread that stores whatever has accumulated in one transaction (group commit), only while
//   the run's lease is current. Readers only ever see stored events, so an id a client saw is
//   never given to another event, whatever happens to the process. While the store cannot be
//   reached, events wait in a bounded buffer (a full buffer pauses the run).
// - A job's final status, result and terminal event are stored in one transaction after all
//   its other events, at most once (fenced by the lease generation).
// - The store announces changes (its listener): new events wake the readers, new or requeued
//   jobs wake a worker, a dismissal sets the run's flag that its stop request reads before
//   every contact iteration.
// - A run whose lease expired (its process died or lost the store for longer than the lease)
//   goes back to accepted with its events discarded and its sequence continuing above the
//   discarded ids; any process then claims it.
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "server/meshes.hpp"
#include "server/observability.hpp"
#include "server/pruner.hpp"
#include "server/store.hpp"

namespace grip::server {

// Per-job limits. Nodes and steps are checked at submission (422); iterations and wall time
// while the job runs (the job fails with the limit as its reason).
struct JobLimits {
  int max_nodes = 100000;                 // nodes of the body's mesh
  int max_steps = 10000;                  // load steps of the scene
  std::int64_t max_iterations = 1000000;  // contact iterations (real solves), all steps together
  double max_seconds = 3600.0;            // wall time of one run
};

struct ServiceOptions {
  int workers = 0;                    // 0: one per core
  int queue_capacity = 256;           // accepted jobs waiting for a worker (all processes together)
  std::string replica;                // this process's name in leases; empty: host-pid-random
  double lease_seconds = 10;          // a run unrenewed this long is taken over by another process
  std::size_t event_buffer = 100000;  // events waiting for the store before runs pause
  JobLimits limits;
  Retention retention;  // finished jobs kept (server/pruner.hpp)
  std::chrono::milliseconds prune_interval{60000};
  // Test and benchmark hook, called on the worker thread as each event is produced (before
  // it is stored).
  std::function<void(const std::string& job_id, std::int64_t seq, const nlohmann::json& event)> event_tap;
};

// Submission refused because the queue is full; retry after `retry_after_seconds`.
class QueueFull : public std::runtime_error {
 public:
  explicit QueueFull(int retry_after) : std::runtime_error("the job queue is full"), retry_after_seconds(retry_after) {}
  int retry_after_seconds;
};

// Submission refused while the service shuts down.
class ShuttingDown : public std::runtime_error {
 public:
  ShuttingDown() : std::runtime_error("the service is shutting down") {}
};

// The idempotency key was used before with a different scene.
class IdempotencyConflict : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Progress of a running job (not stored: a restarted run starts from zero).
struct Progress {
  int step = 0;                 // step being solved, 1-based
  int steps_done = 0;           // converged steps
  double contact_error = 0.0;   // ||v||_2 of the last contact iteration
  std::int64_t iterations = 0;  // contact iterations so far
};

struct JobView {
  JobRecord record;
  std::optional<Progress> progress;  // while running
};

struct SubmitResult {
  JobView job;
  bool replayed = false;  // an earlier submission with the same idempotency key
};

struct EventBatch {
  bool found = true;  // false: no such job
  std::vector<StoredEvent> events;
  bool ended = false;  // the job's terminal event has been delivered (or was before `after`)
};

struct ServiceStats {
  std::size_t queue_depth = 0;
  int running = 0;
  int workers = 0;
  double solve_seconds = 0.0;      // finished runs, this process
  std::int64_t iterations = 0;     // contact iterations of finished runs, this process
  std::int64_t events = 0;         // events stored, this process
  std::size_t events_waiting = 0;  // events not yet stored
  // Round trips and bytes with the database, this process; none where the store does not
  // measure them.
  std::optional<std::pair<std::int64_t, std::int64_t>> db_traffic;
  std::map<JobStatus, std::int64_t> jobs;  // by status, from the store
  Retention retention;
  std::int64_t pruned = 0;                  // finished jobs removed by retention, this process
  std::int64_t disk_bytes = 0;              // the database on disk
  std::int64_t meshes = 0, mesh_bytes = 0;  // uploaded meshes stored, their stored bytes
  // Stored bytes of the jobs this process finished: {upper bound, count} and their sum.
  std::vector<std::pair<double, std::int64_t>> stored_bytes_buckets;
  std::int64_t stored_bytes_sum = 0, stored_bytes_count = 0;
};

bool is_terminal_event(const std::string& type);

class JobService {
 public:
  JobService(Store& store, ServiceOptions options);
  ~JobService();
  JobService(const JobService&) = delete;
  JobService& operator=(const JobService&) = delete;

  // Recovers interrupted jobs, queues accepted ones, starts the writer and the workers.
  void start();

  // Validates and stores the scene, then queues it. Throws grip::SceneErrors (invalid scene
  // or over a limit), QueueFull, ShuttingDown, IdempotencyConflict.
  // `request_id`: the submitting request's, kept with the job.
  SubmitResult submit(const nlohmann::json& scene, const std::optional<std::string>& idempotency_key = std::nullopt,
                      const std::string& request_id = "");
  // submit's checks of a scene (schema, reader, job limits) without storing it: its nodes.
  // Throws grip::SceneErrors.
  int check(const nlohmann::json& scene);
  std::optional<JobView> job(const std::string& id);
  std::vector<JobView> with_progress(std::vector<JobRecord> records);
  JobPage list(std::optional<JobStatus> status, int limit, std::optional<std::int64_t> before);

  // Cancels a queued or running job (a running one stops before its next contact iteration),
  // removes a finished one. The view is the job as dismissed or as it was before removal.
  std::pair<DismissOutcome, std::optional<JobView>> dismiss(const std::string& id);

  // Stored events with seq > after, waiting up to `wait` for some to arrive. `seen`, kept by a
  // caller that reads one job's events again and again (an event stream), lets a call that
  // follows a read which found every stored event wait for the job's next announcement rather
  // than read again: after each batch, that read and the job's read were two reads of the store
  // that found nothing. A wait that times out reads again (a job removed unannounced).
  EventBatch wait_events(const std::string& id, std::int64_t after, std::chrono::milliseconds wait, int limit = 256,
                         std::uint64_t* seen = nullptr);
  std::vector<StoredEvent> events(const std::string& id, std::int64_t after, int limit, std::string_view type = {});
  std::optional<std::string> result(const std::string& id);

  ServiceStats stats();
  // Queue wait and run duration histograms (Prometheus text).
  void write_job_metrics(std::ostream& os) const;
  // Started, not draining, and the store answers.
  bool ready();
  const std::string& replica() const { return options_.replica; }
  const ServiceOptions& options() const { return options_; }
  // Uploaded meshes (POST /v1/meshes), and the parsed ones shared by submissions and workers.
  MeshLibrary& meshes() { return meshes_; }
  // The store the jobs live in (studies keep their plans there: server/studies.hpp).
  Store& store() { return store_; }

  // Called on the worker thread after each run this process finished and stored, with the
  // job's idempotency key (an accuracy study's levels carry theirs: server/studies.hpp). Set
  // and cleared by its owner; clearing waits for a call in progress.
  void set_finished_hook(std::function<void(const std::string& idempotency_key)> hook);

  // Refuses new submissions and releases every event reader at once.
  void begin_drain();
  bool draining() const { return draining_; }
  // Takes no more jobs from the queue, lets running jobs finish for up to `grace`, then stops
  // them and puts them back to accepted (the next start, or another process, runs them again).
  void shutdown(std::chrono::milliseconds grace);

 private:
  struct ActiveJob;
  struct Checked {
    int nodes = 0, steps = 0;
    std::vector<std::string> meshes;  // the uploads it names
  };
  Checked check_scene(const nlohmann::json& scene);
  // The earlier submission with this idempotency key, if any (same scene, else it throws).
  std::optional<SubmitResult> replay(const std::optional<std::string>& key, const std::string& scene);
  void on_change(const StoreChange& change);
  void hear_dismissal(ActiveJob& job, const char* how);
  void worker_loop();
  void writer_loop();
  void lease_loop();
  void run_job(const std::shared_ptr<ActiveJob>& job, const JobRecord& record);
  void emit(const std::shared_ptr<ActiveJob>& job, std::int64_t seq, const nlohmann::json& event);
  // Waits until the job's events up to `seq` are stored (or its lease is lost).
  void flush(const std::shared_ptr<ActiveJob>& job, std::int64_t seq);
  // Stores the outcome after all events up to `last_seq`.
  void finish(const std::shared_ptr<ActiveJob>& job, JobOutcome outcome, std::int64_t last_seq);
  // Runs a store call until it succeeds or the runs are aborted (false then).
  bool retry_store(const std::shared_ptr<ActiveJob>& job, const std::function<void()>& call);
  int retry_after_seconds() const;

  Store& store_;
  ServiceOptions options_;
  MeshLibrary meshes_;
  std::unique_ptr<Pruner> pruner_;                 // with a retention, while started
  std::vector<std::int64_t> stored_bytes_counts_;  // per kStoredBytesBuckets (mutex_)
  std::int64_t stored_bytes_sum_ = 0, stored_bytes_count_ = 0;
  Histogram queue_wait_{seconds_buckets()};                  // accepted -> claimed here
  std::map<std::string, Histogram> run_seconds_by_outcome_;  // claimed -> stored outcome (mutex_)
  std::atomic<bool> started_{false};
  std::atomic<bool> draining_{false};

  // Workers and active (claimed) jobs.
  mutable std::mutex mutex_;
  std::condition_variable work_cv_;  // a job may be waiting: workers try a claim
  std::condition_variable idle_cv_;
  int work_hints_ = 0;
  std::unordered_map<std::string, std::shared_ptr<ActiveJob>> active_;
  int reserved_ = 0;  // submissions past the capacity check, not yet stored
  int running_ = 0;
  bool stop_workers_ = false;
  std::atomic<bool> abort_runs_{false};
  std::vector<std::thread> workers_;
  double solve_seconds_ = 0.0;
  std::int64_t iterations_ = 0;
  std::int64_t finished_runs_ = 0;
  std::thread lease_thread_;
  std::condition_variable lease_cv_;

  // Events: pending batch, stored sequence per active run.
  std::mutex events_mutex_;
  std::mutex finished_hook_mutex_;  // held while the hook runs
  std::function<void(const std::string&)> finished_hook_;
  std::condition_variable writer_cv_;
  std::condition_variable stored_cv_;  // events stored by this writer; draining
  std::condition_variable room_cv_;    // the pending buffer has room again
  std::vector<NewEvent> pending_;
  // The jobs that event streams wait on, each with its count of announcements and a condition
  // of its own: an event wakes its own job's streams only (one condition for all woke the 100
  // streams of a load run at each of some 4,000 events a second; half the server's time went
  // to waking threads). Kept while a stream waits. A lock of their own (not events_mutex_,
  // which every event produced and stored takes).
  std::mutex watch_mutex_;
  struct Watch {
    std::uint64_t changes = 0;  // announcements_ at the job's last announcement (or at the watch's start)
    int waiters = 0;
    std::condition_variable cv;
  };
  std::unordered_map<std::string, std::shared_ptr<Watch>> watches_;
  // Announcements heard, all jobs together: a watch made again starts from here, so a reader's
  // `seen` from an earlier watch of the job never equals it after an announcement it missed.
  std::uint64_t announcements_ = 0;
  std::int64_t events_stored_ = 0;
  bool stop_writer_ = false;
  std::thread writer_;
};

}  // namespace grip::server
