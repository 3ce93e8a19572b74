#pragma once
// The shared job store: PostgreSQL through libpq, for several `grip serve` replicas on one
// database. Claims take the oldest accepted job with FOR UPDATE SKIP LOCKED; leases expire by
// the database's clock (now()), so the replicas' clocks do not matter. Changes are announced
// with NOTIFY on the channel `grip` (payload: a kind letter and the job id) and heard by every
// store instance on a LISTEN connection of its own. Every other call borrows a connection from
// a small pool. While the database cannot be reached, calls throw StoreUnavailable at once
// (a failed connection attempt is not repeated for a second), so no caller hangs.
#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "server/store.hpp"

namespace grip::server {

bool is_postgresql_url(const std::string& db);
// The URL without its password (for logs).
std::string redacted_url(const std::string& url);

class PostgresStore final : public Store {
 public:
  // Connects and creates the tables when missing. Throws StoreUnavailable when the database
  // cannot be reached.
  explicit PostgresStore(const std::string& url, int pool_size = 16);
  ~PostgresStore() override;

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
  bool ping() override;
  void set_listener(std::function<void(const StoreChange&)> listener) override;
  std::optional<std::pair<std::int64_t, std::int64_t>> traffic() const override;

  struct Connection;
  struct Pool;

 private:
  void listen_loop();

  std::unique_ptr<Pool> pool_;
  std::mutex listener_mutex_;
  std::function<void(const StoreChange&)> listener_;
  std::condition_variable listening_cv_;
  bool listening_ = false;  // LISTEN holds on the listening connection (once)
  std::atomic<bool> stop_{false};
  std::thread listen_thread_;
};

}  // namespace grip::server
