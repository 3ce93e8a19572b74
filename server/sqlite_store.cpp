#include "server/sqlite_store.hpp"

#include <array>
#include <filesystem>

namespace grip::server {

namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS jobs (
  ord INTEGER PRIMARY KEY AUTOINCREMENT,
  id TEXT NOT NULL UNIQUE,
  status TEXT NOT NULL,
  scene TEXT NOT NULL,
  created TEXT NOT NULL,
  started TEXT,
  finished TEXT,
  updated TEXT NOT NULL,
  message TEXT NOT NULL DEFAULT '',
  steps INTEGER NOT NULL DEFAULT 0,
  nodes INTEGER NOT NULL DEFAULT 0,
  idempotency_key TEXT UNIQUE,
  last_seq INTEGER NOT NULL DEFAULT 0,
  attempts INTEGER NOT NULL DEFAULT 0,
  solve_seconds REAL NOT NULL DEFAULT 0,
  iterations INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX IF NOT EXISTS jobs_by_status ON jobs (status, ord);
CREATE TABLE IF NOT EXISTS events (
  job_id TEXT NOT NULL,
  seq INTEGER NOT NULL,
  type TEXT NOT NULL,
  data TEXT NOT NULL,
  PRIMARY KEY (job_id, seq)
) WITHOUT ROWID;
CREATE TABLE IF NOT EXISTS results (
  job_id TEXT PRIMARY KEY,
  data TEXT NOT NULL
);
PRAGMA user_version = 1;
)sql";

// Columns read by read_job, in this order.
constexpr const char* kJobColumns =
    "id, ord, status, created, started, finished, updated, message, steps, nodes, "
    "idempotency_key, last_seq, attempts, solve_seconds, iterations";

JobRecord read_job(const Statement& st, bool with_scene) {
  JobRecord j;
  j.id = st.text(0);
  j.ord = st.int64(1);
  j.status = parse_job_status(st.text(2)).value_or(JobStatus::failed);
  j.created = st.text(3);
  j.started = st.text(4);
  j.finished = st.text(5);
  j.updated = st.text(6);
  j.message = st.text(7);
  j.steps = static_cast<int>(st.int64(8));
  j.nodes = static_cast<int>(st.int64(9));
  j.idempotency_key = st.optional_text(10);
  j.last_seq = st.int64(11);
  j.attempts = static_cast<int>(st.int64(12));
  j.solve_seconds = st.real(13);
  j.iterations = st.int64(14);
  if (with_scene) j.scene = st.text(15);
  return j;
}

std::string select_job(bool with_scene, const char* where) {
  return std::string("SELECT ") + kJobColumns + (with_scene ? ", scene" : "") +
         " FROM jobs WHERE " + where;
}

}  // namespace

SqliteStore::SqliteStore(const std::string& path, int busy_timeout_ms) {
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  writer_ = std::make_unique<Database>(path, busy_timeout_ms);
  writer_->exec(kSchema);
  reader_ = std::make_unique<Database>(path, busy_timeout_ms);
}

