#pragma once
// The server's state directory (jobs.db, results/, logs/, uploads/, checkpoints/): one writer at a
// time, a store that never silently forgets, and the rebuilding of a lost store.
#include <cstdint>
#include <stdexcept>
#include <optional>
#include <string>

#include "runout/v1/service.pb.h"

namespace runout::jobs {

struct StateError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Bytes of the regular files below a folder (0 when it cannot be read).
std::int64_t folder_bytes(const std::string& path);

/// The exclusive lock of a state directory (an flock on STATE/server.lock), held for the life of
/// this object; the operating system releases it when the process dies, however it dies. The lock
/// file names the holder (pid, and its listen address once set), so that a second server can say
/// who holds it.
class StateLock {
 public:
  /// Throws StateError naming the holder when another process holds the lock.
  explicit StateLock(const std::string& state_dir);
  ~StateLock();
  StateLock(const StateLock&) = delete;
  StateLock& operator=(const StateLock&) = delete;
  /// Record the address the holder listens on.
  void set_listen(const std::string& address);

 private:
  int fd_ = -1;
  std::string path_;
};

/// Check the job store before a server opens it. Throws StateError, saying what was found and how
/// to recover, when STATE/jobs.db is missing or empty while results/ or logs/ hold earlier jobs,
/// or when it is damaged (SQLite's quick_check fails or it is not a database).
void check_store(const std::string& state_dir);

struct RecoveryReport {
  int records = 0;               ///< job records found (logs/JOB.record.pb)
  int rebuilt = 0;               ///< jobs written to the new store
  int succeeded = 0, failed = 0, cancelled = 0, queued = 0;
  int results_missing = 0;       ///< succeeded jobs whose results are gone (marked removed)
  int logs_without_record = 0;   ///< job logs with no record: not rebuilt
  std::string moved_aside;       ///< where the damaged store was moved ("" when none was there)
  bool healthy = false;          ///< the store was usable: nothing was done
  std::string text() const;      ///< a summary for the operator
};

/// `runout serve --recover`: move a missing, empty or damaged store aside and rebuild one from the
/// job records, their logs and the results (built beside it and moved into place when complete, so
/// an interrupted recovery leaves no half store). A healthy store is left as it is (healthy = true).
/// The caller holds the state directory's lock (`held`), so no server starts meanwhile.
RecoveryReport recover_store(const std::string& state_dir, const StateLock& held);

/// The job-log line (after its time stamp) that records a request id answered with this earlier
/// identical job, so that recovery gives the id back to the same job.
std::string request_log_line(const std::string& request_id, const std::string& request_digest);

/// STATE/server.json, written by a server once it listens (atomically: a temporary file renamed).
void write_server_info(const std::string& state_dir, const v1::ServerInfo& info);
/// STATE/server.json of a running server; nothing when there is none or it cannot be read.
std::optional<v1::ServerInfo> read_server_info(const std::string& state_dir);

}  // namespace runout::jobs
