#pragma once
// The Slurm backend: jobs run as tasks of Slurm job arrays on a cluster instead of as processes of
// the server's machine. The server stays the one front end and the job store its memory; Slurm only
// runs the workers. The state directory lies on a filesystem the compute nodes share.
//
// A task is the same `runout worker` as a local job: its WorkerTask in a file, its events appended to
// a file per Slurm attempt (`<k>.events.<restart count>`), its log appended to the job's log. Tasks
// submitted close together (an ensemble's members, claimed by the scheduler at once) go into one job
// array (`sbatch --array`); the scheduler follows each task with `scontrol show job -o A_k` (Slurm's
// accounting database is not needed) and reads its events as they come.
//
// What Slurm says, mapped onto a worker's end:
//   COMPLETED                   -> exited with its exit code
//   FAILED (ExitCode a:b)       -> exited a, or ended by signal b
//   CANCELLED by us             -> the signal we sent (a stop or a cancel of the job)
//   CANCELLED by someone else   -> SIGTERM from outside (the job is queued again)
//   NODE_FAIL, BOOT_FAIL, OUT_OF_MEMORY, TIMEOUT, DEADLINE -> killed (a crash: run again, counted)
// Tasks are submitted with --requeue: Slurm itself runs again a task whose node failed, and the
// scheduler goes on following it (the next attempt's events file).
//
// A task over several MPI ranks (WorkerTask.ranks, a scenario's `ranks`) is an array of its own
// (with the tasks of the same ranks) of --ntasks=RANKS: its batch step execs `srun --input=0`, which
// starts the ranks on the job's nodes; rank 0 reads the task file and writes the events. A stop is
// SIGTERM to the job's steps (the ranks), not to the batch step.
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "jobs/system/execution.hpp"

namespace runout::jobs {

struct SlurmConfig {
  std::string partition;                 ///< sbatch --partition; empty: the cluster's default
  std::vector<std::string> sbatch_args;  ///< further sbatch options (e.g. "--mem=4G", "--time=02:00:00")
  std::string worker_exe;                ///< the runout program as the compute nodes see it
  std::string job_name;                  ///< every array's name (one per state directory: "runout-<hash>")
  double batch_window_s = 0.3;           ///< tasks submitted within this much of each other share an array
  std::string commands_dir;              ///< where sbatch, scontrol and scancel are; empty: PATH
  /// A task over several MPI ranks: srun --mpi= this ("pmix": Debian's Open MPI through Slurm's
  /// PMIx plugin); "cluster": the cluster's own MpiDefault.
  std::string mpi = "pmix";
};

/// Batches tasks into job arrays and submits them (one per state directory).
class SlurmSubmitter {
 public:
  /// `dir`: the state directory's slurm/ folder (on the shared filesystem).
  SlurmSubmitter(std::string dir, SlurmConfig cfg);
  /// Submit a task (its log appended to `log_path`): waits for the batch window, then submits the
  /// array holding it. Returns the task's Slurm id "A_k" and its folder and index. Throws
  /// std::runtime_error with sbatch's message when Slurm refuses.
  struct Submitted {
    std::string id;  ///< "A_k"
    std::string dir;
    int index = 0;
  };
  Submitted submit(const v1::WorkerTask& task, const std::string& log_path);
  /// Cancel every task of this state directory still known to Slurm (a server killed outright left
  /// them running; their jobs are queued again in the store).
  void cancel_all();
  const SlurmConfig& config() const { return cfg_; }
  /// Run a Slurm command (sbatch, scontrol, scancel) with arguments; its standard output, and its
  /// exit status in `rc`.
  std::string command(const std::string& name, const std::vector<std::string>& args, int& rc, std::string* err = nullptr) const;
  /// A task of the array in `dir` will not be followed any more; the folder goes with the last.
  void release(const std::string& dir);

 private:
  struct Pending {
    v1::WorkerTask task;
    std::string log_path;
    Submitted out;
    std::string error;
    bool done = false;
  };
  void submit_batch(std::vector<std::shared_ptr<Pending>> batch);
  std::string dir_;
  SlurmConfig cfg_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<std::shared_ptr<Pending>> pending_;
  bool leader_ = false;
  long arrays_ = 0;
  std::map<std::string, int> open_;  // array folder -> its tasks still followed
};

/// One task of a Slurm job array as the scheduler follows it.
class SlurmStep : public Execution {
 public:
  SlurmStep(SlurmSubmitter& s, const v1::WorkerTask& task, const std::string& log_path);
  ~SlurmStep() override;
  bool started() const override { return state_ != "PENDING" && state_ != "CONFIGURING"; }
  std::string where() const override { return "Slurm job " + sub_.id; }
  std::optional<v1::WorkerEvent> next_event(std::chrono::milliseconds timeout) override;
  bool output_closed() const override { return closed_; }
  void signal(int sig) override;
  std::optional<WorkerExit> wait(std::chrono::milliseconds timeout) override;
  std::int64_t resident_bytes() const override { return 0; }

 private:
  void poll_state();  ///< scontrol: state, exit code, restarts
  bool read_more();   ///< new bytes of the events file
  SlurmSubmitter& s_;
  SlurmSubmitter::Submitted sub_;
  std::string state_ = "PENDING", exit_code_ = "0:0";
  int restarts_ = 0, reading_ = 0;
  std::size_t offset_ = 0;
  std::string buf_;
  bool final_ = false, closed_ = false, gone_ = false;
  int sent_ = 0;  ///< the last signal we sent
  int ranks_ = 1;  ///< the task's MPI ranks (an srun step of this many tasks when > 1)
  std::chrono::steady_clock::time_point last_poll_{};
};

}  // namespace runout::jobs
