#pragma once
// The job store: jobs (scene, status, timings, leases), their events and their results,
// behind one interface with two implementations: SQLite (embedded, one process, the default)
// and PostgreSQL (shared by several replicas). tests/integration/store_contract_test.cpp
// holds every implementation to this contract:
// - a call returns only once its writes are durable (a 201 is never lost, even to kill -9);
// - claims are atomic: one job goes to one claimant, the oldest accepted job first;
// - a claim is a lease (owner, expiry, generation). Only the current generation may store
//   events, requeue or finish the job (fencing): a run whose lease expired and was taken over
//   can no longer write anything;
// - event sequence numbers of a job are never reused: `last_seq` only grows, also when an
//   interrupted run's events are discarded;
// - finish_job writes the final status, the result and the terminal event in one transaction,
//   at most once per job;
// - every change is announced to the listener (set_listener) of every store instance on the
//   same database, this one included.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
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

// The database cannot be reached (now); nothing was written. Retry later.
class StoreUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The terminal event of a dismissed job, as the store writes it.
inline constexpr std::string_view kDismissedEvent =
    R"({"failure":{"kind":"dismissed","message":"dismissed","step":0},"reason":"dismissed","type":"job_failed"})";

struct JobRecord {
  std::string id;
  std::int64_t ord = 0;  // creation order, assigned by the store
  JobStatus status = JobStatus::accepted;
  std::string scene;    // compact JSON as accepted (only filled when asked for)
  std::string created;  // ISO 8601 UTC timestamps; empty: not yet
  std::string started;
  std::string finished;
  std::string updated;
  std::string message;
  int steps = 0;  // load steps of the scene
  int nodes = 0;  // nodes of the body's mesh
  std::optional<std::string> idempotency_key;
  std::int64_t last_seq = 0;  // highest event sequence number ever given out
  int attempts = 0;           // runs started; above 1 after an interrupted run
  double solve_seconds = 0.0;
  std::int64_t iterations = 0;  // contact iterations of the final run
  std::string owner;            // replica holding (or that last held) the lease
  std::int64_t generation = 0;  // lease generation: grows with every claim
  // A finished job: why it did not succeed (a FailureKind's name, empty when it did), the step
  // that failed (0: none), and the steps that converged.
  std::string failure_kind;
  int failure_step = 0;
  int steps_completed = 0;
  std::int64_t stored_bytes = 0;    // of its scene, events and result, once finished
  std::string request_id;           // of the request that submitted it (X-Request-Id)
  std::vector<std::string> meshes;  // ids of the uploaded meshes its scene uses (written by insert_job)
};

// An uploaded mesh (POST /v1/meshes): content-addressed by the SHA-256 of its bytes.
struct MeshRecord {
  std::string id;           // hex SHA-256 of the file's bytes
  std::int64_t bytes = 0;   // the file's size
  std::int64_t stored = 0;  // its size as stored (zstd)
  std::string summary;      // gmsh_mesh_summary as compact JSON
  std::string created;      // ISO 8601 UTC
};

enum class MeshRemoval { not_found, in_use, removed };

// A study (POST /v1/studies): its plan and the jobs it submitted, as one JSON document. Its
// table is read from its jobs when asked (server/studies.hpp); the record itself never changes.
struct StudyRecord {
  std::string id;
  std::string created;   // ISO 8601 UTC
  std::string document;  // compact JSON
};

// Which finished jobs the store keeps; 0: no bound of that kind. Beyond a bound the
// dismissed jobs go first, then the oldest.
struct Retention {
  double max_age_seconds = 0;  // finished longer ago than this
  std::int64_t max_jobs = 0;   // finished jobs
  std::int64_t max_bytes = 0;  // stored bytes of finished jobs
  bool any() const { return max_age_seconds > 0 || max_jobs > 0 || max_bytes > 0; }
};

// A finished job as retention sees it, in the order it keeps them: the ones it keeps first.
struct FinishedJob {
  std::string id;
  bool dismissed = false;
  std::string finished;
  std::int64_t stored_bytes = 0;
};

// The time (ISO 8601) before which a job finished is too old at `now`; empty: no age bound.
std::string retention_cutoff(const Retention& r, const std::string& now);

// The ids of `jobs` (ordered as FinishedJob says) that `r` removes at `cutoff` (the ISO 8601
// time before which finished jobs are too old; empty: no age bound).
std::vector<std::string> beyond_retention(const std::vector<FinishedJob>& jobs, const Retention& r,
                                          const std::string& cutoff);

// A run's hold on a job (fencing token).
struct Lease {
  std::string job_id;
  std::int64_t generation = 0;
};

struct StoredEvent {
  std::int64_t seq = 0;  // per job, from 1; the SSE `id:`
  std::string type;      // step_started | iteration | step_finished | job_finished | job_failed
  std::string data;      // the event object as compact JSON
};

struct NewEvent {
  Lease lease;
  StoredEvent event;
};

struct JobOutcome {
  JobStatus status = JobStatus::successful;
  std::string message;
  std::string finished;  // timestamp
  double solve_seconds = 0.0;
  std::int64_t iterations = 0;
  std::string failure_kind;  // as JobRecord's
  int failure_step = 0;
  int steps_completed = 0;
  std::optional<std::string> result;  // the result as stored (zstd of its JSON), when the run produced one
  StoredEvent terminal;               // job_finished | job_failed
};

