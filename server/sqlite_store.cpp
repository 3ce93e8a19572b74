#include "server/sqlite_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <set>
#include <thread>

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
  iterations INTEGER NOT NULL DEFAULT 0,
  owner TEXT NOT NULL DEFAULT '',
  generation INTEGER NOT NULL DEFAULT 0,
  lease_expires REAL NOT NULL DEFAULT 0,
  failure_kind TEXT NOT NULL DEFAULT '',
  failure_step INTEGER NOT NULL DEFAULT 0,
  steps_completed INTEGER NOT NULL DEFAULT 0,
  stored_bytes INTEGER NOT NULL DEFAULT 0,
  request_id TEXT NOT NULL DEFAULT ''
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
CREATE TABLE IF NOT EXISTS meshes (
  id TEXT PRIMARY KEY,
  bytes INTEGER NOT NULL,
  data BLOB NOT NULL,
  summary TEXT NOT NULL,
  created TEXT NOT NULL,
  used TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS job_meshes (
  job_id TEXT NOT NULL,
  mesh_id TEXT NOT NULL,
  PRIMARY KEY (job_id, mesh_id)
) WITHOUT ROWID;
CREATE INDEX IF NOT EXISTS job_meshes_by_mesh ON job_meshes (mesh_id);
CREATE TABLE IF NOT EXISTS studies (
  id TEXT PRIMARY KEY,
  created TEXT NOT NULL,
  document TEXT NOT NULL
);
)sql";

// Schema 1 (before leases) to 2.
constexpr const char* kUpgrade1to2 = R"sql(
ALTER TABLE jobs ADD COLUMN owner TEXT NOT NULL DEFAULT '';
ALTER TABLE jobs ADD COLUMN generation INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN lease_expires REAL NOT NULL DEFAULT 0;
)sql";

// Schema 2 to 3 (failure kinds, converged steps of a finished job).
constexpr const char* kUpgrade2to3 = R"sql(
ALTER TABLE jobs ADD COLUMN failure_kind TEXT NOT NULL DEFAULT '';
ALTER TABLE jobs ADD COLUMN failure_step INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN steps_completed INTEGER NOT NULL DEFAULT 0;
)sql";

// Schema 3 to 4: the bytes a finished job stores, the request that submitted it.
constexpr const char* kUpgrade3to4 =
    "ALTER TABLE jobs ADD COLUMN stored_bytes INTEGER NOT NULL DEFAULT 0;"
    "ALTER TABLE jobs ADD COLUMN request_id TEXT NOT NULL DEFAULT '';";

// Columns read by read_job, in this order.
constexpr const char* kJobColumns =
    "id, ord, status, created, started, finished, updated, message, steps, nodes, "
    "idempotency_key, last_seq, attempts, solve_seconds, iterations, owner, generation, failure_kind, "
    "failure_step, steps_completed, stored_bytes, request_id";

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
  j.owner = st.text(15);
  j.generation = st.int64(16);
  j.failure_kind = st.text(17);
  j.failure_step = static_cast<int>(st.int64(18));
  j.steps_completed = static_cast<int>(st.int64(19));
  j.stored_bytes = st.int64(20);
  j.request_id = st.text(21);
  if (with_scene) j.scene = st.text(22);
  return j;
}

std::string select_job(bool with_scene, const char* where) {
  return std::string("SELECT ") + kJobColumns + (with_scene ? ", scene" : "") + " FROM jobs WHERE " + where;
}

// Unix time in seconds: lease expiry (one process, one clock).
double unix_now() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

void insert_event(Database& db, const std::string& id, const StoredEvent& e) {
  db.prepare("INSERT INTO events (job_id, seq, type, data) VALUES (?, ?, ?, ?)")
      .bind(1, id)
      .bind(2, e.seq)
      .bind(3, e.type)
      .bind(4, e.data)
      .run();
}

}  // namespace

