#pragma once
// Worker slots that take queued jobs from the store and run each in a worker process of its own
// (jobs/worker.hpp: the same run driver as `runout run`). Results are written to
// results/<hash>.tmp-<job> and renamed to results/<hash> only when complete, so a folder under
// results/ without ".tmp-" is always a whole result. Each job has a log (logs/<job>.log) that keeps
// its progress and, when it fails, the error, and a record (logs/<job>.record.pb) from which
// `runout serve --recover` rebuilds a lost store.
//
// Stopping: stop() sends SIGTERM to every worker (it writes a checkpoint at the end of its step and
// ends; after the grace time it is killed and continues from its last periodic checkpoint) and
// records the jobs as queued again; a server killed outright takes its workers with it
// (PR_SET_PDEATHSIG), leaves the jobs "running" in the store, and start() queues them again without
// counting it against them. A job whose own worker dies of a signal the server did not send crashed:
// it runs again, and fails after max_crashes such attempts. Continuation from a checkpoint is exact,
// so a job run again gives the result an uninterrupted run gives.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "jobs/system/slurm.hpp"
#include "jobs/system/store.hpp"
#include "runout/v1/worker.pb.h"

namespace runout::jobs {

struct SchedulerConfig {
  std::string state_dir;            ///< holds results/ and logs/
  int workers = 1;                  ///< concurrent runs
  int threads_per_run = 0;          ///< OpenMP threads of each run; 0: cores / workers (at least 1)
  double retention_days = 0;        ///< finished results older than this are deleted; 0: kept
  std::int64_t retention_max_bytes = 0;  ///< oldest results deleted beyond this total; 0: no limit
  std::function<void(const std::string&)> log;  ///< server log lines (optional)
  std::string worker_exe;           ///< the program run as `EXE worker`; default: this program
  double max_job_wall_s = 86400;    ///< wall time of one attempt (a scenario's limits may lower it)
  std::int64_t max_job_memory_bytes = 0;  ///< resident memory of a worker; 0: no limit
  double stop_grace_s = 1;          ///< a stopped or cancelled worker is killed after this long
  /// A local worker whose process has not ended this long after SIGKILL (stuck in uninterruptible
  /// I/O: a hung network filesystem, a failing disk) is left behind: its job ends and its slot is
  /// free. (A Slurm step ends by the cluster's own kill timeout.)
  double stuck_after_kill_s = 10;
  int max_crashes = 3;              ///< a job whose worker crashed this often fails
  std::vector<std::string> data_roots;  ///< the server's data roots (left out of messages to clients)
  bool terrain_cache = true;        ///< depth-averaged runs share prepared grids (STATE/cache/terrain)
  /// The local launcher of a job over several MPI ranks (a scenario's `ranks`): its command and
  /// options, before "-n RANKS EXE worker" (jobs/system/worker.hpp). Empty: such jobs run on one process.
  std::vector<std::string> mpi_launcher = {"mpirun", "--oversubscribe", "--bind-to", "none"};
  /// Run the jobs as tasks of Slurm job arrays (jobs/system/slurm.hpp) instead of local worker
  /// processes; `workers` is then how many tasks may be on the cluster at once.
  std::optional<SlurmConfig> slurm;
};

/// A message for a client: the server's upload folders and data roots left out of the paths in it,
/// so that a file is named as the client named it.
std::string client_message(std::string msg, const std::string& state_dir, const std::vector<std::string>& data_roots);

class Scheduler {
 public:
  Scheduler(JobStore& store, SchedulerConfig cfg);
  ~Scheduler();
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;

  /// Queue again what a dead server left running, apply the retention policy, start the workers.
  void start();
  /// Interrupt running jobs (they are queued again) and join the workers.
  void stop();
  /// A job was queued.
  void notify();
  /// Write the job's record (logs/<job>.record.pb) for `runout serve --recover`.
  void write_record(const StoredJob& job) const;
  std::string record_path(const std::string& id) const;
  /// Ask a running job to stop; it ends as cancelled. false when it is not running here.
  bool cancel_running(const std::string& id);

  /// Live progress of a running job (newer than the store's copy) and a change counter.
  struct Live {
    v1::Progress progress;
    std::uint64_t version = 0;
    bool running = false;
  };
  Live live(const std::string& id) const;
  /// Wait until the job's state or progress changes after `version`, or the timeout passes.
  void wait_change(const std::string& id, std::uint64_t version, std::chrono::milliseconds timeout) const;
  /// Bumped on every state change of any job (watchers re-read the store).
  void touch(const std::string& id);

  std::string results_dir(const std::string& hash) const;
  std::string log_path(const std::string& id) const;
  /// Append "TIME line" to a job's log (its history, which `runout serve --recover` reads); false
  /// when it could not be written.
  bool append_job_log(const std::string& id, const std::string& line) const;
  /// A VOF job's checkpoint while it runs (its frames so far beside it, ID.h5.fields.h5).
  std::string checkpoint_path(const std::string& id) const;
  void remove_checkpoint(const std::string& id) const;
  void remove_orphan_checkpoints();
  /// Delete results per the retention policy now.
  void apply_retention();

 private:
  void worker_loop(int index);
  struct JobContext;  // one job's run: its log, paths, limits and how it is recorded
  struct Attempt;     // what one worker process of a job did
  void run_job(StoredJob job);
  /// An ensemble's job: its members' results into the task (true), or the job ended because a member
  /// failed, was cancelled or lost its results (false). A job of its own: true, nothing added.
  bool ensemble_task(JobContext& jc, v1::WorkerTask& task);
  /// Run the task in a worker process and follow it to its end (progress, cancel, stop, limits).
  Attempt supervise(JobContext& jc, const v1::WorkerTask& task);
  /// Record what an ended attempt means for the job; true: run it again at once.
  bool conclude(JobContext& jc, v1::WorkerTask& task, const Attempt& a, int round);
  void leave_behind(JobContext& jc, std::unique_ptr<Execution> run, Attempt& a);
  /// Publish progress; false when the job should stop (cancel or server stop).
  bool on_progress(const std::string& id, const v1::Progress& p);
  void log(const std::string& line) const;

  JobStore& store_;
  SchedulerConfig cfg_;
  std::vector<std::thread> threads_;
  std::atomic<bool> stopping_{false};
  mutable std::mutex mu_;
  mutable std::condition_variable work_cv_;     // workers wait for jobs
  mutable std::condition_variable change_cv_;   // watchers wait for changes
  std::map<std::string, Live> live_;
  std::map<std::string, std::uint64_t> versions_;
  std::set<std::string> cancel_;
  std::uint64_t counter_ = 0;
  std::uint64_t work_seq_ = 0;  // bumped by notify(): work may be waiting
  std::chrono::steady_clock::time_point last_retention_{};  // guarded by mu_
  std::mutex retention_mu_;
  std::mutex results_mu_;  // results/<hash> folders: moved in, answered from, removed
  std::unique_ptr<SlurmSubmitter> slurm_;  // the Slurm backend; null: local worker processes
};

}  // namespace runout::jobs
