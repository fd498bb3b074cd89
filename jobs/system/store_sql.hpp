#pragma once
// The job store's SQLite helpers (internal to jobs/store*.cpp): a prepared statement that finalises
// itself, and a transaction rolled back when an exception leaves its scope.
#include <sqlite3.h>

#include <cstdint>
#include <string>

#include "jobs/system/store.hpp"

namespace runout::jobs::sql {

// A prepared statement that finalises itself.
class Stmt {
 public:
  Stmt(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &s_, nullptr) != SQLITE_OK)
      throw StoreError(std::string("job store: ") + sqlite3_errmsg(db) + " in: " + sql);
  }
  ~Stmt() { sqlite3_finalize(s_); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
  Stmt& bind(int k, const std::string& v) {
    sqlite3_bind_text(s_, k, v.data(), int(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Stmt& blob(int k, const std::string& v) {
    sqlite3_bind_blob(s_, k, v.data(), int(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Stmt& bind(int k, std::int64_t v) {
    sqlite3_bind_int64(s_, k, v);
    return *this;
  }
  Stmt& null(int k) {
    sqlite3_bind_null(s_, k);
    return *this;
  }
  /// true while rows come.
  bool step() {
    const int rc = sqlite3_step(s_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw StoreError(std::string("job store: ") + sqlite3_errmsg(db_));
  }
  std::string text(int c) const {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_blob(s_, c));
    return p ? std::string(p, std::size_t(sqlite3_column_bytes(s_, c))) : std::string();
  }
  std::int64_t i64(int c) const { return sqlite3_column_int64(s_, c); }
  sqlite3_stmt* get() const { return s_; }

 private:
  sqlite3* db_;
  sqlite3_stmt* s_ = nullptr;
};

// BEGIN IMMEDIATE ... COMMIT, rolled back when an exception leaves the scope.
class Transaction {
 public:
  explicit Transaction(sqlite3* db) : db_(db) { run("BEGIN IMMEDIATE"); }
  ~Transaction() {
    if (!done_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  void commit() {
    run("COMMIT");
    done_ = true;
  }

 private:
  void run(const char* sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
      std::string m = err ? err : "?";
      sqlite3_free(err);
      throw StoreError("job store: " + m);
    }
  }
  sqlite3* db_;
  bool done_ = false;
};

}  // namespace runout::jobs::sql
