#pragma once
// The job store: jobs (scene, status, timings), their events and their results, behind one
// small interface so that a shared store (PostgreSQL) can replace the embedded SQLite one.
//
// Contract every implementation keeps:
// - a call returns only once its writes are durable (a 201 is never lost, even to kill -9);
// - event sequence numbers of a job are never reused: `last_seq` only grows, also when an
//   interrupted run's events are discarded (see requeue_job and recover);
// - finish_job writes the final status, the result and the terminal event in one transaction.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace grip::server {

// OGC API - Processes job status.
enum class JobStatus { accepted, running, successful, failed, dismissed };

std::string_view to_string(JobStatus status);
std::optional<JobStatus> parse_job_status(std::string_view text);
inline bool is_finished(JobStatus s) {
  return s == JobStatus::successful || s == JobStatus::failed || s == JobStatus::dismissed;
}

struct JobRecord {
  std::string id;
  std::int64_t ord = 0;  // creation order, assigned by the store
  JobStatus status = JobStatus::accepted;
  std::string scene;     // compact JSON as accepted (only filled when asked for)
  std::string created;   // ISO 8601 UTC timestamps; empty: not yet
  std::string started;
  std::string finished;
  std::string updated;
  std::string message;
  int steps = 0;         // load steps of the scene
  int nodes = 0;         // sites of the body
  std::optional<std::string> idempotency_key;
  std::int64_t last_seq = 0;  // highest event sequence number ever given out
  int attempts = 0;           // runs started; above 1 after an interrupted run
  double solve_seconds = 0.0;
  std::int64_t iterations = 0;  // contact iterations of the final run
};

struct StoredEvent {
  std::int64_t seq = 0;  // per job, from 1; the SSE `id:`
  std::string type;      // step_started | iteration | step_finished | job_finished | job_failed
  std::string data;      // the event object as compact JSON
};

struct NewEvent {
  std::string job_id;
  StoredEvent event;
};

struct JobOutcome {
  JobStatus status = JobStatus::successful;
  std::string message;
  std::string finished;  // timestamp
  double solve_seconds = 0.0;
  std::int64_t iterations = 0;
  std::optional<std::string> result;   // result JSON, when the run produced one
  std::optional<StoredEvent> terminal;  // job_finished | job_failed
};

struct JobPage {
  std::vector<JobRecord> jobs;
  std::optional<std::int64_t> next_before;  // ord to continue below; none: last page
};

class Store {
 public:
  virtual ~Store() = default;

  // Inserts an accepted job and sets its ord. Throws std::runtime_error when the id or the
  // idempotency key already exists.
  virtual void insert_job(JobRecord& job) = 0;
  virtual std::optional<JobRecord> job(const std::string& id, bool with_scene = false) = 0;
  virtual std::optional<JobRecord> job_by_idempotency_key(const std::string& key) = 0;
  // Newest first; `before`: only jobs with a smaller ord.
  virtual JobPage list_jobs(std::optional<JobStatus> status, int limit,
                            std::optional<std::int64_t> before) = 0;
  virtual std::map<JobStatus, std::int64_t> count_by_status() = 0;

  // accepted -> running (attempts + 1). False when the job is no longer accepted.
  virtual bool start_job(const std::string& id, const std::string& started) = 0;
  // accepted | running -> dismissed, without finishing it (a running job's worker does).
  // False when the job was not accepted or running.
  virtual bool mark_dismissed(const std::string& id, const std::string& updated) = 0;
  // Appends events of any jobs in one transaction and raises each job's last_seq.
  virtual void append_events(const std::vector<NewEvent>& events) = 0;
  // Final status, timings, result and terminal event in one transaction.
  virtual void finish_job(const std::string& id, const JobOutcome& outcome) = 0;
  // Back to accepted, the interrupted run's events discarded (last_seq kept).
  virtual void requeue_job(const std::string& id, const std::string& updated) = 0;
  // Removes a job with its events and result. False when there was none.
  virtual bool delete_job(const std::string& id) = 0;

  // Events with seq > after, in order, at most `limit`; only of `type` when given.
  virtual std::vector<StoredEvent> events_after(const std::string& id, std::int64_t after,
                                                int limit, std::string_view type = {}) = 0;
  virtual std::optional<std::string> result(const std::string& id) = 0;

  // After a crash: running jobs go back to accepted (their events discarded), dismissed jobs
  // that were never finished get finished with `terminal_for_dismissed`; returns the ids of
  // all accepted jobs in creation order.
  virtual std::vector<std::string> recover(const std::string& now,
                                           const std::string& terminal_for_dismissed) = 0;
};

}  // namespace grip::server
