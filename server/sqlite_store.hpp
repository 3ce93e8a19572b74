#pragma once
// The embedded job store: one SQLite file in WAL mode. Job changes commit with
// synchronous=FULL (they survive kill -9 and power loss); event batches with NORMAL (they
// survive kill -9, and the job's FULL finish makes them durable before it is reported). One
// connection writes and one reads (WAL lets reads run beside a write), each under its own
// mutex.
#include <memory>
#include <mutex>
#include <string>

#include "server/sqlite.hpp"
#include "server/store.hpp"

namespace grip::server {

class SqliteStore final : public Store {
 public:
  // Creates the file (and its folder) and the schema when missing.
  explicit SqliteStore(const std::string& path, int busy_timeout_ms = 5000);

  void insert_job(JobRecord& job) override;
  std::optional<JobRecord> job(const std::string& id, bool with_scene) override;
  std::optional<JobRecord> job_by_idempotency_key(const std::string& key) override;
  JobPage list_jobs(std::optional<JobStatus> status, int limit,
                    std::optional<std::int64_t> before) override;
  std::map<JobStatus, std::int64_t> count_by_status() override;
  bool start_job(const std::string& id, const std::string& started) override;
  bool mark_dismissed(const std::string& id, const std::string& updated) override;
  void append_events(const std::vector<NewEvent>& events) override;
  void finish_job(const std::string& id, const JobOutcome& outcome) override;
  void requeue_job(const std::string& id, const std::string& updated) override;
  bool delete_job(const std::string& id) override;
  std::vector<StoredEvent> events_after(const std::string& id, std::int64_t after, int limit,
                                        std::string_view type) override;
  std::optional<std::string> result(const std::string& id) override;
  std::vector<std::string> recover(const std::string& now,
                                   const std::string& terminal_for_dismissed) override;

 private:
  std::mutex write_mutex_;
  std::unique_ptr<Database> writer_;
  std::mutex read_mutex_;
  std::unique_ptr<Database> reader_;
};

}  // namespace grip::server
