#pragma once
// The embedded job store: one SQLite file in WAL mode, used by one process. A job's end
// commits with synchronous=FULL (it survives kill -9 and power loss); a submission commits
// with NORMAL and is then fsynced (the WAL file) outside the writer's lock, before
// insert_job returns, so that concurrent submissions do not queue behind each other's fsync;
// claims, lease renewals and event batches commit with NORMAL (they survive kill -9; what a
// power cut takes of them, recovery redoes; the next fsync makes them durable). The writer's
// connection is NORMAL and switches to FULL for the few commits that need it. One connection writes and one reads (WAL lets reads run beside a write), each
// under its own mutex. Since no other process shares the file, opening it releases every
// lease: the runs of the previous process are requeued at once by requeue_expired. Changes
// are announced to the listener right after they commit.
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "server/sqlite.hpp"
#include "server/store.hpp"

namespace grip::server {

class SqliteStore : public Store {
 public:
  // Creates the file (and its folder) and the schema when missing; upgrades an older schema.
  explicit SqliteStore(const std::string& path, int busy_timeout_ms = 5000);
  ~SqliteStore() override;

  void insert_job(JobRecord& job) override;
  std::optional<JobRecord> job(const std::string& id, bool with_scene) override;
  std::optional<JobRecord> job_by_idempotency_key(const std::string& key) override;
  JobPage list_jobs(std::optional<JobStatus> status, int limit, std::optional<std::int64_t> before) override;
  std::map<JobStatus, std::int64_t> count_by_status() override;
  std::int64_t count_accepted() override;
  std::optional<JobRecord> claim_job(const std::string& owner, const std::string& now, double lease_seconds) override;
  LeaseRenewal renew_leases(const std::string& owner, const std::vector<Lease>& leases, double lease_seconds) override;
  void release_leases(const std::string& owner) override;
  int requeue_expired(const std::string& now) override;
  std::vector<Lease> append_events(const std::vector<NewEvent>& events) override;
  std::optional<FinishStored> finish_job(const Lease& lease, const JobOutcome& outcome) override;
  bool requeue_job(const Lease& lease, const std::string& updated) override;
  std::pair<DismissOutcome, std::optional<JobRecord>> dismiss_job(const std::string& id,
                                                                  const std::string& now) override;
  std::vector<StoredEvent> events_after(const std::string& id, std::int64_t after, int limit,
                                        std::string_view type) override;
  std::optional<std::string> result(const std::string& id) override;
  bool put_mesh(const MeshRecord& mesh, const std::string& data) override;
  std::optional<MeshRecord> mesh(const std::string& id) override;
  std::optional<std::string> mesh_data(const std::string& id) override;
  MeshRemoval remove_mesh(const std::string& id) override;
  void insert_study(const StudyRecord& study) override;
  std::optional<StudyRecord> study(const std::string& id) override;
  bool remove_study(const std::string& id) override;
  std::pair<std::int64_t, std::int64_t> mesh_totals() override;
  std::int64_t prune(const Retention& retention, const std::string& now) override;
  std::int64_t disk_bytes() override;
  bool ping() override { return true; }
  void set_listener(std::function<void(const StoreChange&)> listener) override;

 private:
  void announce(StoreChange::Kind kind, const std::string& job_id);
  // Meshes no stored job uses, named by no job since `cutoff` (empty: none go).
  void prune_meshes(const std::string& cutoff);
  std::optional<JobRecord> job_locked(Database& db, const std::string& id, bool with_scene);

  std::mutex write_mutex_;
  std::unique_ptr<Database> writer_;
  // The WAL file, opened once more to fsync a submission's commit after the writer is free
  // (insert_job); -1: submissions commit with synchronous=FULL instead.
  int wal_fd_ = -1;
  std::mutex read_mutex_;
  std::unique_ptr<Database> reader_;
  std::mutex listener_mutex_;
  std::function<void(const StoreChange&)> listener_;
};

}  // namespace grip::server
