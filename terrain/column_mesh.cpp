#include "terrain/column_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace runout::terrain {

namespace {

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

// Weights of the cells on either side of node n along an axis of `cells` cells: the mean of the
// two inside, a linear extrapolation from the two outermost cells at the edges.
struct Pair {
  int a, b;
  double wa, wb;
};
Pair node_weights(int n, int cells) {
  if (n == 0) return {0, 1, 1.5, -0.5};
  if (n == cells) return {cells - 1, cells - 2, 1.5, -0.5};
  return {n - 1, n, 0.5, 0.5};
}

}  // namespace

std::vector<double> layer_levels(const ColumnMeshSpec& s) {
  if (!(s.first_layer_m > 0) || !std::isfinite(s.first_layer_m))
    throw TerrainError("mesh.first_layer_m: must be > 0, got " + num(s.first_layer_m));
  if (!(s.growth >= 1 && s.growth <= 3)) throw TerrainError("mesh.growth: must lie in [1, 3], got " + num(s.growth));
  if (s.refinement < 1 || s.refinement > 8) throw TerrainError("mesh.refinement: must lie in [1, 8], got " + std::to_string(s.refinement));
  if (!(s.band_height_m > s.first_layer_m) || !std::isfinite(s.band_height_m))
    throw TerrainError("mesh.band_height_m: must be finite and above mesh.first_layer_m (" + num(s.first_layer_m) + " m), got " +
                       num(s.band_height_m));
  std::vector<double> levels{0.0};
  double t = s.first_layer_m;
  while (levels.back() < s.band_height_m) {
    if (levels.size() > 1000) throw TerrainError("mesh: more than 1000 layers; raise mesh.first_layer_m or mesh.growth");
    levels.push_back(levels.back() + t);
    t *= s.growth;
  }
  const double scale = s.band_height_m / levels.back();
  for (auto& l : levels) l *= scale;
  levels.back() = s.band_height_m;
  return levels;
}

int ColumnMesh::kept_columns() const {
  int n = 0;
  for (auto k : kept) n += k != 0;
  return n;
}

std::vector<std::uint8_t> dilate_cells(const Grid& g, const std::vector<std::uint8_t>& cells, double margin_m) {
  if (cells.size() != g.cells()) throw TerrainError("dilate_cells: one flag per grid cell expected");
  if (!(margin_m >= 0) || !std::isfinite(margin_m)) throw TerrainError("dilate_cells: the margin must be >= 0, got " + num(margin_m));
  const int r = int(std::floor(margin_m / g.dx + 1e-9));
  std::vector<std::uint8_t> out(cells.size(), 0);
  // The disc's half-width per row offset; only cells on the set's edge stamp it (an interior
  // cell's disc lies within its neighbours' and the set itself).
  std::vector<int> half(std::size_t(r) + 1);
  for (int dj = 0; dj <= r; ++dj) half[std::size_t(dj)] = int(std::floor(std::sqrt(std::max(0.0, (margin_m / g.dx) * (margin_m / g.dx) - double(dj) * dj)) + 1e-9));
  auto at = [&](int i, int j) { return std::size_t(j) * std::size_t(g.nx) + std::size_t(i); };
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      if (!cells[at(i, j)]) continue;
      out[at(i, j)] = 1;
      const bool edge = i == 0 || j == 0 || i == g.nx - 1 || j == g.ny - 1 || !cells[at(i - 1, j)] || !cells[at(i + 1, j)] ||
                        !cells[at(i, j - 1)] || !cells[at(i, j + 1)];
      if (!edge || r == 0) continue;
      for (int dj = -r; dj <= r; ++dj) {
        const int jj = j + dj;
        if (jj < 0 || jj >= g.ny) continue;
        const int h = half[std::size_t(std::abs(dj))];
        for (int ii = std::max(0, i - h); ii <= std::min(g.nx - 1, i + h); ++ii) out[at(ii, jj)] = 1;
      }
    }
  return out;
}

