#pragma once
// The job store: every job, its state, its transitions (time and reason) and its last progress, in a
// SQLite file (WAL mode, synchronous=FULL: a committed change survives a power loss) in the server's
// state directory. One connection, serialised by a mutex; every state change is one transaction, so
// a process killed at any point leaves a consistent store. Uploads are recorded per client (quota,
// garbage collection).
// States: queued -> running -> succeeded | failed | cancelled; running -> queued when the server stops
// or restarts during a run.
#include <cstdint>
#include <mutex>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "runout/v1/scenario.pb.h"
#include "runout/v1/service.pb.h"

struct sqlite3;

namespace runout::jobs {

struct StoreError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// The client already has as many queued and running jobs as the server allows.
struct QueueFull : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// A request id the client used before for another scenario.
struct RequestIdConflict : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct StoredJob {
  v1::Job job;            ///< id, state, name, hash, times, error, progress, transitions, attempts
  std::string owner;      ///< the client (token) that submitted it
  v1::Scenario scenario;  ///< as resolved on the server (absolute input paths)
  bool results_removed = false;  ///< results deleted by the retention policy
  int crashes = 0;               ///< attempts whose worker process died of a signal nobody sent
  /// Further request ids that name this job (owner's request id, digest of that request): a request
  /// answered with this earlier identical job. Filled by recovery (from the job's log) only.
  std::vector<std::pair<std::string, std::string>> more_requests = {};
};

struct SubmitOutcome {
  StoredJob job;
  bool created = false;  ///< false: an existing job answered (same request id or identical scenario)
};

class JobStore {
 public:
  /// Opens (creating when needed) the store at `path`.
  explicit JobStore(const std::string& path);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  /// Queue a job, or return the existing one: the same owner's job with this request id, else the
  /// same owner's newest job with this scenario hash that did not fail or get cancelled. Throws
  /// RequestIdConflict when the request id names a job of another scenario, QueueFull when the
  /// owner already has `max_queued` queued or running jobs.
  SubmitOutcome submit(const std::string& owner, const std::string& hash, const std::string& request_id,
                       const v1::Scenario& scenario, int max_queued, const std::string& request_hash = "");
  /// An ensemble's member: its place, scenario hash and scenario.
  struct NewMember {
    int index = 0;
    std::string hash;
    v1::Scenario scenario;
  };
  /// An ensemble: its job (hash: the ensemble's, jobs/ensemble) and its members' jobs, queued in one
  /// transaction (no member is lost, none is left without its ensemble). An existing ensemble job
  /// answers as submit() says; the ensemble counts as one job against `max_queued`. The ensemble's
  /// job is claimed only once none of its members is queued or running (it then aggregates).
  /// `record_request` (when given) is called, before the commit, when the request id is recorded for
  /// an earlier identical job that answers (created false): it writes that job's log line, and
  /// an exception from it leaves nothing recorded.
  SubmitOutcome submit_ensemble(const std::string& owner, const std::string& hash, const std::string& request_id,
                                const v1::Scenario& scenario, const std::vector<NewMember>& members, int max_queued,
                                const std::string& request_hash = "",
                                const std::function<void(const StoredJob&)>& record_request = {});
  /// An ensemble's members, in order.
  std::vector<StoredJob> members(const std::string& parent) const;
  /// The owner's job with this request id, and the digest of the request that created it ("" for
  /// jobs stored before it was kept).
  std::optional<std::pair<StoredJob, std::string>> find_request(const std::string& owner, const std::string& request_id) const;
  /// The job with this id; with a non-empty owner only if it is that owner's.
  std::optional<StoredJob> get(const std::string& id, const std::string& owner = "") const;
  /// The owner's jobs, newest first, filtered by state (empty: all); `page_token` from the previous page.
  /// Ensembles' members are not listed (members() lists them).
  std::vector<StoredJob> list(const std::string& owner, const std::vector<v1::JobState>& states, int page_size,
                              const std::string& page_token, std::string* next_page_token) const;
  /// The oldest queued job, now running (attempts + 1); nothing when the queue is empty.
  std::optional<StoredJob> claim_next();
  /// Record a state change with its reason (and the error for failures); `crashed`: the attempt
  /// ended because its worker process crashed (counted in StoredJob::crashes).
  void transition(const std::string& id, v1::JobState state, const std::string& reason, const std::string& error = "",
                  std::int64_t result_bytes = -1, bool crashed = false);
  /// A job's change of state, for its log.
  struct Change {
    std::string id;
    v1::JobState state;
    std::string reason;
  };
  /// Queued jobs become cancelled here; running ones are left for the worker (returns their state).
  /// An ensemble's queued members are cancelled with it and its running ones asked to stop.
  /// `ended` (when given) receives each job this call moved to CANCELLED: the job itself when it
  /// was queued, and an ensemble's queued members (their logs want the line).
  std::optional<StoredJob> cancel(const std::string& id, const std::string& owner, std::vector<Change>* ended = nullptr,
                                  const std::function<void(const std::vector<Change>&)>& before_commit = {});
  /// Jobs left running by a server that went down: queued again (cancelled when the client had
  /// asked). The server's death does not count against a job. Returns how many were queued again;
  /// `changed` (optional) receives each job's id, new state and reason.
  int requeue_running(const std::string& reason, std::vector<Change>* changed = nullptr);
  /// Whether the client asked to cancel this (running) job.
  bool cancel_requested(const std::string& id) const;
  void save_progress(const std::string& id, const v1::Progress& p);
  /// Disk used by the owner's results (each result folder counted once).
  std::int64_t result_bytes_total(const std::string& owner) const;
  /// Succeeded jobs whose results still exist, oldest first: (hash, updated time, bytes); results an
  /// ensemble still waiting for its aggregate needs are left out (retention must not take them).
  struct Finished {
    std::string hash, updated;
    std::int64_t bytes = 0;
  };
  std::vector<Finished> finished_results() const;
  /// The results of this scenario hash were deleted (retention): every job with it says so.
  void mark_results_removed(const std::string& hash, const std::string& reason);

