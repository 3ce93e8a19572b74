#include "server/postgres_store.hpp"

#include <libpq-fe.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <condition_variable>
#include <regex>
#include <vector>

namespace grip::server {

namespace {

using Clock = std::chrono::steady_clock;

constexpr const char* kSchema = R"sql(
SELECT pg_advisory_xact_lock(717017);
CREATE TABLE IF NOT EXISTS grip_jobs (
  ord BIGSERIAL PRIMARY KEY,
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
  last_seq BIGINT NOT NULL DEFAULT 0,
  attempts INTEGER NOT NULL DEFAULT 0,
  solve_seconds DOUBLE PRECISION NOT NULL DEFAULT 0,
  iterations BIGINT NOT NULL DEFAULT 0,
  owner TEXT NOT NULL DEFAULT '',
  generation BIGINT NOT NULL DEFAULT 0,
  lease_expires TIMESTAMPTZ
);
ALTER TABLE grip_jobs ADD COLUMN IF NOT EXISTS failure_kind TEXT NOT NULL DEFAULT '';
ALTER TABLE grip_jobs ADD COLUMN IF NOT EXISTS failure_step INTEGER NOT NULL DEFAULT 0;
ALTER TABLE grip_jobs ADD COLUMN IF NOT EXISTS steps_completed INTEGER NOT NULL DEFAULT 0;
CREATE INDEX IF NOT EXISTS grip_jobs_by_status ON grip_jobs (status, ord);
CREATE TABLE IF NOT EXISTS grip_events (
  job_id TEXT NOT NULL,
  seq BIGINT NOT NULL,
  type TEXT NOT NULL,
  data TEXT NOT NULL,
  PRIMARY KEY (job_id, seq)
);
CREATE TABLE IF NOT EXISTS grip_results (
  job_id TEXT PRIMARY KEY,
  data TEXT NOT NULL
);
-- Results as stored bytes (zstd; gzip from earlier versions) in `bytes`; `data` holds those stored before as JSON text.
ALTER TABLE grip_results ADD COLUMN IF NOT EXISTS bytes BYTEA;
ALTER TABLE grip_results ALTER COLUMN data DROP NOT NULL;
ALTER TABLE grip_jobs ADD COLUMN IF NOT EXISTS stored_bytes BIGINT NOT NULL DEFAULT 0;
ALTER TABLE grip_jobs ADD COLUMN IF NOT EXISTS request_id TEXT NOT NULL DEFAULT '';
CREATE TABLE IF NOT EXISTS grip_meshes (
  id TEXT PRIMARY KEY,
  bytes BIGINT NOT NULL,
  data BYTEA NOT NULL,
  summary TEXT NOT NULL,
  created TEXT NOT NULL,
  used TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS grip_job_meshes (
  job_id TEXT NOT NULL,
  mesh_id TEXT NOT NULL,
  PRIMARY KEY (job_id, mesh_id)
);
CREATE INDEX IF NOT EXISTS grip_job_meshes_by_mesh ON grip_job_meshes (mesh_id);
CREATE TABLE IF NOT EXISTS grip_studies (
  id TEXT PRIMARY KEY,
  created TEXT NOT NULL,
  document TEXT NOT NULL
);
)sql";

// Columns read by read_job, in this order.
constexpr const char* kJobColumns =
    "id, ord, status, created, started, finished, updated, message, steps, nodes, "
    "idempotency_key, last_seq, attempts, solve_seconds, iterations, owner, generation, failure_kind, "
    "failure_step, steps_completed, stored_bytes, request_id";

using Param = std::optional<std::string>;

// SQLSTATEs that mean "the database is not there (now)": connection exceptions (08),
// operator intervention (57: shutdown, cannot connect now), too many connections (53300).
bool unavailable_state(const std::string& state) {
  return state.rfind("08", 0) == 0 || state.rfind("57", 0) == 0 || state == "53300";
}

}  // namespace

// One libpq connection, (re)connected on demand.
struct PostgresStore::Connection {
  PGconn* conn = nullptr;
  ~Connection() {
    if (conn) PQfinish(conn);
  }
};

struct PostgresStore::Pool {
  std::string url;
  std::mutex mutex;
  std::condition_variable freed;
  std::vector<std::unique_ptr<Connection>> idle;
  int size = 0;
  int created = 0;
  Clock::time_point retry_at{};  // after a failed connection attempt: fail fast until then
  std::atomic<std::int64_t> round_trips{0};
  std::atomic<std::int64_t> bytes{0};

  PGconn* connect() {
    const char* keys[] = {"dbname", "connect_timeout", "application_name", nullptr};
    const char* values[] = {url.c_str(), "3", "grip", nullptr};
    PGconn* c = PQconnectdbParams(keys, values, 1);
    if (PQstatus(c) != CONNECTION_OK) {
      std::string msg = PQerrorMessage(c);
      PQfinish(c);
      while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
      throw StoreUnavailable("cannot connect to the database: " + msg);
    }
    PQexec(c, "SET client_min_messages = warning");
    return c;
  }