SqliteStore::SqliteStore(const std::string& path, int busy_timeout_ms) {
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  // NORMAL: claims, renewals, event batches and submissions (fsynced after) commit without
  // fsync; a job's end and the rarer writes switch to FULL for their commit.
  writer_ = std::make_unique<Database>(path, busy_timeout_ms, "NORMAL");
  {
    auto v = writer_->prepare("PRAGMA user_version");
    v.step();
    const bool has_jobs = [&] {
      auto t = writer_->prepare("SELECT count(*) FROM sqlite_master WHERE name = 'jobs'");
      t.step();
      return t.int64(0) > 0;
    }();
    if (has_jobs && v.int64(0) < 2) writer_->exec(kUpgrade1to2);
    if (has_jobs && v.int64(0) < 3) writer_->exec(kUpgrade2to3);
    if (has_jobs && v.int64(0) < 4) writer_->exec(kUpgrade3to4);
  }
  // Pages freed by removals go back to the file system at each prune (incremental_vacuum);
  // a file made without it switches once, by a VACUUM that rewrites it.
  const std::int64_t vacuum_mode = [&] {
    auto mode = writer_->prepare("PRAGMA auto_vacuum");
    mode.step();
    return mode.int64(0);
  }();
  if (vacuum_mode != 2) {
    writer_->exec("PRAGMA auto_vacuum = INCREMENTAL");
    writer_->exec("VACUUM");
  }
  writer_->exec(kSchema);
  writer_->exec("PRAGMA user_version = 4");
  // The file is this process's alone: whatever a previous process held is free now.
  writer_->exec("UPDATE jobs SET lease_expires = 0 WHERE finished IS NULL");
  reader_ = std::make_unique<Database>(path, busy_timeout_ms);
  // The writes above made the WAL file; it stays while the connections are open.
  wal_fd_ = ::open((path + "-wal").c_str(), O_RDONLY | O_CLOEXEC);
}

SqliteStore::~SqliteStore() {
  if (wal_fd_ >= 0) ::close(wal_fd_);
}

void SqliteStore::set_listener(std::function<void(const StoreChange&)> listener) {
  std::lock_guard lock(listener_mutex_);
  listener_ = std::move(listener);
}

void SqliteStore::announce(StoreChange::Kind kind, const std::string& job_id) {
  std::function<void(const StoreChange&)> l;
  {
    std::lock_guard lock(listener_mutex_);
    l = listener_;
  }
  if (l) l(StoreChange{kind, job_id});
}

