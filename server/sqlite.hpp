#pragma once
// A small RAII wrapper over SQLite's C API: a connection, prepared statements with bound
// parameters, and a transaction guard. Every failure throws SqliteError with SQLite's message.
#include <sqlite3.h>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>

namespace grip::server {

class SqliteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Statement;

class Database {
 public:
  // Opens (creating) the file; sets WAL mode, the busy timeout and `synchronous` (FULL or
  // NORMAL: the setting that a Transaction of the other kind switches away from and back).
  Database(const std::string& path, int busy_timeout_ms, const char* synchronous = "FULL");
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  void exec(const std::string& sql);
  // A statement of `sql`, prepared once per text and kept (reset when each use ends): parsing
  // the same few texts again for every job took a seventh of the server's time in a load run.
  // A text in use already (two statements of it alive at once) gets one of its own.
  Statement prepare(std::string_view sql);
  std::int64_t changes() const;
  sqlite3* handle() const { return db_; }
  bool synchronous_full() const { return full_; }

 private:
  struct Kept {
    sqlite3_stmt* stmt = nullptr;
    bool in_use = false;
  };
  sqlite3* db_ = nullptr;
  bool full_ = true;
  std::unordered_map<std::string, Kept> kept_;  // node-based: a Kept stays where it is
};

class Statement {
 public:
  Statement(sqlite3* db, std::string_view sql);
  // A kept statement of the Database: reset and unbound when this ends, not finalized.
  Statement(sqlite3* db, sqlite3_stmt* kept, bool* in_use);
  ~Statement();
  Statement(Statement&& other) noexcept;
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  Statement& operator=(Statement&&) = delete;

  // Parameters are 1-based, as in SQLite.
  Statement& bind(int index, std::int64_t value);
  Statement& bind(int index, int value) { return bind(index, static_cast<std::int64_t>(value)); }
  Statement& bind(int index, double value);
  Statement& bind(int index, std::string_view value);
  Statement& bind(int index, const char* value) { return bind(index, std::string_view(value)); }
  Statement& bind(int index, const std::string& value) { return bind(index, std::string_view(value)); }
  Statement& bind(int index, const std::optional<std::string>& value);
  Statement& bind_null(int index);
  // Bytes as a BLOB (a TEXT binding would claim they are UTF-8).
  Statement& bind_blob(int index, std::string_view bytes);

  // Steps once: true while a row is available, false when done.
  bool step();
  // Runs to completion (for statements without rows).
  void run();
  void reset();

  std::int64_t int64(int column) const;
  double real(int column) const;
  std::string text(int column) const;
  std::string blob(int column) const;  // a BLOB's bytes (a TEXT value's too)
  std::optional<std::string> optional_text(int column) const;
  bool is_null(int column) const;

 private:
  sqlite3* db_ = nullptr;
  sqlite3_stmt* stmt_ = nullptr;
  bool* in_use_ = nullptr;  // a kept statement's flag
};

// BEGIN IMMEDIATE on construction; ROLLBACK on destruction unless commit() was called.
// A full transaction commits with synchronous=FULL (fsynced before commit() returns); a relaxed
// one with NORMAL (no fsync: the WAL reaches the disk at the connection's next FULL commit or
// checkpoint), for writes that a crash may lose because recovery redoes them anyway
// (docs/running.md#the-service). A transaction whose kind is not the connection's setting
// switches it for its commit and back after: each switch is a PRAGMA that SQLite parses again
// every time it runs, so a connection is opened with the setting of its most frequent writes.
class Transaction {
 public:
  enum class Sync { full, relaxed };
  explicit Transaction(Database& db, Sync sync = Sync::full);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  void end(const char* sql);
  Database& db_;
  Sync sync_;
  bool switched_;  // the connection's setting is the other one
  bool done_ = false;
};

}  // namespace grip::server
