#pragma once
// The inside of a `runout worker` process (the protocol and the outside are in
// jobs/system/worker.hpp): read one WorkerTask, resolve its scenario, run it through the engine's
// run driver and report progress and exactly one outcome as length-prefixed WorkerEvents.

namespace runout::jobs {

/// A run that fails with less than this free on the disk of its results failed for the full disk,
/// and its error says so [bytes].
inline constexpr double kFullDiskBytes = 4 << 20;

/// Reads one WorkerTask from `in_fd` (to its end), runs it and writes events to `out_fd`. Returns
/// the process's exit status (0 when an outcome was written).
int worker_main(int in_fd, int out_fd);

}  // namespace runout::jobs
