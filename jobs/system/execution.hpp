#pragma once
// Where a job's worker runs, as the scheduler sees it: a process of its own on this machine
// (worker.hpp, WorkerProcess) or a task of a Slurm job array on a cluster (slurm.hpp, SlurmStep).
// Both speak the same protocol (runout/v1/worker.proto): the task in, length-prefixed events out,
// SIGTERM asks the worker to end at the end of its step with a checkpoint.
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "runout/v1/worker.pb.h"

namespace runout::jobs {

/// How a worker ended.
struct WorkerExit {
  bool exited = false;  ///< by exit(); else by a signal
  int code = 0;         ///< exit status when exited
  int signal = 0;       ///< the signal that ended it
  bool signal_ours = false;  ///< that signal (or the SIGTERM before it) came from us
  std::string describe() const;  ///< "exit status 3", "SIGSEGV", ...
};

/// Take the first whole length-prefixed event (4 bytes of length, little endian, then the message)
/// off `buf`; nothing while it is incomplete. A damaged message is skipped (the outcome decides); a
/// length beyond any event means the stream is not our protocol: `closed` becomes true, nothing more
/// can be read from it.
std::optional<v1::WorkerEvent> take_event(std::string& buf, bool& closed);

class Execution {
 public:
  virtual ~Execution() = default;
  /// For the job's log: "worker process 1234", "Slurm job 55_3".
  virtual std::string where() const = 0;
  /// The next event, waiting at most `timeout`; nothing on timeout or once the output is closed.
  virtual std::optional<v1::WorkerEvent> next_event(std::chrono::milliseconds timeout) = 0;
  /// The worker closed its output (it ended, or is ending).
  virtual bool output_closed() const = 0;
  /// SIGTERM: end at the end of the step; SIGKILL: end now. Recorded: an end by it is ours.
  virtual void signal(int sig) = 0;
  /// Wait for the worker to end (at most `timeout`; nothing when it has not).
  virtual std::optional<WorkerExit> wait(std::chrono::milliseconds timeout) = 0;
  /// The worker runs (a cluster's task has left its queue): its wall time counts from here.
  virtual bool started() const { return true; }
  /// Resident memory of the worker [bytes]; 0 when it cannot be read (a cluster enforces its own).
  virtual std::int64_t resident_bytes() const = 0;
};

}  // namespace runout::jobs
