#pragma once
// The run driver of the 3D engine on the DEM (scenario engine "vof" without `lab`): the set-up
// (setup.hpp: grid, release, terrain-following mesh), the run with progress, checkpoints,
// cancellation and the depth-averaged engine's stop rule, the hazard maps integrated through the
// depth after every step (hazard.hpp), and the outputs: the depth-averaged engine's rasters,
// outline and map (jobs/drivers/hazard_outputs.hpp), max_surface_speed.tif, max_ground_stress.tif,
// the 3D frames (fields.h5 + fields.xmf, in the grid's CRS with z up) and run.json (record.hpp).
#include <string>

#include "jobs/drivers/run.hpp"

namespace runout::jobs {

/// Called by run_scenario for a resolved scenario with `terrain`.
RunSummary run_terrain_vof(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt);

}  // namespace runout::jobs