  // A connection now, or StoreUnavailable (and fail fast for a second).
  PGconn* reconnect() {
    {
      std::lock_guard lock(mutex);
      if (Clock::now() < retry_at) throw StoreUnavailable("the database does not answer");
    }
    try {
      return connect();
    } catch (...) {
      std::lock_guard lock(mutex);
      retry_at = Clock::now() + std::chrono::seconds(1);
      throw;
    }
  }

  std::unique_ptr<Connection> take() {
    std::unique_lock lock(mutex);
    freed.wait(lock, [&] { return !idle.empty() || created < size; });
    std::unique_ptr<Connection> c;
    if (!idle.empty()) {
      c = std::move(idle.back());
      idle.pop_back();
    } else {
      c = std::make_unique<Connection>();
      ++created;
    }
    if (c->conn && PQstatus(c->conn) == CONNECTION_OK) return c;
    // (Re)connect, unless an attempt just failed.
    if (Clock::now() < retry_at) {
      idle.push_back(std::move(c));
      freed.notify_one();
      throw StoreUnavailable("the database does not answer");
    }
    lock.unlock();
    try {
      if (c->conn) PQfinish(c->conn);
      c->conn = nullptr;
      c->conn = connect();
    } catch (...) {
      lock.lock();
      retry_at = Clock::now() + std::chrono::seconds(1);
      idle.push_back(std::move(c));
      freed.notify_one();
      throw;
    }
    return c;
  }

  void give(std::unique_ptr<Connection> c) {
    std::lock_guard lock(mutex);
    idle.push_back(std::move(c));
    freed.notify_one();
  }
};

namespace {

// A query's result, owned.
class Result {
 public:
  explicit Result(PGresult* r) : r_(r) {}
  ~Result() { PQclear(r_); }
  Result(Result&& o) noexcept : r_(o.r_) { o.r_ = nullptr; }
  Result(const Result&) = delete;
  Result& operator=(const Result&) = delete;
  int rows() const { return PQntuples(r_); }
  bool null(int row, int col) const { return PQgetisnull(r_, row, col); }
  std::string text(int row, int col) const { return std::string(PQgetvalue(r_, row, col), PQgetlength(r_, row, col)); }
  std::optional<std::string> optional_text(int row, int col) const {
    if (null(row, col)) return std::nullopt;
    return text(row, col);
  }
  std::int64_t int64(int row, int col) const { return null(row, col) ? 0 : std::stoll(text(row, col)); }
  double real(int row, int col) const { return null(row, col) ? 0.0 : std::stod(text(row, col)); }

 private:
  PGresult* r_;
};

// A borrowed connection; queries through it throw StoreUnavailable when the database went
// away (the connection is then reset at its next use) and std::runtime_error otherwise.
class Session {
 public:
  explicit Session(PostgresStore::Pool& pool) : pool_(pool), c_(pool.take()) {}
  ~Session() {
    if (in_transaction_) {
      PGresult* r = PQexec(c_->conn, "ROLLBACK");
      PQclear(r);
    }
    pool_.give(std::move(c_));
  }
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  Result query(const char* sql, const std::vector<Param>& params = {}) {
    std::vector<const char*> values;
    std::int64_t sent = static_cast<std::int64_t>(std::char_traits<char>::length(sql));
    for (const Param& p : params) {
      values.push_back(p ? p->c_str() : nullptr);
      if (p) sent += static_cast<std::int64_t>(p->size());
    }
    PGresult* raw =
        PQexecParams(c_->conn, sql, static_cast<int>(values.size()), nullptr, values.data(), nullptr, nullptr, 0);
    // A pooled connection that the database dropped while idle (it restarted) fails its first
    // statement: connect again and send that statement once more. Statements whose reply
    // could have been lost with a commit are safe to repeat (events: ON CONFLICT DO NOTHING;
    // a job: its unique id; a finish: fenced).
    if (first_ && !in_transaction_ && PQstatus(c_->conn) != CONNECTION_OK) {
      PQclear(raw);
      PQfinish(c_->conn);
      c_->conn = nullptr;
      c_->conn = pool_.reconnect();
      raw = PQexecParams(c_->conn, sql, static_cast<int>(values.size()), nullptr, values.data(), nullptr, nullptr, 0);
    }
    first_ = false;
    Result r(raw);
    ++pool_.round_trips;
    std::int64_t received = 0;
    const auto status = PQresultStatus(raw);
    if (status == PGRES_TUPLES_OK)
      for (int i = 0; i < r.rows(); ++i)
        for (int k = 0; k < PQnfields(raw); ++k) received += PQgetlength(raw, i, k);
    pool_.bytes += sent + received;
    if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return r;
    const char* state = raw ? PQresultErrorField(raw, PG_DIAG_SQLSTATE) : nullptr;
    std::string message = raw ? PQresultErrorMessage(raw) : PQerrorMessage(c_->conn);
    while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
    if (PQstatus(c_->conn) != CONNECTION_OK || (state && unavailable_state(state)) || !raw) {
      in_transaction_ = false;
      throw StoreUnavailable("database: " + message);
    }
    throw std::runtime_error("database: " + message);
  }
  // Several statements, no parameters (the schema).
  void script(const char* sql) {
    PGresult* raw = PQexec(c_->conn, sql);
    Result r(raw);
    ++pool_.round_trips;
    if (PQresultStatus(raw) == PGRES_COMMAND_OK || PQresultStatus(raw) == PGRES_TUPLES_OK) return;
    const std::string message = PQerrorMessage(c_->conn);
    if (PQstatus(c_->conn) != CONNECTION_OK) throw StoreUnavailable("database: " + message);
    throw std::runtime_error("database: " + message);
  }
  void begin() {
    query("BEGIN");
    in_transaction_ = true;
  }
  void commit() {
    query("COMMIT");
    in_transaction_ = false;
  }

