#include "server/sqlite.hpp"

namespace grip::server {
namespace {

[[noreturn]] void fail(sqlite3* db, const std::string& what) {
  throw SqliteError(what + ": " + (db ? sqlite3_errmsg(db) : "out of memory"));
}

}  // namespace

Database::Database(const std::string& path, int busy_timeout_ms, const char* synchronous) {
  const int flags = SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX;
  if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
    const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw SqliteError("cannot open " + path + ": " + msg);
  }
  sqlite3_busy_timeout(db_, busy_timeout_ms);
  exec("PRAGMA journal_mode=WAL");
  exec(std::string("PRAGMA synchronous=") + synchronous);
  full_ = std::string_view(synchronous) == "FULL";
  exec("PRAGMA foreign_keys=ON");
}

Database::~Database() {
  for (auto& [sql, kept] : kept_) sqlite3_finalize(kept.stmt);
  sqlite3_close_v2(db_);
}

void Database::exec(const std::string& sql) {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string msg = err ? err : sqlite3_errmsg(db_);
    sqlite3_free(err);
    throw SqliteError(sql.substr(0, 60) + ": " + msg);
  }
}

Statement Database::prepare(std::string_view sql) {
  auto [it, added] = kept_.try_emplace(std::string(sql));
  Kept& kept = it->second;
  if (added) {
    if (sqlite3_prepare_v3(db_, sql.data(), static_cast<int>(sql.size()), SQLITE_PREPARE_PERSISTENT, &kept.stmt,
                           nullptr) != SQLITE_OK) {
      kept_.erase(it);
      fail(db_, "prepare " + std::string(sql.substr(0, 60)));
    }
  }
  if (kept.in_use) return Statement(db_, sql);
  kept.in_use = true;
  return Statement(db_, kept.stmt, &kept.in_use);
}

std::int64_t Database::changes() const { return sqlite3_changes64(db_); }

Statement::Statement(sqlite3* db, std::string_view sql) : db_(db) {
  if (sqlite3_prepare_v2(db, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr) != SQLITE_OK)
    fail(db, "prepare " + std::string(sql.substr(0, 60)));
}

Statement::Statement(sqlite3* db, sqlite3_stmt* kept, bool* in_use) : db_(db), stmt_(kept), in_use_(in_use) {}

Statement::~Statement() {
  if (!in_use_) {
    sqlite3_finalize(stmt_);
    return;
  }
  sqlite3_reset(stmt_);  // ends its read of the database (a kept open read would hold back checkpoints)
  sqlite3_clear_bindings(stmt_);
  *in_use_ = false;
}

Statement::Statement(Statement&& other) noexcept : db_(other.db_), stmt_(other.stmt_), in_use_(other.in_use_) {
  other.stmt_ = nullptr;
  other.in_use_ = nullptr;
}

Statement& Statement::bind(int index, std::int64_t value) {
  if (sqlite3_bind_int64(stmt_, index, value) != SQLITE_OK) fail(db_, "bind");
  return *this;
}

Statement& Statement::bind(int index, double value) {
  if (sqlite3_bind_double(stmt_, index, value) != SQLITE_OK) fail(db_, "bind");
  return *this;
}

Statement& Statement::bind(int index, std::string_view value) {
  if (sqlite3_bind_text64(stmt_, index, value.data(), value.size(), SQLITE_TRANSIENT, SQLITE_UTF8) != SQLITE_OK)
    fail(db_, "bind");
  return *this;
}

Statement& Statement::bind(int index, const std::optional<std::string>& value) {
  return value ? bind(index, std::string_view(*value)) : bind_null(index);
}

Statement& Statement::bind_blob(int index, std::string_view bytes) {
  if (sqlite3_bind_blob64(stmt_, index, bytes.data(), bytes.size(), SQLITE_TRANSIENT) != SQLITE_OK) fail(db_, "bind");
  return *this;
}

Statement& Statement::bind_null(int index) {
  if (sqlite3_bind_null(stmt_, index) != SQLITE_OK) fail(db_, "bind");
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  fail(db_, "step");
}

void Statement::run() {
  while (step()) {
  }
}

void Statement::reset() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}

std::int64_t Statement::int64(int column) const { return sqlite3_column_int64(stmt_, column); }

double Statement::real(int column) const { return sqlite3_column_double(stmt_, column); }

std::string Statement::text(int column) const {
  const auto* p = sqlite3_column_text(stmt_, column);
  return p ? std::string(reinterpret_cast<const char*>(p), static_cast<size_t>(sqlite3_column_bytes(stmt_, column)))
           : std::string();
}

std::string Statement::blob(int column) const {
  const auto* p = sqlite3_column_blob(stmt_, column);
  return p ? std::string(static_cast<const char*>(p), static_cast<size_t>(sqlite3_column_bytes(stmt_, column)))
           : std::string();
}

std::optional<std::string> Statement::optional_text(int column) const {
  if (is_null(column)) return std::nullopt;
  return text(column);
}

bool Statement::is_null(int column) const { return sqlite3_column_type(stmt_, column) == SQLITE_NULL; }

// The few fixed texts run as kept statements: sqlite3_exec parsed them again at every use.
namespace {

const char* setting(Transaction::Sync sync) {
  return sync == Transaction::Sync::full ? "PRAGMA synchronous=FULL" : "PRAGMA synchronous=NORMAL";
}

}  // namespace

Transaction::Transaction(Database& db, Sync sync)
    : db_(db), sync_(sync), switched_(db.synchronous_full() != (sync == Sync::full)) {
  if (switched_) db_.prepare(setting(sync_)).run();
  try {
    db_.prepare("BEGIN IMMEDIATE").run();
  } catch (...) {
    if (switched_) db_.prepare(setting(sync_ == Sync::full ? Sync::relaxed : Sync::full)).run();
    throw;
  }
}

Transaction::~Transaction() {
  if (done_) return;
  try {
    end("ROLLBACK");
  } catch (...) {
    // Nothing more to do: SQLite rolls back on its own when a statement failed hard.
  }
}

void Transaction::commit() {
  end("COMMIT");
  done_ = true;
}

void Transaction::end(const char* sql) {
  struct Restore {
    Database& db;
    const char* back;  // the connection's own setting, if switched
    ~Restore() {
      if (!back) return;
      try {
        db.prepare(back).run();
      } catch (...) {
      }
    }
  } restore{db_, switched_ ? setting(sync_ == Sync::full ? Sync::relaxed : Sync::full) : nullptr};
  db_.prepare(sql).run();
}

}  // namespace grip::server
