#pragma once
// The report-ready maps of a run on the DEM (both engines alike): one per hazard quantity and one of
// the pressure zones, PNG and PDF, with the release, the outline, the points of interest and the
// run's parameters; and the points of interest's figures for run.json.
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "jobs/drivers/run.hpp"
#include "jobs/products/scores.hpp"
#include "jobs/products/zones.hpp"
#include "runout/v1/run_record.pb.h"
#include "terrain/terrain.hpp"

namespace runout::jobs {

/// A point of interest (outputs.points_of_interest) placed on the grid; throws a TerrainError naming
/// the field when it lies outside the domain.
struct PlacedPoint {
  std::string name;
  double x = 0, y = 0;
  std::size_t cell = 0;
};
std::vector<PlacedPoint> place_points_of_interest(const ResolvedScenario& s, const terrain::Grid& grid);

/// The cells inside the observed outline (observations.outline_path); empty without one.
std::vector<std::uint8_t> observed_cells(const ResolvedScenario& s, const terrain::Grid& grid);

/// What the outputs read besides the run (points of interest, the observed outline), checked before
/// the run so that a bad one is refused at once. Throws TerrainError naming the field.
void check_output_inputs(const ResolvedScenario& s, const terrain::Grid& grid);

/// The lines of the maps' parameter block: engine, friction, release, grid, software.
std::vector<std::string> map_parameters(const ResolvedScenario& s, const terrain::Grid& grid, double release_volume_m3);

/// map_<quantity>.png and .pdf for max_depth, max_speed, max_pressure (with the zones' boundaries),
/// deposit and arrival_time, and map_pressure_zones; their names go to sum.files.
void write_hazard_maps(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                       const products::ZoneMap& zones, const std::vector<PlacedPoint>& points, const std::string& out_dir,
                       RunSummary& sum);

/// map_observation.png and .pdf: hits, false alarms and misses against the observed outline, the
/// scores in the parameter block.
void write_score_map(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                     const products::OutlineScores& scores, const std::vector<PlacedPoint>& points, const std::string& out_dir,
                     RunSummary& sum);

/// Each point's figures: the cell's maxima, zone and arrival time.
std::vector<v1::PointReport> point_reports(const std::vector<PlacedPoint>& points, const engine::HazardMaps& hz, const products::ZoneMap& zones,
                                           double outline_threshold);

}  // namespace runout::jobs
