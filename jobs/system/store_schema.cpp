// The job store's file: opening it (WAL, synced commits, foreign keys), its tables, and the
// migrations of stores written by earlier versions.
#include <sqlite3.h>

#include "jobs/system/store.hpp"

namespace runout::jobs {

JobStore::JobStore(const std::string& path) {
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, nullptr) !=
      SQLITE_OK) {
    const std::string m = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw StoreError("job store '" + path + "': " + m);
  }
  sqlite3_busy_timeout(db_, 10000);
  exec("PRAGMA journal_mode=WAL");
  // Every committed state change survives a power loss: the WAL is synced at each commit.
  exec("PRAGMA synchronous=FULL");
  exec("PRAGMA foreign_keys=ON");
  exec(R"(CREATE TABLE IF NOT EXISTS jobs(
           seq INTEGER PRIMARY KEY AUTOINCREMENT,
           id TEXT UNIQUE NOT NULL,
           owner TEXT NOT NULL,
           name TEXT NOT NULL,
           hash TEXT NOT NULL,
           request_id TEXT,
           state INTEGER NOT NULL,
           created TEXT NOT NULL,
           updated TEXT NOT NULL,
           error TEXT NOT NULL DEFAULT '',
           attempts INTEGER NOT NULL DEFAULT 0,
           scenario BLOB NOT NULL,
           progress BLOB,
           result_bytes INTEGER NOT NULL DEFAULT 0,
           results_removed INTEGER NOT NULL DEFAULT 0,
           cancel_requested INTEGER NOT NULL DEFAULT 0,
           interrupted INTEGER NOT NULL DEFAULT 0);
         CREATE UNIQUE INDEX IF NOT EXISTS jobs_request ON jobs(owner, request_id) WHERE request_id IS NOT NULL;
         CREATE INDEX IF NOT EXISTS jobs_owner_hash ON jobs(owner, hash);
         CREATE INDEX IF NOT EXISTS jobs_state ON jobs(state, seq);
         CREATE TABLE IF NOT EXISTS transitions(
           job TEXT NOT NULL REFERENCES jobs(id),
           time TEXT NOT NULL,
           state INTEGER NOT NULL,
           reason TEXT NOT NULL);
         CREATE INDEX IF NOT EXISTS transitions_job ON transitions(job);
         CREATE TABLE IF NOT EXISTS requests(
           owner TEXT NOT NULL,
           request_id TEXT NOT NULL,
           job TEXT NOT NULL REFERENCES jobs(id),
           request_hash TEXT NOT NULL DEFAULT '',
           PRIMARY KEY(owner, request_id));)");
  // Stores written before the cancel flag existed get the column.
  sqlite3_stmt* probe = nullptr;
  if (sqlite3_prepare_v2(db_, "SELECT cancel_requested FROM jobs LIMIT 0", -1, &probe, nullptr) != SQLITE_OK)
    exec("ALTER TABLE jobs ADD COLUMN cancel_requested INTEGER NOT NULL DEFAULT 0");
  sqlite3_finalize(probe);
  // ... and the count of attempts the server ended cleanly (interrupted by a stop, queued again).
  probe = nullptr;
  if (sqlite3_prepare_v2(db_, "SELECT interrupted FROM jobs LIMIT 0", -1, &probe, nullptr) != SQLITE_OK) {
    // The clean interruptions so far, from the transitions they left.
    exec("ALTER TABLE jobs ADD COLUMN interrupted INTEGER NOT NULL DEFAULT 0;"
         "UPDATE jobs SET interrupted = (SELECT COUNT(*) FROM transitions t WHERE t.job = jobs.id AND t.state = 1 "
         "AND t.reason LIKE 'interrupted by the server stopping%')");
  }
  sqlite3_finalize(probe);
  // ... and the count of the job's worker processes that crashed (died of a signal nobody sent).
  probe = nullptr;
  if (sqlite3_prepare_v2(db_, "SELECT crashes FROM jobs LIMIT 0", -1, &probe, nullptr) != SQLITE_OK)
    exec("ALTER TABLE jobs ADD COLUMN crashes INTEGER NOT NULL DEFAULT 0");
  sqlite3_finalize(probe);
  // ... and the digest of the request that created a job (a retry must send the same).
  probe = nullptr;
  if (sqlite3_prepare_v2(db_, "SELECT request_hash FROM jobs LIMIT 0", -1, &probe, nullptr) != SQLITE_OK)
    exec("ALTER TABLE jobs ADD COLUMN request_hash TEXT");
  sqlite3_finalize(probe);
  // ... and an ensemble's members: their ensemble's job and their place in it.
  probe = nullptr;
  if (sqlite3_prepare_v2(db_, "SELECT parent FROM jobs LIMIT 0", -1, &probe, nullptr) != SQLITE_OK)
    exec("ALTER TABLE jobs ADD COLUMN parent TEXT NOT NULL DEFAULT '';"
         "ALTER TABLE jobs ADD COLUMN member INTEGER NOT NULL DEFAULT -1");
  sqlite3_finalize(probe);
  exec("CREATE INDEX IF NOT EXISTS jobs_parent ON jobs(parent, member)");
  exec(R"(CREATE TABLE IF NOT EXISTS uploads(
           id TEXT NOT NULL,
           owner TEXT NOT NULL,
           bytes INTEGER NOT NULL,
           time REAL NOT NULL,
           PRIMARY KEY(id, owner));)");
}

JobStore::~JobStore() { sqlite3_close(db_); }

void JobStore::exec(const char* sql) const {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    std::string m = err ? err : "?";
    sqlite3_free(err);
    throw StoreError("job store: " + m);
  }
}

}  // namespace runout::jobs
