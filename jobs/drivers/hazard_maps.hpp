#pragma once
// The report-ready maps of a run on the DEM (both engines alike): one per hazard quantity and one of
// the pressure zones, PNG and PDF, with the release, the outline, the points of interest and the
// run's parameters; and the points of interest's figures for run.json.
#include <array>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "jobs/drivers/run.hpp"
#include "jobs/figures/hazard_map.hpp"
#include "jobs/products/path.hpp"
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

/// What the outputs read besides the run, read once before the run (so that a bad one is refused at
/// once) and handed to write_hazard_outputs: the points of interest, the path line (the scenario's
/// path.line_path, or the steepest descent from the release's centroid) and the cells inside the
/// observed outline (empty without observations.outline_path).
struct OutputInputs {
  std::vector<PlacedPoint> points;
  products::Line path;
  std::string path_source;  ///< what the path is (run.json's path.source)
  std::vector<std::uint8_t> observed;
  /// Per resistance area (scenario `resistance.areas[]`), its cells (empty: no areas).
  std::vector<std::vector<std::uint8_t>> resistance_areas;
  /// Per area of erodible cover (scenario `entrainment.areas[]`), its normal thickness per cell.
  std::vector<std::vector<double>> cover_areas;
  /// Per dam (scenario `dams[]`), its cells, height and crest.
  std::vector<terrain::DamCells> dams;
  /// The cells of a 3D nest (scenario `nest`), outlined on the maps; empty: none.
  std::vector<std::uint8_t> nest;
  /// Per structure (scenario `structures[]`), the cells its footprints touch and its height there.
  std::vector<terrain::DamCells> structures;
};
/// Throws TerrainError naming the field (a point outside the domain, a line or outline that cannot be
/// read, an outline that covers no cell of the domain).
OutputInputs read_output_inputs(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0);

/// Without a path line in the scenario: the path becomes the one the flow took instead of the
/// steepest descent, when the flow moved: products::flow_path of the frames' mass centres (`centres`
/// as TimeSeriesWriter::mass_centres gives them) while they stay inside the outline, else (a flow
/// that split) products::longest_flow_line. A scenario's own line is kept.
void use_flow_path(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const std::vector<double>& max_depth,
                   const std::vector<std::array<double, 3>>& centres, OutputInputs& in);

/// The label of a structure with 3D loads on a map: its name and highest pressure to three
/// significant digits, and ", not resolved" where the loads are no design values
/// ("farmhouse: 15 kPa, not resolved"). The run's maps and the report's use it.
std::string structure_load_label(const std::string& name, double max_pressure_kpa, bool resolved);

/// The lines of the maps' parameter block: engine, friction, release, grid, software.
std::vector<std::string> map_parameters(const ResolvedScenario& s, const terrain::Grid& grid, double release_volume_m3);
/// The last lines of every map's parameter block: the grid ("grid: 10 m, 200 × 150 cells, EPSG:32632")
/// and the software with its commit.
std::vector<std::string> map_footer(const terrain::Grid& grid);

/// What every map of a run draws besides its quantity.
struct MapOverlay {
  std::vector<PlacedPoint> points;
  std::vector<std::uint8_t> resistance;  ///< cells of resistance areas, outlined
  std::vector<std::uint8_t> cover;       ///< cells of erodible cover, outlined
  std::vector<std::uint8_t> dams;        ///< cells of dams, outlined
  std::vector<std::uint8_t> structures;  ///< cells of structures, outlined
  std::vector<std::uint8_t> nest;        ///< cells of a 3D nest, outlined
  products::Line path;
  std::vector<figures::MapPoint> path_marks;
};

/// map_<quantity>.png and .pdf for max_depth, max_speed, max_pressure (with the zones' boundaries),
/// deposit and arrival_time, and map_pressure_zones; their names go to sum.files. `values[q]` is
/// hazard raster q (hazard_rasters()) in its raster's unit.
void write_hazard_maps(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                       const std::vector<std::vector<double>>& values, const products::ZoneMap& zones, const MapOverlay& overlay,
                       const std::string& out_dir, RunSummary& sum);

/// path_profile.csv and map_path_profile.png and .pdf; their names go to sum.files.
void write_path_outputs(const ResolvedScenario& s, const products::PathProfile& p, const std::string& out_dir, RunSummary& sum);

/// map_observation.png and .pdf: hits, false alarms and misses against the observed outline, the
/// scores in the parameter block.
void write_score_map(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                     const products::OutlineScores& scores, const MapOverlay& overlay, const std::string& out_dir, RunSummary& sum);

/// Each point's figures: the cell's maxima (pressure_kpa: the max_pressure raster's values), zone and
/// arrival time.
std::vector<v1::PointReport> point_reports(const std::vector<PlacedPoint>& points, const engine::HazardMaps& hz,
                                           const std::vector<double>& pressure_kpa, const products::ZoneMap& zones, double outline_threshold);

}  // namespace runout::jobs
