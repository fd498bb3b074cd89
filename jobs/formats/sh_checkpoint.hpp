#pragma once
// Checkpoints of depth-averaged runs (HDF5): the 2D solver's complete state between two steps
// (engine::Sh2dCheckpoint), the number of time-series frames written before it, and the hash of
// the scenario it belongs to, so that a run continues exactly where it stopped and a checkpoint
// cannot be applied to another scenario. The frames themselves lie beside it in
// CHECKPOINT.timeseries.h5 (see TimeSeriesWriter::save_copy).
#include <string>

#include "engine/sh2d.hpp"

namespace runout::jobs {

struct ShCheckpoint {
  std::string scenario_hash;   ///< jobs::scenario_hash of the run's scenario
  int timeseries_frames = 0;   ///< frames of timeseries.h5 written before the checkpoint
  engine::Sh2dCheckpoint state;
};

/// The checkpoint's format; a file of another format (another build, a VOF checkpoint) is refused.
inline constexpr const char* kShCheckpointFormat = "runout depth-averaged checkpoint 5";

/// Write atomically (a temporary file renamed over `path`). Throws std::runtime_error.
void write_sh_checkpoint(const std::string& path, const std::string& scenario_hash, int timeseries_frames,
                         const engine::Sh2dCheckpoint& state);
/// Read; throws ScenarioError naming the file and what is wrong with it.
ShCheckpoint read_sh_checkpoint(const std::string& path);

}  // namespace runout::jobs
