#pragma once
// The ISeeSnow benchmark export of a depth-averaged run (validation.md A8): peak flow thickness and
// velocity as ESRI ASCII grids on the input DEM's grid (<release>_<id>_null_runout_pft.asc, _pfv.asc),
// the benchmark's result-table row (iseesnow_<id>.csv) and the model configuration file (.txt).
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "jobs/scenario/scenario.hpp"
#include "terrain/terrain.hpp"

namespace runout::jobs {

/// Writes the export into `out_dir` for the simulation id `simulation_id` (its leading digits are
/// the result table's row index, the rest the test case); returns the names of the files written.
std::vector<std::string> write_iseesnow(const ResolvedScenario& s, const std::string& simulation_id, const std::string& out_dir,
                                        const terrain::Grid& grid, const engine::Sh2dResult& res, double cpu_seconds);

}  // namespace runout::jobs
