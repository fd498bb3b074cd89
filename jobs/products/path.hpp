#pragma once
// The path (thalweg) analysis of a run, as AvaFrame's AIMEC does it: the path resampled every cell
// size, a cross-section of the domain width across it at each station, the maxima of depth, speed
// and pressure in each cross-section (the longitudinal profiles), the runout point (the last station
// whose cross-section reaches the threshold), the runout angle alpha, the beta point and the runout
// zone's area beyond it.
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "jobs/scenario/scenario.hpp"
#include "terrain/terrain.hpp"

namespace runout::jobs::products {

using Line = std::vector<std::pair<double, double>>;

/// The path of steepest descent on the DEM from (x, y) (the release's centroid): from cell to the
/// neighbour of the steepest drop (of eight) until no neighbour is lower, then on straight in the
/// last 200 m's direction to the domain's edge, so that a flat run-out zone is crossed too.
Line steepest_descent(const terrain::Grid& g, double x, double y);

/// The flow's mass centre at one time (volume-weighted, in the grid's CRS).
struct TrackPoint {
  double t = 0, x = 0, y = 0;
};

/// The path the flow took, as com1DFA and AIMEC take it: the mass centre's track in time order
/// (points closer than half a cell to the last one kept dropped), extended at the top straight back
/// against its first direction to the release's upper edge (the last released cell on that line
/// before the first gap),
/// and at the bottom straight on in its last 200 m's direction to the domain's edge, so that the
/// front beyond the mass centre's stop is crossed. Empty when the track has fewer than two distinct
/// points (a flow that did not move).
Line flow_path(const terrain::Grid& g, const std::vector<TrackPoint>& track, const std::vector<double>& release);

/// The longest flow line: from the highest released cell through the released and outlined cells
/// (moves to the eight neighbours, one or √2 cells long) to the outlined cell beyond the release
/// farthest from it along such moves; the line to it keeps to the flow's middle (each move costs its
/// length over (1 + the cell's distance to the flow's edge)²), smoothed over five cells and extended
/// straight on to the domain's edge as the track is. It follows the branch that reached farthest.
/// Empty without released or outlined cells.
/// `far_end`, when given, receives the farthest cell's centre.
Line longest_flow_line(const terrain::Grid& g, const std::vector<double>& release, const std::vector<double>& max_depth, double threshold,
                       std::pair<double, double>* far_end = nullptr);

/// The horizontal distance from (x, y) to the polyline.
double distance_to_line(const Line& line, double x, double y);

/// Whether every point of the track (after its first) lies on a cell of the outline (max depth
/// above `threshold`): false when the flow split and its mass centre left it.
bool track_inside_outline(const terrain::Grid& g, const std::vector<TrackPoint>& track, const std::vector<double>& max_depth, double threshold);

/// The hazard maps the analysis reads, per cell (row 0 south; NaN outside the domain).
struct PathFields {
  const std::vector<double>& depth;         ///< [m]
  const std::vector<double>& speed;         ///< [m/s]
  const std::vector<double>& pressure_kpa;  ///< [kPa]
  const std::vector<double>& release;       ///< release thickness (> 0: released), where beta is not looked for
};

struct PathProfile {
  std::vector<double> s, x, y, z;          ///< per station: horizontal distance along the path, place, ground
  std::vector<double> depth, speed, pressure_kpa;  ///< per station: the largest in its cross-section
  double spacing = 0, length = 0;
  std::optional<std::size_t> runout, beta;  ///< station indices
  double alpha_deg = 0;                     ///< with a runout point
  double runout_zone_area_m2 = 0;
  std::string criterion;                    ///< e.g. "max pressure >= 1 kPa"
};

/// Analyse the run's maps along `line` (in the grid's CRS, from the top down). Throws
/// terrain::TerrainError when the line has no length.
PathProfile analyse_path(const terrain::Grid& g, const Line& line, const PathFields& f, const PathSettings& s);

/// path_profile.csv: one row per station.
void write_profile_csv(const std::string& path, const PathProfile& p);

}  // namespace runout::jobs::products
