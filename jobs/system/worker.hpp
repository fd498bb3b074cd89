#pragma once
// Jobs in their own processes. A job runs in a `runout worker` process (the runout program run
// again), as a batch system runs a job step: a job that crashes, hangs, blocks in I/O or runs out
// of memory takes only itself down, and stopping it is a signal to that process.
//
// The protocol (runout/v1/worker.proto): the task on the worker's standard input, length-prefixed
// WorkerEvent messages on its standard output (progress, then exactly one outcome), anything else
// it prints on standard error (the job's log). SIGTERM asks it to end at the end of its current
// step (with a checkpoint when the task names one); what a worker does not end within the grace
// time is killed. This boundary is the one a multi-machine backend uses: the task and the events
// are all that crosses it. The inside of a worker is jobs/drivers/worker_task.hpp.
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "jobs/system/execution.hpp"
#include "runout/v1/worker.pb.h"

namespace runout::jobs {

/// The running program ("/proc/self/exe"), the default worker executable: exec of the link starts
/// this very program even after an upgrade replaced its file.
std::string self_executable();

/// One worker process as seen from the server.
class WorkerProcess : public Execution {
 public:
  /// Starts `exe worker` with the task on its standard input and its standard error appended to
  /// `log_path`. The process dies with the thread that started it (PR_SET_PDEATHSIG), so a killed
  /// server leaves no worker behind. A task over several MPI ranks (task.ranks() > 1) with a
  /// `launcher` ("mpirun", its options) starts `launcher... -n RANKS exe worker` instead: the
  /// launcher passes the task to rank 0 and rank 0's events back, and takes its ranks with it when
  /// it is killed; a stop reaches the ranks as SIGUSR1. Throws std::runtime_error when it cannot start.
  WorkerProcess(const std::string& exe, const v1::WorkerTask& task, const std::string& log_path,
                const std::vector<std::string>& launcher = {});
  /// Kills a worker that is still running and reaps it.
  ~WorkerProcess() override;
  WorkerProcess(const WorkerProcess&) = delete;
  WorkerProcess& operator=(const WorkerProcess&) = delete;

  pid_t pid() const { return pid_; }
  std::string where() const override { return "worker process " + std::to_string(pid_); }
  /// The next event, waiting at most `timeout`; nothing on timeout or once the output is closed.
  std::optional<v1::WorkerEvent> next_event(std::chrono::milliseconds timeout) override;
  /// The worker closed its output (it ended, or is ending).
  bool output_closed() const override { return closed_; }
  /// Send a signal (recorded: a death by it, or by SIGKILL after it, is ours).
  void signal(int sig) override;
  /// SIGTERM now, SIGKILL when it has not ended after `grace`.
  void stop(std::chrono::milliseconds grace);
  /// Wait for the process to end (at most `timeout`; nothing when it has not).
  std::optional<WorkerExit> wait(std::chrono::milliseconds timeout) override;
  /// Resident memory of the process [bytes] (0 when it cannot be read); under a launcher, of the
  /// launcher and its ranks together.
  std::int64_t resident_bytes() const override;

 private:
  bool fill(std::chrono::milliseconds timeout);
  void feed();  ///< write what it can of the task to the worker's standard input
  pid_t pid_ = -1;
  int out_fd_ = -1;
  int in_fd_ = -1;
  std::string pending_in_;
  bool closed_ = false;
  bool reaped_ = false;
  bool sent_ = false;
  bool launched_ = false;  ///< started by an MPI launcher (several ranks)
  WorkerExit exit_;
  std::string buf_;
};

}  // namespace runout::jobs
