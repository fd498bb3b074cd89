#pragma once
// The release on the terrain mesh: the phase fraction of each cell from the released material's
// vertical thickness per grid column (the depth-averaged engine's H, so that both engines release
// the same volume), cells filled from the ground up and the partial cell by its fraction; and the
// column mesh's defaults chosen from the release.
#include <vector>

#include "terrain/column_mesh.hpp"

namespace runout::jobs::vof_terrain {

/// The column mesh's defaults for a release whose thickest column holds `max_vertical_m` of
/// material: the first layer a fifth of it (the release spans at least four layers), growth 1.2,
/// and a band of eight times it (a deposit several times the release's thickness stays inside,
/// with air above). Throws TerrainError when there is no release.
terrain::ColumnMeshSpec default_column_mesh(double max_vertical_m);

/// The phase fraction per cell of the engine's mesh of `c` (cells numbered as terrain_mesh numbers
/// them: i east fastest, then the layer, then k north; columns outside the domain skipped) from
/// the vertical thickness per grid cell, row-major as the grid (`vertical_m[j * grid_nx + i]`); the
/// refined columns of a grid cell all take its thickness, so that the volume does not change.
/// Throws TerrainError naming mesh.band_height_m when a column's release does not fit in the band,
/// and when material lies in a column outside the domain.
std::vector<double> release_alpha(const terrain::ColumnMesh& c, const std::vector<double>& vertical_m, bool outside_ok = false);

}  // namespace runout::jobs::vof_terrain