void SqliteStore::insert_job(JobRecord& job) {
  std::lock_guard lock(write_mutex_);
  auto st = writer_->prepare(
      "INSERT INTO jobs (id, status, scene, created, updated, message, steps, nodes, "
      "idempotency_key) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
  st.bind(1, job.id).bind(2, to_string(job.status)).bind(3, job.scene).bind(4, job.created);
  st.bind(5, job.updated).bind(6, job.message).bind(7, job.steps).bind(8, job.nodes);
  st.bind(9, job.idempotency_key);
  st.run();
  job.ord = sqlite3_last_insert_rowid(writer_->handle());
}

std::optional<JobRecord> SqliteStore::job(const std::string& id, bool with_scene) {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare(select_job(with_scene, "id = ?"));
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  return read_job(st, with_scene);
}

std::optional<JobRecord> SqliteStore::job_by_idempotency_key(const std::string& key) {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare(select_job(true, "idempotency_key = ?"));
  st.bind(1, key);
  if (!st.step()) return std::nullopt;
  return read_job(st, true);
}

JobPage SqliteStore::list_jobs(std::optional<JobStatus> status, int limit,
                               std::optional<std::int64_t> before) {
  std::lock_guard lock(read_mutex_);
  std::string where = "ord < ?";
  if (status) where += " AND status = ?";
  auto st = reader_->prepare(select_job(false, where.c_str()) + " ORDER BY ord DESC LIMIT ?");
  st.bind(1, before.value_or(INT64_MAX));
  if (status) st.bind(2, to_string(*status));
  st.bind(status ? 3 : 2, limit + 1);  // one more tells whether a next page exists
  JobPage page;
  while (st.step()) page.jobs.push_back(read_job(st, false));
  if (static_cast<int>(page.jobs.size()) > limit) {
    page.jobs.pop_back();
    page.next_before = page.jobs.back().ord;
  }
  return page;
}

std::map<JobStatus, std::int64_t> SqliteStore::count_by_status() {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare("SELECT status, count(*) FROM jobs GROUP BY status");
  std::map<JobStatus, std::int64_t> counts;
  while (st.step())
    if (auto s = parse_job_status(st.text(0))) counts[*s] = st.int64(1);
  return counts;
}

bool SqliteStore::start_job(const std::string& id, const std::string& started) {
  std::lock_guard lock(write_mutex_);
  auto st = writer_->prepare(
      "UPDATE jobs SET status = 'running', started = ?1, updated = ?1, message = 'running', "
      "attempts = attempts + 1 WHERE id = ?2 AND status = 'accepted'");
  st.bind(1, started).bind(2, id).run();
  return writer_->changes() == 1;
}

bool SqliteStore::mark_dismissed(const std::string& id, const std::string& updated) {
  std::lock_guard lock(write_mutex_);
  auto st = writer_->prepare(
      "UPDATE jobs SET status = 'dismissed', updated = ?1, message = 'dismissed' "
      "WHERE id = ?2 AND status IN ('accepted', 'running')");
  st.bind(1, updated).bind(2, id).run();
  return writer_->changes() == 1;
}

void SqliteStore::append_events(const std::vector<NewEvent>& events) {
  if (events.empty()) return;
  std::lock_guard lock(write_mutex_);
  // Events commit without fsync: kill -9 cannot lose them (the WAL is in the OS's cache), and
  // the next synchronous=FULL commit of the same WAL (a job's finish) makes them durable on
  // disk before that job is reported finished. A running job's events are discarded at
  // recovery anyway.
  writer_->exec("PRAGMA synchronous=NORMAL");
  struct Restore {
    Database& db;
    ~Restore() {
      try {
        db.exec("PRAGMA synchronous=FULL");
      } catch (...) {
      }
    }
  } restore{*writer_};
  Transaction tx(*writer_);
  auto ins = writer_->prepare("INSERT INTO events (job_id, seq, type, data) VALUES (?, ?, ?, ?)");
  auto seq = writer_->prepare("UPDATE jobs SET last_seq = max(last_seq, ?) WHERE id = ?");
  for (size_t i = 0; i < events.size(); ++i) {
    const NewEvent& e = events[i];
    ins.reset();
    ins.bind(1, e.job_id).bind(2, e.event.seq).bind(3, e.event.type).bind(4, e.event.data).run();
    // last_seq once per job and batch: at the job's last event in the batch.
    bool last_of_job = true;
    for (size_t k = i + 1; k < events.size() && last_of_job; ++k)
      if (events[k].job_id == e.job_id) last_of_job = false;
    if (last_of_job) {
      seq.reset();
      seq.bind(1, e.event.seq).bind(2, e.job_id).run();
    }
  }
  tx.commit();
}

void SqliteStore::finish_job(const std::string& id, const JobOutcome& o) {
  std::lock_guard lock(write_mutex_);
  Transaction tx(*writer_);
  auto st = writer_->prepare(
      "UPDATE jobs SET status = ?1, message = ?2, finished = ?3, updated = ?3, "
      "solve_seconds = ?4, iterations = ?5, last_seq = max(last_seq, ?6) WHERE id = ?7");
  st.bind(1, to_string(o.status)).bind(2, o.message).bind(3, o.finished);
  st.bind(4, o.solve_seconds).bind(5, o.iterations);
  st.bind(6, o.terminal ? o.terminal->seq : std::int64_t{0}).bind(7, id).run();
  if (o.result) {
    auto r = writer_->prepare("INSERT OR REPLACE INTO results (job_id, data) VALUES (?, ?)");
    r.bind(1, id).bind(2, *o.result).run();
  }
  if (o.terminal) {
    auto e = writer_->prepare("INSERT INTO events (job_id, seq, type, data) VALUES (?, ?, ?, ?)");
    e.bind(1, id).bind(2, o.terminal->seq).bind(3, o.terminal->type).bind(4, o.terminal->data);
    e.run();
  }
  tx.commit();
}

void SqliteStore::requeue_job(const std::string& id, const std::string& updated) {
  std::lock_guard lock(write_mutex_);
  Transaction tx(*writer_);
  writer_->prepare("DELETE FROM events WHERE job_id = ?").bind(1, id).run();
  auto st = writer_->prepare(
      "UPDATE jobs SET status = 'accepted', started = NULL, updated = ?1, "
      "message = 'requeued after an interrupted run' WHERE id = ?2 AND status = 'running'");
  st.bind(1, updated).bind(2, id).run();
  tx.commit();
}

bool SqliteStore::delete_job(const std::string& id) {
  std::lock_guard lock(write_mutex_);
  Transaction tx(*writer_);
  writer_->prepare("DELETE FROM events WHERE job_id = ?").bind(1, id).run();
  writer_->prepare("DELETE FROM results WHERE job_id = ?").bind(1, id).run();
  writer_->prepare("DELETE FROM jobs WHERE id = ?").bind(1, id).run();
  const bool removed = writer_->changes() == 1;
  tx.commit();
  return removed;
}

std::vector<StoredEvent> SqliteStore::events_after(const std::string& id, std::int64_t after,
                                                   int limit, std::string_view type) {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare(
      type.empty()
          ? "SELECT seq, type, data FROM events WHERE job_id = ? AND seq > ? ORDER BY seq LIMIT ?"
          : "SELECT seq, type, data FROM events WHERE job_id = ? AND seq > ? AND type = ? "
            "ORDER BY seq LIMIT ?");
  st.bind(1, id);
  st.bind(2, after);
  if (!type.empty()) st.bind(3, type);
  st.bind(type.empty() ? 3 : 4, limit);
  std::vector<StoredEvent> out;
  while (st.step()) out.push_back({st.int64(0), st.text(1), st.text(2)});
  return out;
}

std::optional<std::string> SqliteStore::result(const std::string& id) {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare("SELECT data FROM results WHERE job_id = ?");
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  return st.text(0);
}

std::vector<std::string> SqliteStore::recover(const std::string& now,
                                              const std::string& terminal_for_dismissed) {
  std::lock_guard lock(write_mutex_);
  Transaction tx(*writer_);
  writer_->exec(
      "DELETE FROM events WHERE job_id IN (SELECT id FROM jobs WHERE status = 'running')");
  writer_->prepare(
             "UPDATE jobs SET status = 'accepted', started = NULL, updated = ?, "
             "message = 'requeued after an interrupted run' WHERE status = 'running'")
      .bind(1, now)
      .run();
  // Dismissed while running, then interrupted before the worker finished it.
  std::vector<std::pair<std::string, std::int64_t>> unfinished;
  {
    auto st = writer_->prepare(
        "SELECT id, last_seq FROM jobs WHERE status = 'dismissed' AND finished IS NULL");
    while (st.step()) unfinished.emplace_back(st.text(0), st.int64(1));
  }
  for (const auto& [id, last_seq] : unfinished) {
    writer_->prepare("INSERT INTO events (job_id, seq, type, data) VALUES (?, ?, 'job_failed', ?)")
        .bind(1, id)
        .bind(2, last_seq + 1)
        .bind(3, terminal_for_dismissed)
        .run();
    writer_->prepare("UPDATE jobs SET finished = ?1, updated = ?1, last_seq = ?2 WHERE id = ?3")
        .bind(1, now)
        .bind(2, last_seq + 1)
        .bind(3, id)
        .run();
  }
  std::vector<std::string> accepted;
  {
    auto st = writer_->prepare("SELECT id FROM jobs WHERE status = 'accepted' ORDER BY ord");
    while (st.step()) accepted.push_back(st.text(0));
  }
  tx.commit();
  return accepted;
}

}  // namespace grip::server