ColumnMesh column_mesh(const Grid& g, const ColumnMeshSpec& s, const std::vector<std::uint8_t>& corridor) {
  if (!corridor.empty() && corridor.size() != g.cells()) throw TerrainError("mesh: the corridor needs one flag per grid cell");
  if (g.nx < 2 || g.ny < 2) throw TerrainError("mesh: the grid needs at least 2 x 2 cells");
  ColumnMesh m;
  m.levels = layer_levels(s);
  const int r = s.refinement;
  m.refinement = r;
  m.ni = g.nx * r;
  m.nk = g.ny * r;
  m.x_min = g.x_min;
  m.y_min = g.y_min;
  m.dx = g.dx / r;
  // The grid cells' corners, then the refined nodes bilinear between them.
  std::vector<double> corner(std::size_t(g.nx + 1) * std::size_t(g.ny + 1));
  auto z = [&](int i, int j) { return g.z[std::size_t(j) * std::size_t(g.nx) + std::size_t(i)]; };
  for (int k = 0; k <= g.ny; ++k) {
    const Pair pj = node_weights(k, g.ny);
    for (int i = 0; i <= g.nx; ++i) {
      const Pair pi = node_weights(i, g.nx);
      corner[std::size_t(k) * std::size_t(g.nx + 1) + std::size_t(i)] =
          pj.wa * (pi.wa * z(pi.a, pj.a) + pi.wb * z(pi.b, pj.a)) + pj.wb * (pi.wa * z(pi.a, pj.b) + pi.wb * z(pi.b, pj.b));
    }
  }
  auto at = [&](int i, int k) { return corner[std::size_t(k) * std::size_t(g.nx + 1) + std::size_t(i)]; };
  m.ground.resize(std::size_t(m.ni + 1) * std::size_t(m.nk + 1));
  for (int k = 0; k <= m.nk; ++k) {
    const int k0 = std::min(k / r, g.ny - 1);
    const double fk = double(k - k0 * r) / r;
    for (int i = 0; i <= m.ni; ++i) {
      const int i0 = std::min(i / r, g.nx - 1);
      const double fi = double(i - i0 * r) / r;
      m.ground[std::size_t(k) * std::size_t(m.ni + 1) + std::size_t(i)] =
          (1 - fk) * ((1 - fi) * at(i0, k0) + fi * at(i0 + 1, k0)) + fk * ((1 - fi) * at(i0, k0 + 1) + fi * at(i0 + 1, k0 + 1));
    }
  }
  m.kept.resize(std::size_t(m.ni) * std::size_t(m.nk));
  for (std::size_t col = 0; col < m.kept.size(); ++col) {
    const std::size_t c = m.grid_cell(col);
    m.kept[col] = (g.outside.empty() || g.outside[c] == 0) && (corridor.empty() || corridor[c] != 0);
  }
  if (m.kept_columns() == 0) throw TerrainError(corridor.empty() ? "mesh: no column lies inside the domain" : "mesh: no column of the corridor lies inside the domain");
  return m;
}

void place_structures(ColumnMesh& m, const Grid& g, const std::vector<DamRequest>& rq) {
  if (rq.empty()) return;
  Grid cg;  // the columns as a grid: the same CRS and corner, the columns' width, the ground at their centres
  cg.nx = m.ni;
  cg.ny = m.nk;
  cg.dx = m.dx;
  cg.x_min = m.x_min;
  cg.y_min = m.y_min;
  cg.crs_wkt = g.crs_wkt;
  cg.crs_name = g.crs_name;
  cg.z.resize(cg.cells());
  cg.outside.resize(cg.cells());
  for (int k = 0; k < m.nk; ++k)
    for (int i = 0; i < m.ni; ++i) {
      const std::size_t col = std::size_t(k) * std::size_t(m.ni) + std::size_t(i);
      cg.z[col] = 0.25 * (m.ground_at(i, k) + m.ground_at(i + 1, k) + m.ground_at(i, k + 1) + m.ground_at(i + 1, k + 1));
      cg.outside[col] = m.kept[col] ? 0 : 1;
    }
  m.base.assign(cg.cells(), 0);
  m.structure.assign(cg.cells(), -1);
  for (std::size_t a = 0; a < rq.size(); ++a) {
    DamRequest q = rq[a];
    q.centres_only = true;
    const DamCells d = rasterize_dam(cg, q);  // throws when the structure stands on no kept column
    int taken = 0;
    for (std::size_t col = 0; col < cg.cells(); ++col) {
      if (!(d.height[col] > 0)) continue;
      int layers = 0;
      while (layers < m.layers() && 0.5 * (m.levels[std::size_t(layers)] + m.levels[std::size_t(layers) + 1]) < d.height[col]) ++layers;
      if (layers == 0) continue;
      m.base[col] = layers;
      m.structure[col] = int(a);
      ++taken;
    }
    if (taken == 0)
      throw TerrainError(q.field + ": lower than half the mesh's first layer (" + num(m.levels[1]) +
                         " m) on every column it stands on: it takes no cell (raise mesh.first_layer_m's resolution or leave it out)");
  }
}

}  // namespace runout::terrain
