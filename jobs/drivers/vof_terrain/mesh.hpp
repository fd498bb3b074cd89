#pragma once
// The VOF engine's mesh over real terrain: the column mesh of terrain/column_mesh.hpp as hexahedra
// in the engine's frame. The engine's frame is right-handed with y up, as the laboratory set-ups'
// (gravity along -y): x east, y the elevation above `origin.z`, z south, in metres from the grid's
// centre. Patches: "ground" (the bottom of every column), "atmosphere" (the top), "sides" (the
// grid's edges and the faces towards columns outside the domain), and per structure
// (terrain::place_structures) "structure:NAME" (its walls and roof).
#include <vector>

#include "engine/vof/column_friction.hpp"
#include "engine/vof/mesh.hpp"
#include "terrain/column_mesh.hpp"

namespace runout::jobs::vof_terrain {

/// Where the engine's frame lies in the grid's CRS: x = east - origin.x, y = elevation - origin.z,
/// z = origin.y - north.
struct Frame {
  double x = 0, y = 0, z = 0;
  engine::vof::Vec to_engine(double east, double north, double elevation) const { return {east - x, elevation - z, y - north}; }
  /// A point of the engine's frame in the grid's CRS: its east and north.
  double east(const engine::vof::Vec& p) const { return p.x + x; }
  double north(const engine::vof::Vec& p) const { return y - p.z; }
};

/// The frame of a column mesh: the grid's centre, the lowest ground node.
Frame frame_of(const terrain::ColumnMesh& c);

/// The engine's mesh of the kept columns: i east, j up the layers, k north (cell (i, j, k) of the
/// engine's structured numbering with left-out columns skipped).
engine::vof::Mesh terrain_mesh(const terrain::ColumnMesh& c, const Frame& frame, const std::vector<std::string>& structure_names = {});

/// The patch of structure `name`.
inline std::string structure_patch(const std::string& name) { return "structure:" + name; }

/// The engine's cells of each column, bottom up: cell(col, layer), -1 for columns outside the
/// domain and for the layers a structure takes; col = k * ni + i (row 0 south). Cells numbered as terrain_mesh() numbers them (the one
/// place that numbering is spelt out besides structured_hex_mesh). With a refinement R each grid
/// cell holds R x R columns (sub_column).
struct Columns {
  int ni = 0, nk = 0, layers = 0;
  int refinement = 1;          ///< columns per grid cell along each axis
  double plan_area = 0;        ///< of one column [m2]
  std::vector<double> levels;  ///< the layer interfaces' heights above the ground (ColumnMesh::levels)
  std::vector<int> cells;      ///< (col * layers + layer)
  int cell(std::size_t col, int layer) const { return cells[col * std::size_t(layers) + std::size_t(layer)]; }
  std::size_t columns() const { return std::size_t(ni) * std::size_t(nk); }
  int grid_nx() const { return ni / refinement; }
  std::size_t grid_cells() const { return columns() / std::size_t(refinement * refinement); }
  /// The grid cell (j * grid_nx + i) of column col.
  std::size_t grid_cell(std::size_t col) const { return terrain::grid_cell_of(col, ni, refinement); }
  /// Column n (0 to R^2 - 1) of grid cell gc.
  std::size_t sub_column(std::size_t gc, int n) const {
    const std::size_t r = std::size_t(refinement), gi = gc % std::size_t(grid_nx()), gj = gc / std::size_t(grid_nx());
    return (gj * r + std::size_t(n) / r) * std::size_t(ni) + gi * r + std::size_t(n) % r;
  }
};
Columns columns_of(const terrain::ColumnMesh& c);

/// The engine's columns (the bed friction on the column's weight, VofConfig::column_friction): per
/// kept column its "ground" face, its cells bottom up, and the bed's curvature from the grid's
/// elevations (its grid cell's) (the depth-averaged engine's Hessian, as u.K.u = cos(theta) u_h.Hess(b).u_h for the
/// horizontal part u_h of a velocity along the bed, in the engine's frame).
engine::vof::MeshColumns bed_columns(const Columns& cols, const engine::vof::Mesh& m, const terrain::Grid& g);

}  // namespace runout::jobs::vof_terrain
