#pragma once
// The terrain-following column mesh of the 3D engine on real terrain: above each cell of the
// computation grid that lies inside the domain (Grid::outside == 0: inside the area of interest,
// with DEM data), a column of hexahedra from the ground up to a band height, its layers graded
// towards the ground. Columns are vertical; each layer interface follows the ground at a constant
// height above it, so that the cells' bottoms and tops are the ground surface lifted.
//
// The ground at the grid cells' corners is the bilinear interpolant of the cell centres' elevations,
// extrapolated linearly at the grid's edges: a plane DEM gives a plane ground. Refined columns
// (mesh.refinement) split each grid cell into R x R columns on the same ground.
// The area of interest is followed cell by cell (columns kept by their centre, as the depth-averaged
// engine keeps cells); the faces towards a left-out column are the mesh's sides.
//
// terrain/ computes the nodes and the kept columns; the terrain run driver builds the VOF engine's
// mesh from them (engine/vof structured_hex_mesh), so terrain/ stays free of the engine.
#include <cstdint>
#include <vector>

#include "terrain/terrain.hpp"

namespace runout::terrain {

struct ColumnMeshSpec {
  double first_layer_m = 0;  ///< the layer on the ground, vertical thickness [m]; > 0
  double growth = 1.2;       ///< each layer this many times the one below it; 1-3
  double band_height_m = 0;  ///< from the ground to the mesh's top [m]; > first_layer_m
  int refinement = 1;        ///< columns per grid cell along each axis; 1-8
};

/// The heights above the ground of the layer interfaces, 0 first and band_height_m last: layers of
/// first_layer_m growing by `growth`, as many as reach the band height, then all scaled by the same
/// factor (at most 1) so that they end exactly there. Throws TerrainError naming the option.
std::vector<double> layer_levels(const ColumnMeshSpec& s);

/// The grid cell (j * (ni / refinement) + i) of refined column col = k * ni + i, with ni columns
/// along x and `refinement` columns per grid cell along each axis.
inline std::size_t grid_cell_of(std::size_t col, int ni, int refinement) {
  const std::size_t i = col % std::size_t(ni), k = col / std::size_t(ni), r = std::size_t(refinement);
  return (k / r) * (std::size_t(ni) / r) + i / r;
}

struct ColumnMesh {
  int ni = 0, nk = 0;        ///< columns along x (east) and y (north): the grid's cells times the refinement
  int refinement = 1;        ///< columns per grid cell along each axis
  double x_min = 0, y_min = 0, dx = 0;  ///< the grid's corner; the columns' width (the grid's cell / refinement)
  std::vector<double> levels;           ///< layer interfaces above the ground (layer_levels)
  std::vector<double> ground;           ///< (ni + 1) (nk + 1) node elevations, node (i, k) at k (ni + 1) + i
  std::vector<std::uint8_t> kept;       ///< per column (row k south to north, k * ni + i): 1 inside the domain
  /// Structures (place_structures): per column the layers a structure takes from the ground up (0:
  /// none; layers(): the whole column) and the structure's index (-1: none). Empty: no structures.
  std::vector<int> base, structure;
  int base_of(std::size_t col) const { return base.empty() ? 0 : base[col]; }
  int layers() const { return int(levels.size()) - 1; }
  double ground_at(int i, int k) const { return ground[std::size_t(k) * std::size_t(ni + 1) + std::size_t(i)]; }
  /// Node (i, k) of interface j in the grid's CRS: x east, y north, z up.
  double node_x(int i) const { return x_min + i * dx; }
  double node_y(int k) const { return y_min + k * dx; }
  double node_z(int i, int k, int j) const { return ground_at(i, k) + levels[std::size_t(j)]; }
  int kept_columns() const;
  /// The grid cell (j * (ni / refinement) + i) that column col = k * ni + i lies in.
  std::size_t grid_cell(std::size_t col) const { return grid_cell_of(col, ni, refinement); }
};

/// The column mesh over `g` (at least 2 x 2 cells): the columns inside the domain, and when
/// `corridor` is given (one flag per grid cell, row 0 south) only those of the corridor too. With a
/// refinement R each grid cell holds R x R columns whose ground nodes lie on the unrefined mesh's
/// ground (bilinear within each grid cell): the same surface, so that the refinement changes the
/// flow's resolution and not the terrain. Throws TerrainError when the spec is out of range or no
/// column is kept.
ColumnMesh column_mesh(const Grid& g, const ColumnMeshSpec& s, const std::vector<std::uint8_t>& corridor = {});

/// Stands the structures `rq` (footprint polygons with a height or a top elevation) on the column
/// mesh `m` of grid `g`: a column whose centre lies inside a footprint (or that holds the centroid of
/// a footprint that covers no centre) loses the layers whose middle lies below the structure's top
/// there (ColumnMesh::base, ::structure; where structures overlap, the later one's). The heights are
/// read at the columns' centres, their ground the mean of the column's four ground nodes. Throws
/// TerrainError naming the request's field (terrain::rasterize_dam's errors), and when a structure
/// keeps no column or takes no layer (lower than half the first layer).
void place_structures(ColumnMesh& m, const Grid& g, const std::vector<DamRequest>& rq);

/// The cells of `cells` (one flag per grid cell) dilated by `margin_m`: every cell whose centre lies
/// within margin_m (Euclidean, centre to centre) of a flagged cell's centre. margin_m >= 0.
std::vector<std::uint8_t> dilate_cells(const Grid& g, const std::vector<std::uint8_t>& cells, double margin_m);

}  // namespace runout::terrain
