#pragma once
// run.json of a 3D run on the DEM: the depth-averaged engine's DEM, grid, release and results
// sections, the terrain mesh and its quality, the mass balance (outflow through the sides counted),
// the solver's figures (alpha bounds, active cells), the profiles at the named points and timings.
#include <string>
#include <vector>

#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/run.hpp"
#include "jobs/drivers/vof_lab/monitors.hpp"
#include "jobs/drivers/vof_terrain/hazard.hpp"
#include "engine/vof/backend.hpp"
#include "jobs/drivers/vof_terrain/setup.hpp"

namespace runout::jobs::vof_terrain {

struct TerrainRunFacts {
  const TerrainSetup& su;
  const ColumnHazard& hazard;
  const RunningFigures& fig;
  const RunSummary& sum;
  double continued_from = 0;  ///< NaN: not continued
  const HazardOutputs& outputs;
  int frames = 0;
  double corridor_outflow = 0;     ///< [m3] through the corridor's edge
  double domain_edge_outflow = 0;  ///< [m3] through the domain's edge
  std::vector<std::string> notes;  ///< run.json's notes
  const engine::vof::VofBackend* backend = nullptr;  ///< the engine (a run split over MPI ranks records its split)
};

void write_terrain_record(const std::string& path, const ResolvedScenario& r, const TerrainRunFacts& f);

}  // namespace runout::jobs::vof_terrain