  /// Whether any job of this scenario hash was accepted before (its inputs passed the checks).
  bool has_hash(const std::string& hash) const;
  /// Queued and running jobs (their scenarios name the uploads still in use).
  std::vector<StoredJob> active_jobs() const;
  /// How many jobs the store holds.
  std::int64_t job_count() const;
  /// A job rebuilt by `runout serve --recover` (with its transitions), as it was.
  void insert_recovered(const StoredJob& j);

  /// An upload of `bytes` by this client (again: its time is renewed).
  void record_upload(const std::string& owner, const std::string& id, std::int64_t bytes);
  /// Bytes of the uploads this client holds.
  std::int64_t upload_bytes(const std::string& owner) const;
  /// Uploads whose newest record is older than `cutoff_epoch_s`.
  std::vector<std::string> uploads_older_than(double cutoff_epoch_s) const;
  /// Every record of an upload (it was removed).
  void forget_upload(const std::string& id);
  /// This client's record of an upload; returns whether any client still holds one.
  bool forget_upload(const std::string& id, const std::string& owner);

 private:
  StoredJob read_row(void* stmt) const;
  void fill_counts(StoredJob& j) const;  ///< an ensemble's members by state (job.members)
  void load_transitions(StoredJob& j) const;
  void exec(const char* sql) const;
  sqlite3* db_ = nullptr;
  mutable std::mutex mu_;
};

/// "2026-11-23T06:30:04.123Z"
std::string utc_now();
/// A new random job id ("j" + 16 hex digits).
std::string new_job_id();
/// "queued", "running", ...
std::string state_name(v1::JobState s);
bool is_final(v1::JobState s);

}  // namespace runout::jobs
