#include "terrain/column_mesh.hpp"

#include <cmath>
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

ColumnMesh column_mesh(const Grid& g, const ColumnMeshSpec& s) {
  if (g.nx < 2 || g.ny < 2) throw TerrainError("mesh: the grid needs at least 2 x 2 cells");
  ColumnMesh m;
  m.ni = g.nx;
  m.nk = g.ny;
  m.x_min = g.x_min;
  m.y_min = g.y_min;
  m.dx = g.dx;
  m.levels = layer_levels(s);
  m.ground.resize(std::size_t(g.nx + 1) * std::size_t(g.ny + 1));
  auto z = [&](int i, int j) { return g.z[std::size_t(j) * std::size_t(g.nx) + std::size_t(i)]; };
  for (int k = 0; k <= g.ny; ++k) {
    const Pair pj = node_weights(k, g.ny);
    for (int i = 0; i <= g.nx; ++i) {
      const Pair pi = node_weights(i, g.nx);
      m.ground[std::size_t(k) * std::size_t(g.nx + 1) + std::size_t(i)] =
          pj.wa * (pi.wa * z(pi.a, pj.a) + pi.wb * z(pi.b, pj.a)) + pj.wb * (pi.wa * z(pi.a, pj.b) + pi.wb * z(pi.b, pj.b));
    }
  }
  m.kept.resize(g.cells());
  for (std::size_t c = 0; c < g.cells(); ++c) m.kept[c] = g.outside.empty() || g.outside[c] == 0;
  if (m.kept_columns() == 0) throw TerrainError("mesh: no column lies inside the domain");
  return m;
}

}  // namespace runout::terrain
