#pragma once
// Checkpoints of VOF runs (HDF5): the solver's state (engine::vof::VofState), the run's step count
// and running figures, and the hash of the scenario it belongs to, so that a run continues exactly
// where it stopped and a checkpoint cannot be applied to another scenario.
#include <map>
#include <string>
#include <vector>

#include "engine/vof/backend.hpp"

namespace runout::jobs {

struct VofCheckpoint {
  std::string scenario_hash;
  long steps = 0;
  std::map<std::string, double> figures;  ///< the run's running figures by name (peak speed, ...)
  std::map<std::string, std::vector<double>> series;  ///< the run's monitor series so far, by name
  engine::vof::VofState state;
};

/// Write atomically (a temporary file renamed over `path`). Throws std::runtime_error.
void write_checkpoint(const std::string& path, const VofCheckpoint& cp);
/// Read; throws ScenarioError naming the file and what is wrong with it.
VofCheckpoint read_checkpoint(const std::string& path);

}  // namespace runout::jobs