void SqliteStore::insert_job(JobRecord& job) {
  // Committed without fsync under the writer's lock, then fsynced outside it: an fsync (1-4 ms
  // here) held the lock that every other submission, claim and finish waits for. The commit's
  // frames are in the WAL file when it returns; fdatasync on any descriptor of that file puts
  // them on disk, and a checkpoint in between has synced them into the database file first.
  const bool sync_after = wal_fd_ >= 0;
  {
    std::lock_guard lock(write_mutex_);
    Transaction tx(*writer_, sync_after ? Transaction::Sync::relaxed : Transaction::Sync::full);
    {
      auto st = writer_->prepare(
          "INSERT INTO jobs (id, status, scene, created, updated, message, steps, nodes, "
          "idempotency_key, request_id) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
      st.bind(1, job.id).bind(2, to_string(job.status)).bind(3, job.scene).bind(4, job.created);
      st.bind(5, job.updated).bind(6, job.message).bind(7, job.steps).bind(8, job.nodes);
      st.bind(9, job.idempotency_key).bind(10, job.request_id);
      st.run();
      job.ord = sqlite3_last_insert_rowid(writer_->handle());
    }
    for (const std::string& mesh : job.meshes) {
      writer_->prepare("INSERT OR IGNORE INTO job_meshes (job_id, mesh_id) VALUES (?, ?)")
          .bind(1, job.id)
          .bind(2, mesh)
          .run();
      writer_->prepare("UPDATE meshes SET used = ? WHERE id = ?").bind(1, job.created).bind(2, mesh).run();
    }
    tx.commit();
  }
  if (sync_after && ::fdatasync(wal_fd_) != 0)
    throw SqliteError(std::string("fsync of the job store's WAL failed: ") + std::strerror(errno));
  announce(StoreChange::job, job.id);
}

std::optional<JobRecord> SqliteStore::job_locked(Database& db, const std::string& id, bool with_scene) {
  auto st = db.prepare(select_job(with_scene, "id = ?"));
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  return read_job(st, with_scene);
}

std::optional<JobRecord> SqliteStore::job(const std::string& id, bool with_scene) {
  std::lock_guard lock(read_mutex_);
  return job_locked(*reader_, id, with_scene);
}

std::optional<JobRecord> SqliteStore::job_by_idempotency_key(const std::string& key) {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare(select_job(true, "idempotency_key = ?"));
  st.bind(1, key);
  if (!st.step()) return std::nullopt;
  return read_job(st, true);
}

JobPage SqliteStore::list_jobs(std::optional<JobStatus> status, int limit, std::optional<std::int64_t> before) {
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

std::int64_t SqliteStore::count_accepted() {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare("SELECT count(*) FROM jobs WHERE status = 'accepted'");
  st.step();
  return st.int64(0);
}

std::optional<JobRecord> SqliteStore::claim_job(const std::string& owner, const std::string& now,
                                                double lease_seconds) {
  std::optional<JobRecord> claimed;
  {
    std::lock_guard lock(write_mutex_);
    // Without fsync: a claim lost to a power cut leaves the job accepted, as recovery would
    // make it anyway (its run starts again); the finish's FULL commit makes it durable.
    Transaction tx(*writer_, Transaction::Sync::relaxed);
    std::string id;
    {
      auto st = writer_->prepare("SELECT id FROM jobs WHERE status = 'accepted' ORDER BY ord LIMIT 1");
      if (!st.step()) return std::nullopt;
      id = st.text(0);
    }
    writer_
        ->prepare(
            "UPDATE jobs SET status = 'running', started = ?1, updated = ?1, message = 'running', "
            "attempts = attempts + 1, generation = generation + 1, owner = ?2, lease_expires = ?3 "
            "WHERE id = ?4")
        .bind(1, now)
        .bind(2, owner)
        .bind(3, unix_now() + lease_seconds)
        .bind(4, id)
        .run();
    claimed = job_locked(*writer_, id, true);
    tx.commit();
  }
  announce(StoreChange::job, claimed->id);
  return claimed;
}

LeaseRenewal SqliteStore::renew_leases(const std::string& owner, const std::vector<Lease>& leases,
                                       double lease_seconds) {
  LeaseRenewal r;
  if (leases.empty()) return r;
  std::lock_guard lock(write_mutex_);
  // Without fsync: a restarted server frees every lease of the file anyway (the constructor).
  Transaction tx(*writer_, Transaction::Sync::relaxed);
  for (const Lease& l : leases) {
    writer_
        ->prepare(
            "UPDATE jobs SET lease_expires = ?1 WHERE id = ?2 AND generation = ?3 AND owner = ?4 "
            "AND finished IS NULL AND status IN ('running', 'dismissed')")
        .bind(1, unix_now() + lease_seconds)
        .bind(2, l.job_id)
        .bind(3, l.generation)
        .bind(4, owner)
        .run();
    if (writer_->changes() != 1) continue;
    r.held.push_back(l);
    auto st = writer_->prepare("SELECT status FROM jobs WHERE id = ?");
    st.bind(1, l.job_id);
    if (st.step() && st.text(0) == "dismissed") r.dismissed.push_back(l.job_id);
  }
  tx.commit();
  return r;
}

void SqliteStore::release_leases(const std::string& owner) {
  std::lock_guard lock(write_mutex_);
  writer_->prepare("UPDATE jobs SET lease_expires = 0 WHERE owner = ? AND finished IS NULL").bind(1, owner).run();
}

int SqliteStore::requeue_expired(const std::string& now) {
  int changed = 0;
  {
    std::lock_guard lock(write_mutex_);
    Transaction tx(*writer_);
    const double t = unix_now();
    writer_
        ->prepare(
            "DELETE FROM events WHERE job_id IN (SELECT id FROM jobs WHERE status = 'running' "
            "AND lease_expires < ?)")
        .bind(1, t)
        .run();
    writer_
        ->prepare(
            "UPDATE jobs SET status = 'accepted', started = NULL, updated = ?1, "
            "message = 'requeued after an interrupted run' WHERE status = 'running' "
            "AND lease_expires < ?2")
        .bind(1, now)
        .bind(2, t)
        .run();
    changed += static_cast<int>(writer_->changes());
    // Dismissed while running, then its runner went away before finishing it.
    std::vector<std::pair<std::string, std::int64_t>> unfinished;
    {
      auto st = writer_->prepare(
          "SELECT id, last_seq FROM jobs WHERE status = 'dismissed' AND finished IS NULL "
          "AND lease_expires < ?");
      st.bind(1, t);
      while (st.step()) unfinished.emplace_back(st.text(0), st.int64(1));
    }
    for (const auto& [id, last_seq] : unfinished) {
      insert_event(*writer_, id, {last_seq + 1, "job_failed", std::string(kDismissedEvent)});
      writer_->prepare("UPDATE jobs SET finished = ?1, updated = ?1, last_seq = ?2 WHERE id = ?3")
          .bind(1, now)
          .bind(2, last_seq + 1)
          .bind(3, id)
          .run();
    }
    changed += static_cast<int>(unfinished.size());
    tx.commit();
  }
  if (changed > 0) announce(StoreChange::job, "");
  return changed;
}

std::vector<Lease> SqliteStore::append_events(const std::vector<NewEvent>& events) {
  if (events.empty()) return {};
  // The highest seq per run in this batch.
  std::map<std::pair<std::string, std::int64_t>, std::int64_t> runs;
  for (const NewEvent& e : events) {
    auto& top = runs[{e.lease.job_id, e.lease.generation}];
    top = std::max(top, e.event.seq);
  }
  std::vector<Lease> refused;
  {
    std::lock_guard lock(write_mutex_);
    // Events commit without fsync: kill -9 cannot lose them (the WAL is in the OS's cache),
    // and the next synchronous=FULL commit of the same WAL (a job's finish) makes them
    // durable on disk before that job is reported finished. A running job's events are
    // discarded when it is requeued anyway.
    Transaction tx(*writer_, Transaction::Sync::relaxed);
    std::set<std::pair<std::string, std::int64_t>> stale;
    auto seq = writer_->prepare(
        "UPDATE jobs SET last_seq = max(last_seq, ?) WHERE id = ? AND generation = ? "
        "AND finished IS NULL AND status IN ('running', 'dismissed')");
    for (const auto& [run, top] : runs) {
      seq.reset();
      seq.bind(1, top).bind(2, run.first).bind(3, run.second).run();
      if (writer_->changes() != 1) {
        stale.insert(run);
        refused.push_back({run.first, run.second});
      }
    }
    auto ins = writer_->prepare("INSERT INTO events (job_id, seq, type, data) VALUES (?, ?, ?, ?)");
    for (const NewEvent& e : events) {
      if (stale.count({e.lease.job_id, e.lease.generation})) continue;
      ins.reset();
      ins.bind(1, e.lease.job_id).bind(2, e.event.seq).bind(3, e.event.type).bind(4, e.event.data).run();
    }
    tx.commit();
  }
  for (const auto& [run, top] : runs) announce(StoreChange::events, run.first);
  return refused;
}

std::optional<FinishStored> SqliteStore::finish_job(const Lease& lease, const JobOutcome& o) {
  FinishStored finished{o.status};
  {
    std::lock_guard lock(write_mutex_);
    Transaction tx(*writer_);
    std::string status;
    {
      auto st = writer_->prepare("SELECT status FROM jobs WHERE id = ? AND generation = ? AND finished IS NULL");
      st.bind(1, lease.job_id).bind(2, lease.generation);
      if (!st.step()) return std::nullopt;
      status = st.text(0);
    }
    if (status != "running" && status != "dismissed") return std::nullopt;
    const bool dismissed = status == "dismissed" || o.status == JobStatus::dismissed;
    if (dismissed) finished.status = JobStatus::dismissed;
    StoredEvent terminal = o.terminal;
    if (dismissed) terminal = {o.terminal.seq, "job_failed", std::string(kDismissedEvent)};
    writer_
        ->prepare(
            "UPDATE jobs SET status = ?1, message = ?2, finished = ?3, updated = ?3, "
            "solve_seconds = ?4, iterations = ?5, last_seq = max(last_seq, ?6), failure_kind = ?8, "
            "failure_step = ?9, steps_completed = ?10 WHERE id = ?7")
        .bind(1, to_string(finished.status))
        .bind(2, dismissed ? std::string("dismissed") : o.message)
        .bind(3, o.finished)
        .bind(4, o.solve_seconds)
        .bind(5, o.iterations)
        .bind(6, terminal.seq)
        .bind(7, lease.job_id)
        .bind(8, dismissed ? std::string("dismissed") : o.failure_kind)
        .bind(9, dismissed ? 0 : o.failure_step)
        .bind(10, o.steps_completed)
        .run();
    if (o.result && !dismissed)
      writer_->prepare("INSERT OR REPLACE INTO results (job_id, data) VALUES (?, ?)")
          .bind(1, lease.job_id)
          .bind_blob(2, *o.result)
          .run();
    insert_event(*writer_, lease.job_id, terminal);
    {
      auto st = writer_->prepare(
          "UPDATE jobs SET stored_bytes = length(CAST(scene AS BLOB)) + "
          "coalesce((SELECT length(CAST(data AS BLOB)) FROM results WHERE job_id = ?1), 0) + "
          "coalesce((SELECT sum(length(CAST(data AS BLOB))) FROM events WHERE job_id = ?1), 0) WHERE id = ?1 "
          "RETURNING stored_bytes");
      st.bind(1, lease.job_id);
      if (st.step()) finished.stored_bytes = st.int64(0);
    }
    tx.commit();
  }
  announce(StoreChange::events, lease.job_id);
  return finished;
}

bool SqliteStore::requeue_job(const Lease& lease, const std::string& updated) {
  bool done = false;
  {
    std::lock_guard lock(write_mutex_);
    Transaction tx(*writer_);
    writer_
        ->prepare(
            "UPDATE jobs SET status = 'accepted', started = NULL, updated = ?1, "
            "message = 'requeued after an interrupted run' WHERE id = ?2 AND generation = ?3 "
            "AND status = 'running'")
        .bind(1, updated)
        .bind(2, lease.job_id)
        .bind(3, lease.generation)
        .run();
    done = writer_->changes() == 1;
    if (done) writer_->prepare("DELETE FROM events WHERE job_id = ?").bind(1, lease.job_id).run();
    tx.commit();
  }
  if (done) announce(StoreChange::job, lease.job_id);
  return done;
}

std::pair<DismissOutcome, std::optional<JobRecord>> SqliteStore::dismiss_job(const std::string& id,
                                                                             const std::string& now) {
  std::pair<DismissOutcome, std::optional<JobRecord>> out{DismissOutcome::not_found, std::nullopt};
  {
    std::lock_guard lock(write_mutex_);
    Transaction tx(*writer_);
    auto rec = job_locked(*writer_, id, false);
    if (!rec) return out;
    if (rec->status == JobStatus::accepted) {
      const std::int64_t seq = rec->last_seq + 1;
      writer_
          ->prepare(
              "UPDATE jobs SET status = 'dismissed', message = 'dismissed before it started', "
              "finished = ?1, updated = ?1, last_seq = ?2 WHERE id = ?3")
          .bind(1, now)
          .bind(2, seq)
          .bind(3, id)
          .run();
      insert_event(*writer_, id, {seq, "job_failed", std::string(kDismissedEvent)});
      out = {DismissOutcome::dismissed, job_locked(*writer_, id, false)};
    } else if (!is_finished(rec->status) || rec->finished.empty()) {
      writer_->prepare("UPDATE jobs SET status = 'dismissed', message = 'dismissed', updated = ? WHERE id = ?")
          .bind(1, now)
          .bind(2, id)
          .run();
      out = {DismissOutcome::dismissed, job_locked(*writer_, id, false)};
    } else {
      writer_->prepare("DELETE FROM events WHERE job_id = ?").bind(1, id).run();
      writer_->prepare("DELETE FROM results WHERE job_id = ?").bind(1, id).run();
      writer_->prepare("DELETE FROM job_meshes WHERE job_id = ?").bind(1, id).run();
      writer_->prepare("DELETE FROM jobs WHERE id = ?").bind(1, id).run();
      out = {DismissOutcome::removed, rec};
    }
    tx.commit();
  }
  announce(out.first == DismissOutcome::dismissed ? StoreChange::dismissed : StoreChange::job, id);
  return out;
}

std::vector<StoredEvent> SqliteStore::events_after(const std::string& id, std::int64_t after, int limit,
                                                   std::string_view type) {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare(
      type.empty() ? "SELECT seq, type, data FROM events WHERE job_id = ? AND seq > ? ORDER BY seq LIMIT ?"
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
  return st.blob(0);
}

namespace {

constexpr size_t kPruneBatch = 50;  // jobs removed per write transaction (some 35 ms)

}  // namespace

std::int64_t SqliteStore::prune(const Retention& retention, const std::string& now) {
  if (!retention.any()) return 0;
  std::vector<FinishedJob> finished;
  {
    std::lock_guard lock(read_mutex_);
    auto st = reader_->prepare(
        "SELECT id, status, finished, stored_bytes FROM jobs WHERE finished IS NOT NULL AND "
        "status IN ('successful', 'failed', 'dismissed') ORDER BY status = 'dismissed', ord DESC");
    while (st.step()) finished.push_back({st.text(0), st.text(1) == "dismissed", st.text(2), st.int64(3)});
  }
  const std::string cutoff = retention_cutoff(retention, now);
  const std::vector<std::string> gone = beyond_retention(finished, retention, cutoff);
  if (gone.empty()) {
    prune_meshes(cutoff);
    return 0;
  }
  // In batches, each its own transaction and vacuum, with a pause between them: the one
  // writer is everyone's (submissions, events, finishes), and a pass that removed 2,800 jobs
  // in one transaction held it 1.9 s, which the jobs finishing meanwhile waited out.
  for (size_t from = 0; from < gone.size(); from += kPruneBatch) {
    if (from > 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    std::lock_guard lock(write_mutex_);
    Transaction tx(*writer_);
    auto events = writer_->prepare("DELETE FROM events WHERE job_id = ?");
    auto results = writer_->prepare("DELETE FROM results WHERE job_id = ?");
    auto uses = writer_->prepare("DELETE FROM job_meshes WHERE job_id = ?");
    auto jobs = writer_->prepare("DELETE FROM jobs WHERE id = ? AND finished IS NOT NULL");
    for (size_t i = from; i < std::min(gone.size(), from + kPruneBatch); ++i)
      for (Statement* st : {&events, &results, &uses, &jobs}) {
        st->reset();
        st->bind(1, gone[i]).run();
      }
    tx.commit();
    writer_->exec("PRAGMA incremental_vacuum");
  }
  prune_meshes(cutoff);
  announce(StoreChange::job, "");
  return static_cast<std::int64_t>(gone.size());
}

void SqliteStore::prune_meshes(const std::string& cutoff) {
  if (cutoff.empty()) return;
  std::lock_guard lock(write_mutex_);
  writer_
      ->prepare(
          "DELETE FROM meshes WHERE used < ? AND NOT EXISTS (SELECT 1 FROM job_meshes u WHERE u.mesh_id = meshes.id)")
      .bind(1, cutoff)
      .run();
  if (writer_->changes() > 0) writer_->exec("PRAGMA incremental_vacuum");
}

bool SqliteStore::put_mesh(const MeshRecord& mesh, const std::string& data) {
  std::lock_guard lock(write_mutex_);
  writer_
      ->prepare(
          "INSERT INTO meshes (id, bytes, data, summary, created, used) VALUES (?1, ?2, ?3, ?4, ?5, ?5) "
          "ON CONFLICT (id) DO NOTHING")
      .bind(1, mesh.id)
      .bind(2, mesh.bytes)
      .bind_blob(3, data)
      .bind(4, mesh.summary)
      .bind(5, mesh.created)
      .run();
  return writer_->changes() == 1;
}

void SqliteStore::insert_study(const StudyRecord& study) {
  std::lock_guard lock(write_mutex_);
  writer_->prepare("INSERT INTO studies (id, created, document) VALUES (?, ?, ?)")
      .bind(1, study.id)
      .bind(2, study.created)
      .bind(3, study.document)
      .run();
}

std::optional<StudyRecord> SqliteStore::study(const std::string& id) {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare("SELECT id, created, document FROM studies WHERE id = ?");
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  return StudyRecord{st.text(0), st.text(1), st.text(2)};
}

bool SqliteStore::remove_study(const std::string& id) {
  std::lock_guard lock(write_mutex_);
  writer_->prepare("DELETE FROM studies WHERE id = ?").bind(1, id).run();
  return writer_->changes() == 1;
}

std::optional<MeshRecord> SqliteStore::mesh(const std::string& id) {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare("SELECT id, bytes, length(data), summary, created FROM meshes WHERE id = ?");
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  return MeshRecord{st.text(0), st.int64(1), st.int64(2), st.text(3), st.text(4)};
}

std::optional<std::string> SqliteStore::mesh_data(const std::string& id) {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare("SELECT data FROM meshes WHERE id = ?");
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  return st.blob(0);
}

MeshRemoval SqliteStore::remove_mesh(const std::string& id) {
  std::lock_guard lock(write_mutex_);
  Transaction tx(*writer_);
  {
    auto st = writer_->prepare(
        "SELECT (SELECT count(*) FROM meshes WHERE id = ?1), "
        "(SELECT count(*) FROM job_meshes WHERE mesh_id = ?1)");
    st.bind(1, id);
    st.step();
    if (st.int64(0) == 0) return MeshRemoval::not_found;
    if (st.int64(1) > 0) return MeshRemoval::in_use;
  }
  writer_->prepare("DELETE FROM meshes WHERE id = ?").bind(1, id).run();
  tx.commit();
  return MeshRemoval::removed;
}

std::pair<std::int64_t, std::int64_t> SqliteStore::mesh_totals() {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare("SELECT count(*), coalesce(sum(length(data)), 0) FROM meshes");
  st.step();
  return {st.int64(0), st.int64(1)};
}

std::int64_t SqliteStore::disk_bytes() {
  std::lock_guard lock(read_mutex_);
  auto st = reader_->prepare("SELECT page_count * page_size FROM pragma_page_count(), pragma_page_size()");
  return st.step() ? st.int64(0) : 0;
}

}  // namespace grip::server