struct JobPage {
  std::vector<JobRecord> jobs;
  std::optional<std::int64_t> next_before;  // ord to continue below; none: last page
};

enum class DismissOutcome { not_found, dismissed, removed };

// What renew_leases found about the owner's jobs.
struct LeaseRenewal {
  std::vector<Lease> held;             // leases still this owner's (renewed)
  std::vector<std::string> dismissed;  // among them: jobs dismissed meanwhile
};

// A change announced to listeners.
// What finish_job stored.
struct FinishStored {
  JobStatus status;
  std::int64_t stored_bytes = 0;
};

struct StoreChange {
  enum Kind { events, job, dismissed } kind = job;  // events stored; status changed; dismissed
  std::string job_id;                               // empty: some job (a claim, a requeue)
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
  virtual JobPage list_jobs(std::optional<JobStatus> status, int limit, std::optional<std::int64_t> before) = 0;
  virtual std::map<JobStatus, std::int64_t> count_by_status() = 0;
  virtual std::int64_t count_accepted() = 0;

  // The oldest accepted job becomes running for `owner` (attempts + 1, a new generation, a
  // lease of `lease_seconds`); returned with its scene. None when no job is accepted.
  virtual std::optional<JobRecord> claim_job(const std::string& owner, const std::string& now,
                                             double lease_seconds) = 0;
  // Extends the given leases of `owner` that are still current (unfinished, same generation);
  // a lease its process no longer runs is left to expire.
  virtual LeaseRenewal renew_leases(const std::string& owner, const std::vector<Lease>& leases,
                                    double lease_seconds) = 0;
  // Ends every lease `owner` holds at once: a process starting under a fixed name knows that
  // its previous incarnation is gone.
  virtual void release_leases(const std::string& owner) = 0;
  // Jobs whose lease expired: running ones go back to accepted (events discarded, last_seq
  // kept), dismissed ones are finished. Returns how many changed.
  virtual int requeue_expired(const std::string& now) = 0;

  // Appends events and raises each job's last_seq, in one transaction, each only while its
  // lease is current. Returns the leases that were not (their events are dropped).
  virtual std::vector<Lease> append_events(const std::vector<NewEvent>& events) = 0;
  // Final status, timings, result and terminal event in one transaction, if `lease` is current
  // and the job unfinished. A job dismissed meanwhile ends dismissed (no result, the dismissed
  // event). Returns the status stored and the job's stored bytes (scene, events, result), or
  // none when fenced out.
  virtual std::optional<FinishStored> finish_job(const Lease& lease, const JobOutcome& outcome) = 0;
  // Back to accepted, the run's events discarded (last_seq kept), if `lease` is current.
  virtual bool requeue_job(const Lease& lease, const std::string& updated) = 0;
  // Atomically: an accepted job is finished as dismissed (with the dismissed event), a running
  // one marked dismissed (its runner finishes it), a finished one removed with its events and
  // result. Returns the job as it is afterwards (removed: as it was).
  virtual std::pair<DismissOutcome, std::optional<JobRecord>> dismiss_job(const std::string& id,
                                                                          const std::string& now) = 0;

  // Events with seq > after, in order, at most `limit`; only of `type` when given.
  virtual std::vector<StoredEvent> events_after(const std::string& id, std::int64_t after, int limit,
                                                std::string_view type = {}) = 0;
  // The result as stored: bytes (zstd; gzip or JSON text if stored by an earlier version).
  virtual std::optional<std::string> result(const std::string& id) = 0;

  // Meshes. put_mesh stores `data` (the file zstd-compressed) under mesh.id unless a mesh with
  // that id is stored; true when this call stored it. The same bytes are stored once.
  virtual bool put_mesh(const MeshRecord& mesh, const std::string& data) = 0;
  virtual std::optional<MeshRecord> mesh(const std::string& id) = 0;
  virtual std::optional<std::string> mesh_data(const std::string& id) = 0;
  // Removes a mesh unless a stored job uses it (insert_job's JobRecord::meshes).
  virtual MeshRemoval remove_mesh(const std::string& id) = 0;
  // Meshes stored and their stored bytes.
  virtual std::pair<std::int64_t, std::int64_t> mesh_totals() = 0;

  // Studies. insert_study throws std::runtime_error when the id exists; remove_study: whether
  // it was there. A study's jobs are removed (dismissed) by the caller.
  virtual void insert_study(const StudyRecord& study) = 0;
  virtual std::optional<StudyRecord> study(const std::string& id) = 0;
  virtual bool remove_study(const std::string& id) = 0;

  // Removes the finished jobs beyond `retention` at `now` (ISO 8601), with their events and
  // results, and hands their space back (SQLite: incremental vacuum). Returns how many. With an
  // age bound, meshes that no stored job uses and that no job named for that long go too.
  virtual std::int64_t prune(const Retention& retention, const std::string& now) = 0;
  // Bytes the database takes on disk (SQLite: the file; PostgreSQL: grip's tables).
  virtual std::int64_t disk_bytes() = 0;

  // True when the database answers now.
  virtual bool ping() = 0;
  // Called (on a store thread) for every change on the database, from any store instance.
  virtual void set_listener(std::function<void(const StoreChange&)> listener) = 0;
  // Round trips and bytes exchanged with the database so far (benchmarks); none when the
  // store does not measure them (embedded).
  virtual std::optional<std::pair<std::int64_t, std::int64_t>> traffic() const { return std::nullopt; }
};

}  // namespace grip::server
