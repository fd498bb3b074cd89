#pragma once
// The map picture of a run: hillshade of the terrain (GDAL's DEM tools), the maximum flow depth in
// colour classes with a legend, the release cells and the runout outline drawn on top, a scale bar
// and a north arrow. PNG through GDAL's PNG driver.
#include <string>
#include <vector>

#include "terrain/terrain.hpp"

namespace runout::figures {
using terrain::Grid;

struct MapRequest {
  std::string title;           ///< drawn at the top (ASCII; characters without a glyph are skipped)
  double outline_threshold = 0.1;
  int scale = 2;               ///< pixels per cell (the picture is upscaled for legibility)
};

/// Write the map as PNG. `max_depth` and `release` are per cell, row 0 south (like Grid::z).
void write_map_png(const std::string& path, const Grid& g, const std::vector<double>& max_depth,
                   const std::vector<double>& release, const MapRequest& req);

}  // namespace runout::figures
