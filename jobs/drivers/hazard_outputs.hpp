#pragma once
// What both engines' runs on a DEM write alike: the engine's local grid, the figures of the hazard
// map (maximum depth, affected area, runout), the hazard rasters, the outline and the map.
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "engine/sh2d.hpp"
#include "jobs/drivers/run.hpp"
#include "runout/v1/run_record.pb.h"
#include "terrain/terrain.hpp"

namespace runout::jobs {

/// The engine's grid: the prepared grid with its local origin at the grid's centre.
engine::Terrain2D engine_terrain(const terrain::Grid& grid);

/// The maximum depth, the affected area (max_depth above the outline threshold) and the runout from
/// the centroid of the release h0 into `sum`.
void hazard_figures(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                    RunSummary& sum);

/// Throws std::runtime_error when one of the named figures is not finite: the flow state became NaN
/// or infinite, and nothing is written.
void require_finite_figures(std::initializer_list<std::pair<const char*, double>> figures);

/// The hazard rasters the scenario asks for (hazard_rasters()), the outline and the map; their names
/// go to sum.files.
terrain::OutlineReport write_hazard_outputs(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0,
                                            const engine::HazardMaps& hz, const std::string& out_dir, RunSummary& sum);

/// The record's dem, grid (without its local origin, which each engine sets) and release sections.
void record_inputs(v1::RunRecord& rec, const terrain::DemReport& dem, const terrain::Grid& grid, const terrain::ReleaseReport& release);

}  // namespace runout::jobs
