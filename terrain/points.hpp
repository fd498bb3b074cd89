#pragma once
// Named points given by the user in any CRS (a farmhouse in WGS84 longitude and latitude, a dam
// in the national grid), placed on the computation grid.
#include <string>
#include <utility>
#include <vector>

#include "terrain/terrain.hpp"

namespace runout::terrain {

struct GridPoint {
  double x = 0, y = 0;  ///< in the grid's CRS
  int i = -1, j = -1;   ///< the grid cell holding it (row 0 south)
};

/// The point (x, y) in `crs` ("" or the grid's: as given; "EPSG:4326": longitude, latitude) on `g`.
/// Throws TerrainError naming `what` when the CRS is unknown, cannot be related to the grid's, or the
/// point lies outside the domain (outside the grid or in a cell outside the area of interest).
GridPoint place_point(const Grid& g, double x, double y, const std::string& crs, const std::string& what);

/// The first line of the vector file `path` (its own CRS, else `crs`) as vertices in the grid's CRS.
/// Throws TerrainError naming `what` when it cannot be read, holds no line or has fewer than two
/// vertices.
std::vector<std::pair<double, double>> read_line(const Grid& g, const std::string& path, const std::string& crs, const std::string& what);

}  // namespace runout::terrain
