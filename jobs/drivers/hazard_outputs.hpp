#pragma once
// What both engines' runs on a DEM write alike: the engine's local grid, the figures of the hazard
// map (maximum depth, affected area, runout), the hazard rasters, the outline and the map.
#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/sh2d.hpp"
#include "jobs/drivers/hazard_maps.hpp"
#include "jobs/drivers/run.hpp"
#include "jobs/products/path.hpp"
#include "jobs/products/scores.hpp"
#include "runout/v1/run_record.pb.h"
#include "terrain/terrain.hpp"

namespace runout::jobs {

/// The engine's grid: the prepared grid with its local origin at the grid's centre.
engine::Terrain2D engine_terrain(const terrain::Grid& grid);

/// The thickness-weighted centroid of the release h0 (NaN without one).
std::pair<double, double> release_centroid(const terrain::Grid& grid, const std::vector<double>& h0);

/// The maximum depth, the affected area (max_depth above the outline threshold) and the runout from
/// the centroid of the release h0 into `sum`, and for the depth-averaged engine the note on
/// near-vertical terrain (steep_terrain_note).
void hazard_figures(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                    RunSummary& sum);

/// Throws std::runtime_error when one of the named figures is not finite: the flow state became NaN
/// or infinite, and nothing is written.
/// Slopes steeper than this [deg] are outside what the depth-averaged model describes (its
/// thickness normal to the ground holds h / cos(slope) of a vertical column).
inline constexpr double kSteepSlopeDeg = 60;
/// A note (empty when none) naming the cells steeper than kSteepSlopeDeg under the release or the
/// flow (max depth above the outline threshold): depth and speed there are not physical.
std::string steep_terrain_note(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz);

/// Per structure (scenario structures[], `cells` from read_output_inputs): its cells, its height and
/// the flow in the cells next to it (4-neighbours not on it): the deepest flow and the largest
/// pressure of the maps `hz` (density rho [kg/m3] times the squared speed, in kPa).
std::vector<StructureSummary> structure_summaries(const ResolvedScenario& s, const terrain::Grid& grid,
                                                  const std::vector<terrain::DamCells>& cells, const engine::HazardMaps& hz);
/// One structure into a run.json StructureResult (the load figures only where it has loads).
void record_structure(const StructureSummary& q, v1::StructureResult* r);
/// The structures of `sum` into run.json's structures[].
void record_structures(const RunSummary& sum, v1::RunRecord& rec);

void require_finite_figures(std::initializer_list<std::pair<const char*, double>> figures);

/// What write_hazard_outputs wrote that the run record reports.
struct HazardOutputs {
  terrain::OutlineReport outline;
  double max_pressure_kpa = 0;
  std::vector<terrain::ClassArea> zone_areas;  ///< per zone of the scenario's pressure_zones
  std::vector<v1::PointReport> points;         ///< outputs.points_of_interest
  std::optional<products::OutlineScores> scores;  ///< against observations.outline_path
  std::optional<products::PathProfile> path;      ///< the path analysis (none: no line on the grid)
  std::string path_source;
  std::vector<std::string> parameters;  ///< the parameters in words (map_parameters), for run.json
};

/// The hazard rasters the scenario asks for (hazard_rasters(), each with its QGIS style), the
/// pressure zones (raster, polygons, style), the outline and the maps (hazard_maps.hpp); their names
/// go to sum.files.
/// `in`: what read_output_inputs read before the run.
HazardOutputs write_hazard_outputs(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0,
                                   const engine::HazardMaps& hz, const OutputInputs& in, const std::string& out_dir, RunSummary& sum);

/// The record's results that both engines on the DEM report alike: affected area and its criterion,
/// outline, runout, maximum depth and pressure, the pressure zones.
void record_hazard_results(const ResolvedScenario& s, const RunSummary& sum, const HazardOutputs& out, v1::ResultsReport& re);

/// The record's dem, grid (without its local origin, which each engine sets) and release sections.
void record_inputs(v1::RunRecord& rec, const terrain::DemReport& dem, const terrain::Grid& grid, const terrain::ReleaseReport& release);

/// The record's grid: CRS, size, cell size and corner.
v1::GridReport grid_report(const terrain::Grid& g);

}  // namespace runout::jobs
