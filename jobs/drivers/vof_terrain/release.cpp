#include "jobs/drivers/vof_terrain/release.hpp"

#include "jobs/drivers/vof_terrain/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace runout::jobs::vof_terrain {

terrain::ColumnMeshSpec default_column_mesh(double max_vertical_m) {
  if (!(max_vertical_m > 0) || !std::isfinite(max_vertical_m))
    throw terrain::TerrainError("mesh: the release holds no material, so the mesh's layers cannot be chosen from it");
  return {max_vertical_m / 5, 1.2, 8 * max_vertical_m};
}

std::vector<double> release_alpha(const terrain::ColumnMesh& c, const std::vector<double>& vertical_m, bool outside_ok) {
  if (vertical_m.size() != std::size_t(c.ni) * std::size_t(c.nk) / std::size_t(c.refinement * c.refinement))
    throw terrain::TerrainError("release: the thickness raster is not of the mesh's grid");
  const double band = c.levels.back();
  const Columns cols = columns_of(c);
  std::size_t cells = 0;
  for (int id : cols.cells) cells += id >= 0;
  std::vector<double> alpha(cells, 0.0);
  for (std::size_t col = 0; col < cols.columns(); ++col) {
    const double h = vertical_m[c.grid_cell(col)];  // every column of a grid cell takes the cell's thickness
    // The grid cell, as the user's rasters number it (the refined column lies in it).
    const int i = int(col % std::size_t(c.ni)) / c.refinement, k = int(col / std::size_t(c.ni)) / c.refinement;
    if (!c.kept[col]) {
      if (h > 0 && !outside_ok)
        throw terrain::TerrainError("release: material in the grid cell (" + std::to_string(i) + ", " + std::to_string(k) + ") outside the domain");
      continue;
    }
    if (h > band)
      throw terrain::TerrainError("mesh.band_height_m: " + std::to_string(band) + " m does not hold the release's " + std::to_string(h) +
                                  " m in grid cell (" + std::to_string(i) + ", " + std::to_string(k) + ")");
    for (int j = 0; j < c.layers(); ++j) {
      const double lo = c.levels[std::size_t(j)], hi = c.levels[std::size_t(j) + 1];
      if (cols.cell(col, j) >= 0)  // not inside a structure
        alpha[std::size_t(cols.cell(col, j))] = std::clamp((h - lo) / (hi - lo), 0.0, 1.0);
    }
  }
  return alpha;
}

}  // namespace runout::jobs::vof_terrain