 private:
  PostgresStore::Pool& pool_;
  std::unique_ptr<PostgresStore::Connection> c_;
  bool in_transaction_ = false;
  bool first_ = true;  // no statement sent yet
};

JobRecord read_job(const Result& r, int row, bool with_scene) {
  JobRecord j;
  j.id = r.text(row, 0);
  j.ord = r.int64(row, 1);
  j.status = parse_job_status(r.text(row, 2)).value_or(JobStatus::failed);
  j.created = r.text(row, 3);
  j.started = r.text(row, 4);
  j.finished = r.text(row, 5);
  j.updated = r.text(row, 6);
  j.message = r.text(row, 7);
  j.steps = static_cast<int>(r.int64(row, 8));
  j.nodes = static_cast<int>(r.int64(row, 9));
  j.idempotency_key = r.optional_text(row, 10);
  j.last_seq = r.int64(row, 11);
  j.attempts = static_cast<int>(r.int64(row, 12));
  j.solve_seconds = r.real(row, 13);
  j.iterations = r.int64(row, 14);
  j.owner = r.text(row, 15);
  j.generation = r.int64(row, 16);
  j.failure_kind = r.text(row, 17);
  j.failure_step = static_cast<int>(r.int64(row, 18));
  j.steps_completed = static_cast<int>(r.int64(row, 19));
  j.stored_bytes = r.int64(row, 20);
  j.request_id = r.text(row, 21);
  if (with_scene) j.scene = r.text(row, 22);
  return j;
}

std::string select_job(bool with_scene, const std::string& where) {
  return std::string("SELECT ") + kJobColumns + (with_scene ? ", scene" : "") + " FROM grip_jobs WHERE " + where;
}

// Bytes as a bytea literal in text form (\x and hex digits): parameters are sent as text.
std::string bytea(const std::string& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out = "\\x";
  out.reserve(2 + 2 * bytes.size());
  for (unsigned char c : bytes) {
    out += digits[c >> 4];
    out += digits[c & 15];
  }
  return out;
}

// The bytes of a bytea value in text form (hex: \x...).
std::string from_bytea(const std::string& text) {
  auto value = [](char c) { return c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10; };
  std::string out;
  if (text.size() < 2 || text[0] != '\\' || text[1] != 'x') throw std::runtime_error("database: bytea not in hex form");
  out.reserve((text.size() - 2) / 2);
  for (size_t i = 2; i + 1 < text.size(); i += 2) out += static_cast<char>(value(text[i]) << 4 | value(text[i + 1]));
  return out;
}

std::string num(std::int64_t v) { return std::to_string(v); }
std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace

bool is_postgresql_url(const std::string& db) {
  return db.rfind("postgresql://", 0) == 0 || db.rfind("postgres://", 0) == 0;
}

std::string redacted_url(const std::string& url) {
  static const std::regex password(R"(^(postgres(?:ql)?://[^:/@]*):[^@]*@)");
  std::string out = std::regex_replace(url, password, "$1:***@");
  static const std::regex query_password(R"(([?&]password=)[^&]*)");
  return std::regex_replace(out, query_password, "$1***");
}

PostgresStore::PostgresStore(const std::string& url, int pool_size) : pool_(std::make_unique<Pool>()) {
  pool_->url = url;
  pool_->size = std::max(2, pool_size);
  {
    Session s(*pool_);
    s.begin();
    s.script(kSchema);
    s.commit();
  }
  listen_thread_ = std::thread([this] { listen_loop(); });
  // Changes made after construction are heard: wait (a little) until LISTEN holds.
  std::unique_lock lock(listener_mutex_);
  listening_cv_.wait_for(lock, std::chrono::seconds(5), [&] { return listening_; });
}

PostgresStore::~PostgresStore() {
  stop_ = true;
  if (listen_thread_.joinable()) listen_thread_.join();
}

void PostgresStore::set_listener(std::function<void(const StoreChange&)> listener) {
  std::lock_guard lock(listener_mutex_);
  listener_ = std::move(listener);
}

std::optional<std::pair<std::int64_t, std::int64_t>> PostgresStore::traffic() const {
  return std::make_pair(pool_->round_trips.load(), pool_->bytes.load());
}

void PostgresStore::listen_loop() {
  auto announce = [this](const StoreChange& c) {
    std::function<void(const StoreChange&)> l;
    {
      std::lock_guard lock(listener_mutex_);
      l = listener_;
    }
    if (l) l(c);
  };
  PGconn* conn = nullptr;
  while (!stop_) {
    if (!conn || PQstatus(conn) != CONNECTION_OK) {
      if (conn) PQfinish(conn);
      conn = nullptr;
      try {
        conn = pool_->connect();
      } catch (const StoreUnavailable&) {
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
        continue;
      }
      PGresult* r = PQexec(conn, "LISTEN grip");
      const bool ok = PQresultStatus(r) == PGRES_COMMAND_OK;
      PQclear(r);
      if (!ok) continue;
      {
        std::lock_guard lock(listener_mutex_);
        listening_ = true;
      }
      listening_cv_.notify_all();
      // Whatever was announced while not listening: everyone looks again.
      announce({StoreChange::job, ""});
    }
    pollfd p{PQsocket(conn), POLLIN, 0};
    if (::poll(&p, 1, 250) < 0) continue;
    if (!PQconsumeInput(conn)) {
      PQfinish(conn);
      conn = nullptr;
      continue;
    }
    while (PGnotify* n = PQnotifies(conn)) {
      const std::string payload = n->extra ? n->extra : "";
      PQfreemem(n);
      if (payload.empty()) continue;
      const StoreChange::Kind kind = payload[0] == 'e'   ? StoreChange::events
                                     : payload[0] == 'd' ? StoreChange::dismissed
                                                         : StoreChange::job;
      announce({kind, payload.substr(1)});
    }
  }
  if (conn) PQfinish(conn);
}

bool PostgresStore::ping() {
  try {
    Session s(*pool_);
    s.query("SELECT 1");
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

void PostgresStore::insert_job(JobRecord& job) {
  Session s(*pool_);
  // One statement: the job, the meshes it uses (their last use), the announcement.
  nlohmann::json meshes = job.meshes;
  const Result r = s.query(
      "WITH ins AS (INSERT INTO grip_jobs (id, status, scene, created, updated, message, steps, "
      "nodes, idempotency_key, request_id) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10) RETURNING ord, id), "
      "uses AS (INSERT INTO grip_job_meshes (job_id, mesh_id) SELECT ins.id, m FROM ins, "
      "jsonb_array_elements_text($11::jsonb) m ON CONFLICT DO NOTHING), "
      "touch AS (UPDATE grip_meshes SET used = $4 WHERE id IN (SELECT jsonb_array_elements_text($11::jsonb))) "
      "SELECT ord, pg_notify('grip', 'j' || id) FROM ins",
      {job.id, std::string(to_string(job.status)), job.scene, job.created, job.updated, job.message,
       num(std::int64_t{job.steps}), num(std::int64_t{job.nodes}), job.idempotency_key, job.request_id, meshes.dump()});
  job.ord = r.int64(0, 0);
}

std::optional<JobRecord> PostgresStore::job(const std::string& id, bool with_scene) {
  Session s(*pool_);
  const Result r = s.query(select_job(with_scene, "id = $1").c_str(), {id});
  if (r.rows() == 0) return std::nullopt;
  return read_job(r, 0, with_scene);
}

std::optional<JobRecord> PostgresStore::job_by_idempotency_key(const std::string& key) {
  Session s(*pool_);
  const Result r = s.query(select_job(true, "idempotency_key = $1").c_str(), {key});
  if (r.rows() == 0) return std::nullopt;
  return read_job(r, 0, true);
}

JobPage PostgresStore::list_jobs(std::optional<JobStatus> status, int limit, std::optional<std::int64_t> before) {
  Session s(*pool_);
  const std::string sql = select_job(false, status ? "ord < $1 AND status = $3" : "ord < $1 AND $3::text IS NULL") +
                          " ORDER BY ord DESC LIMIT $2";
  const Result r = s.query(sql.c_str(), {num(before.value_or(INT64_MAX)), num(std::int64_t{limit + 1}),
                                         status ? Param(std::string(to_string(*status))) : std::nullopt});
  JobPage page;
  for (int i = 0; i < r.rows(); ++i) page.jobs.push_back(read_job(r, i, false));
  if (static_cast<int>(page.jobs.size()) > limit) {
    page.jobs.pop_back();
    page.next_before = page.jobs.back().ord;
  }
  return page;
}

std::map<JobStatus, std::int64_t> PostgresStore::count_by_status() {
  Session s(*pool_);
  const Result r = s.query("SELECT status, count(*) FROM grip_jobs GROUP BY status");
  std::map<JobStatus, std::int64_t> counts;
  for (int i = 0; i < r.rows(); ++i)
    if (auto st = parse_job_status(r.text(i, 0))) counts[*st] = r.int64(i, 1);
  return counts;
}

std::int64_t PostgresStore::count_accepted() {
  Session s(*pool_);
  return s.query("SELECT count(*) FROM grip_jobs WHERE status = 'accepted'").int64(0, 0);
}

std::optional<JobRecord> PostgresStore::claim_job(const std::string& owner, const std::string& now,
                                                  double lease_seconds) {
  Session s(*pool_);
  const std::string sql =
      "WITH next AS (SELECT id FROM grip_jobs WHERE status = 'accepted' ORDER BY ord LIMIT 1 "
      "FOR UPDATE SKIP LOCKED) "
      "UPDATE grip_jobs j SET status = 'running', started = $1, updated = $1, message = 'running', "
      "attempts = attempts + 1, generation = generation + 1, owner = $2, "
      "lease_expires = now() + make_interval(secs => $3) FROM next WHERE j.id = next.id RETURNING " +
      std::regex_replace(std::string(kJobColumns), std::regex(R"((^|, )(\w+))"), "$1j.$2") + ", j.scene";
  const Result r = s.query(sql.c_str(), {now, owner, num(lease_seconds)});
  if (r.rows() == 0) return std::nullopt;
  return read_job(r, 0, true);
}

LeaseRenewal PostgresStore::renew_leases(const std::string& owner, const std::vector<Lease>& leases,
                                         double lease_seconds) {
  if (leases.empty()) return {};
  nlohmann::json list = nlohmann::json::array();
  for (const Lease& l : leases) list.push_back({{"id", l.job_id}, {"g", l.generation}});
  Session s(*pool_);
  const Result r = s.query(
      "UPDATE grip_jobs j SET lease_expires = now() + make_interval(secs => $2) "
      "FROM jsonb_array_elements($3::jsonb) x WHERE j.id = x->>'id' AND j.generation = (x->>'g')::bigint "
      "AND j.owner = $1 AND j.finished IS NULL AND j.status IN ('running', 'dismissed') "
      "RETURNING j.id, j.generation, j.status",
      {owner, num(lease_seconds), list.dump()});
  LeaseRenewal out;
  for (int i = 0; i < r.rows(); ++i) {
    out.held.push_back({r.text(i, 0), r.int64(i, 1)});
    if (r.text(i, 2) == "dismissed") out.dismissed.push_back(r.text(i, 0));
  }
  return out;
}

void PostgresStore::release_leases(const std::string& owner) {
  Session s(*pool_);
  s.query("UPDATE grip_jobs SET lease_expires = '-infinity' WHERE owner = $1 AND finished IS NULL", {owner});
}

int PostgresStore::requeue_expired(const std::string& now) {
  Session s(*pool_);
  const Result a = s.query(
      "WITH expired AS (SELECT id FROM grip_jobs WHERE status = 'running' AND lease_expires < now() "
      "FOR UPDATE SKIP LOCKED), "
      "del AS (DELETE FROM grip_events e USING expired x WHERE e.job_id = x.id), "
      "upd AS (UPDATE grip_jobs j SET status = 'accepted', started = NULL, updated = $1, "
      "message = 'requeued after an interrupted run' FROM expired x WHERE j.id = x.id RETURNING j.id) "
      "SELECT count(*) FROM (SELECT pg_notify('grip', 'j' || id) FROM upd) n",
      {now});
  // Dismissed while running, then its runner went away before finishing it.
  const Result b = s.query(
      "WITH gone AS (SELECT id, last_seq FROM grip_jobs WHERE status = 'dismissed' AND finished IS NULL "
      "AND lease_expires < now() FOR UPDATE SKIP LOCKED), "
      "ev AS (INSERT INTO grip_events (job_id, seq, type, data) SELECT id, last_seq + 1, 'job_failed', $2 FROM gone), "
      "upd AS (UPDATE grip_jobs j SET finished = $1, updated = $1, last_seq = gone.last_seq + 1 FROM gone "
      "WHERE j.id = gone.id RETURNING j.id) "
      "SELECT count(*) FROM (SELECT pg_notify('grip', 'e' || id) FROM upd) n",
      {now, std::string(kDismissedEvent)});
  return static_cast<int>(a.int64(0, 0) + b.int64(0, 0));
}

std::vector<Lease> PostgresStore::append_events(const std::vector<NewEvent>& events) {
  if (events.empty()) return {};
  // One statement per run in the batch: the lease check, last_seq, the events and the
  // announcement together.
  std::map<std::pair<std::string, std::int64_t>, std::pair<std::int64_t, nlohmann::json>> runs;
  for (const NewEvent& e : events) {
    auto& [top, list] = runs[{e.lease.job_id, e.lease.generation}];
    top = std::max(top, e.event.seq);
    list.push_back({{"s", e.event.seq}, {"t", e.event.type}, {"d", e.event.data}});
  }
  std::vector<Lease> refused;
  Session s(*pool_);
  for (const auto& [run, batch] : runs) {
    const Result r = s.query(
        "WITH ok AS (UPDATE grip_jobs SET last_seq = greatest(last_seq, $3) WHERE id = $1 AND "
        "generation = $2 AND finished IS NULL AND status IN ('running', 'dismissed') RETURNING id), "
        "ins AS (INSERT INTO grip_events (job_id, seq, type, data) SELECT ok.id, (e->>'s')::bigint, "
        "e->>'t', e->>'d' FROM ok, jsonb_array_elements($4::jsonb) e ON CONFLICT (job_id, seq) DO NOTHING) "
        "SELECT id, pg_notify('grip', 'e' || id) FROM ok",
        {run.first, num(run.second), num(batch.first), batch.second.dump()});
    if (r.rows() == 0) refused.push_back({run.first, run.second});
  }
  return refused;
}

std::optional<FinishStored> PostgresStore::finish_job(const Lease& lease, const JobOutcome& o) {
  Session s(*pool_);
  // One statement: atomic, and fenced by the generation.
  const Result r = s.query(
      "WITH cur AS (SELECT id, status FROM grip_jobs WHERE id = $1 AND generation = $2 AND "
      "finished IS NULL AND status IN ('running', 'dismissed') FOR UPDATE), "
      "upd AS (UPDATE grip_jobs j SET "
      "status = CASE WHEN cur.status = 'dismissed' OR $3::text = 'dismissed' THEN 'dismissed' ELSE $3::text END, "
      "message = CASE WHEN cur.status = 'dismissed' OR $3::text = 'dismissed' THEN 'dismissed' ELSE $4::text END, "
      "finished = $5::text, updated = $5::text, solve_seconds = $6::float8, iterations = $7::bigint, "
      "last_seq = greatest(j.last_seq, $8::bigint), "
      "failure_kind = CASE WHEN cur.status = 'dismissed' OR $3::text = 'dismissed' THEN 'dismissed' ELSE $13::text "
      "END, "
      "failure_step = CASE WHEN cur.status = 'dismissed' OR $3::text = 'dismissed' THEN 0 ELSE $14::integer END, "
      "steps_completed = $15::integer, stored_bytes = octet_length(j.scene) + "
      "CASE WHEN cur.status = 'dismissed' OR $3::text = 'dismissed' THEN 0 ELSE coalesce(octet_length($9::bytea), 0) "
      "END + "
      "octet_length($11::text) + (SELECT coalesce(sum(octet_length(e.data)), 0) FROM grip_events e WHERE e.job_id = "
      "j.id) "
      "FROM cur WHERE j.id = cur.id RETURNING j.id, j.status, j.stored_bytes), "
      "res AS (INSERT INTO grip_results (job_id, bytes) SELECT id, $9::bytea FROM upd WHERE "
      "upd.status <> 'dismissed' AND $9::bytea IS NOT NULL ON CONFLICT (job_id) DO UPDATE SET bytes = EXCLUDED.bytes, "
      "data = NULL), "
      "ev AS (INSERT INTO grip_events (job_id, seq, type, data) SELECT id, $8::bigint, "
      "CASE WHEN upd.status = 'dismissed' THEN 'job_failed' ELSE $10::text END, "
      "CASE WHEN upd.status = 'dismissed' THEN $12::text ELSE $11::text END FROM upd) "
      "SELECT status, stored_bytes, pg_notify('grip', 'e' || id) FROM upd",
      {lease.job_id, num(lease.generation), std::string(to_string(o.status)), o.message, o.finished,
       num(o.solve_seconds), num(o.iterations), num(o.terminal.seq), o.result ? Param(bytea(*o.result)) : Param(),
       o.terminal.type, o.terminal.data, std::string(kDismissedEvent), o.failure_kind,
       num(std::int64_t{o.failure_step}), num(std::int64_t{o.steps_completed})});
  if (r.rows() == 0) return std::nullopt;
  const auto status = parse_job_status(r.text(0, 0));
  if (!status) return std::nullopt;
  return FinishStored{*status, r.int64(0, 1)};
}

bool PostgresStore::requeue_job(const Lease& lease, const std::string& updated) {
  Session s(*pool_);
  const Result r = s.query(
      "WITH upd AS (UPDATE grip_jobs SET status = 'accepted', started = NULL, updated = $3, "
      "message = 'requeued after an interrupted run' WHERE id = $1 AND generation = $2 AND "
      "status = 'running' RETURNING id), "
      "del AS (DELETE FROM grip_events WHERE job_id IN (SELECT id FROM upd)) "
      "SELECT pg_notify('grip', 'j' || id) FROM upd",
      {lease.job_id, num(lease.generation), updated});
  return r.rows() == 1;
}

std::pair<DismissOutcome, std::optional<JobRecord>> PostgresStore::dismiss_job(const std::string& id,
                                                                               const std::string& now) {
  Session s(*pool_);
  s.begin();
  const std::string select = select_job(false, "id = $1");
  const Result cur = s.query((select + " FOR UPDATE").c_str(), {id});
  if (cur.rows() == 0) return {DismissOutcome::not_found, std::nullopt};
  const JobRecord rec = read_job(cur, 0, false);
  DismissOutcome outcome = DismissOutcome::dismissed;
  if (rec.status == JobStatus::accepted) {
    const std::string seq = num(rec.last_seq + 1);
    s.query(
        "UPDATE grip_jobs SET status = 'dismissed', message = 'dismissed before it started', "
        "finished = $2, updated = $2, last_seq = $3 WHERE id = $1",
        {id, now, seq});
    s.query("INSERT INTO grip_events (job_id, seq, type, data) VALUES ($1, $2, 'job_failed', $3)",
            {id, seq, std::string(kDismissedEvent)});
    s.query("SELECT pg_notify('grip', 'e' || $1::text)", {id});
  } else if (!is_finished(rec.status) || rec.finished.empty()) {
    s.query("UPDATE grip_jobs SET status = 'dismissed', message = 'dismissed', updated = $2 WHERE id = $1", {id, now});
    s.query("SELECT pg_notify('grip', 'd' || $1::text)", {id});
  } else {
    s.query("DELETE FROM grip_events WHERE job_id = $1", {id});
    s.query("DELETE FROM grip_results WHERE job_id = $1", {id});
    s.query("DELETE FROM grip_job_meshes WHERE job_id = $1", {id});
    s.query("DELETE FROM grip_jobs WHERE id = $1", {id});
    s.query("SELECT pg_notify('grip', 'j' || $1::text)", {id});
    outcome = DismissOutcome::removed;
  }
  std::optional<JobRecord> after = rec;
  if (outcome == DismissOutcome::dismissed) {
    const Result r = s.query(select.c_str(), {id});
    after = read_job(r, 0, false);
  }
  s.commit();
  return {outcome, after};
}

std::vector<StoredEvent> PostgresStore::events_after(const std::string& id, std::int64_t after, int limit,
                                                     std::string_view type) {
  Session s(*pool_);
  const Result r = s.query(
      "SELECT seq, type, data FROM grip_events WHERE job_id = $1 AND seq > $2 AND "
      "($4::text IS NULL OR type = $4) ORDER BY seq LIMIT $3",
      {id, num(after), num(std::int64_t{limit}), type.empty() ? Param() : Param(std::string(type))});
  std::vector<StoredEvent> out;
  for (int i = 0; i < r.rows(); ++i) out.push_back({r.int64(i, 0), r.text(i, 1), r.text(i, 2)});
  return out;
}

std::optional<std::string> PostgresStore::result(const std::string& id) {
  Session s(*pool_);
  const Result r = s.query("SELECT data, bytes FROM grip_results WHERE job_id = $1", {id});
  if (r.rows() == 0) return std::nullopt;
  return r.null(0, 1) ? r.text(0, 0) : from_bytea(r.text(0, 1));
}

std::int64_t PostgresStore::prune(const Retention& retention, const std::string& now) {
  if (!retention.any()) return 0;
  Session s(*pool_);
  const Result r = s.query(
      "SELECT id, status, finished, stored_bytes FROM grip_jobs WHERE finished IS NOT NULL AND "
      "status IN ('successful', 'failed', 'dismissed') ORDER BY status = 'dismissed', ord DESC");
  std::vector<FinishedJob> finished;
  for (int i = 0; i < r.rows(); ++i)
    finished.push_back({r.text(i, 0), r.text(i, 1) == "dismissed", r.text(i, 2), r.int64(i, 3)});
  const std::string cutoff = retention_cutoff(retention, now);
  const std::vector<std::string> gone = beyond_retention(finished, retention, cutoff);
  // In batches, each one transaction; ids are UUIDs (no quoting needed in the array literal).
  for (size_t from = 0; from < gone.size(); from += 500) {
    std::string ids = "{";
    for (size_t i = from; i < std::min(gone.size(), from + 500); ++i) ids += (i > from ? "," : "") + gone[i];
    ids += "}";
    s.begin();
    s.query("DELETE FROM grip_events WHERE job_id = ANY($1::text[])", {ids});
    s.query("DELETE FROM grip_results WHERE job_id = ANY($1::text[])", {ids});
    s.query("DELETE FROM grip_job_meshes WHERE job_id = ANY($1::text[])", {ids});
    s.query("DELETE FROM grip_jobs WHERE id = ANY($1::text[]) AND finished IS NOT NULL", {ids});
    s.query("SELECT pg_notify('grip', 'j')");
    s.commit();
  }
  // Meshes no stored job uses, named by no job since the cutoff.
  if (!cutoff.empty())
    s.query(
        "DELETE FROM grip_meshes m WHERE used < $1 AND NOT EXISTS (SELECT 1 FROM grip_job_meshes u WHERE u.mesh_id = "
        "m.id)",
        {cutoff});
  return static_cast<std::int64_t>(gone.size());
}

bool PostgresStore::put_mesh(const MeshRecord& mesh, const std::string& data) {
  Session s(*pool_);
  const Result r = s.query(
      "INSERT INTO grip_meshes (id, bytes, data, summary, created, used) VALUES ($1, $2, $3::bytea, $4, $5, $5) "
      "ON CONFLICT (id) DO NOTHING RETURNING id",
      {mesh.id, num(mesh.bytes), bytea(data), mesh.summary, mesh.created});
  return r.rows() == 1;
}

void PostgresStore::insert_study(const StudyRecord& study) {
  Session s(*pool_);
  s.query("INSERT INTO grip_studies (id, created, document) VALUES ($1, $2, $3)",
          {study.id, study.created, study.document});
}

std::optional<StudyRecord> PostgresStore::study(const std::string& id) {
  Session s(*pool_);
  const Result r = s.query("SELECT id, created, document FROM grip_studies WHERE id = $1", {id});
  if (r.rows() == 0) return std::nullopt;
  return StudyRecord{r.text(0, 0), r.text(0, 1), r.text(0, 2)};
}

bool PostgresStore::remove_study(const std::string& id) {
  Session s(*pool_);
  return s.query("DELETE FROM grip_studies WHERE id = $1 RETURNING id", {id}).rows() == 1;
}

std::optional<MeshRecord> PostgresStore::mesh(const std::string& id) {
  Session s(*pool_);
  const Result r =
      s.query("SELECT id, bytes, octet_length(data), summary, created FROM grip_meshes WHERE id = $1", {id});
  if (r.rows() == 0) return std::nullopt;
  return MeshRecord{r.text(0, 0), r.int64(0, 1), r.int64(0, 2), r.text(0, 3), r.text(0, 4)};
}

std::optional<std::string> PostgresStore::mesh_data(const std::string& id) {
  Session s(*pool_);
  const Result r = s.query("SELECT data FROM grip_meshes WHERE id = $1", {id});
  if (r.rows() == 0) return std::nullopt;
  return from_bytea(r.text(0, 0));
}

MeshRemoval PostgresStore::remove_mesh(const std::string& id) {
  Session s(*pool_);
  // One statement: a job inserted meanwhile either sees the mesh gone (its submission was
  // checked before) or keeps it.
  const Result r = s.query(
      "WITH found AS (SELECT id FROM grip_meshes WHERE id = $1 FOR UPDATE), "
      "used AS (SELECT count(*) AS n FROM grip_job_meshes WHERE mesh_id = $1), "
      "del AS (DELETE FROM grip_meshes m USING found, used WHERE m.id = found.id AND used.n = 0 RETURNING m.id) "
      "SELECT (SELECT count(*) FROM found), (SELECT n FROM used), (SELECT count(*) FROM del)",
      {id});
  if (r.int64(0, 0) == 0) return MeshRemoval::not_found;
  return r.int64(0, 2) == 1 ? MeshRemoval::removed : MeshRemoval::in_use;
}

std::pair<std::int64_t, std::int64_t> PostgresStore::mesh_totals() {
  Session s(*pool_);
  const Result r = s.query("SELECT count(*), coalesce(sum(octet_length(data)), 0) FROM grip_meshes");
  return {r.int64(0, 0), r.int64(0, 1)};
}

std::int64_t PostgresStore::disk_bytes() {
  Session s(*pool_);
  const Result r = s.query(
      "SELECT coalesce(pg_total_relation_size('grip_jobs'), 0) + coalesce(pg_total_relation_size('grip_events'), 0) + "
      "coalesce(pg_total_relation_size('grip_results'), 0) + coalesce(pg_total_relation_size('grip_meshes'), 0)");
  return r.int64(0, 0);
}

}  // namespace grip::server
