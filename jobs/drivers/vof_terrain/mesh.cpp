#include "jobs/drivers/vof_terrain/mesh.hpp"

#include <algorithm>

namespace runout::jobs::vof_terrain {

Frame frame_of(const terrain::ColumnMesh& c) {
  Frame f;
  f.x = c.x_min + 0.5 * c.ni * c.dx;
  f.y = c.y_min + 0.5 * c.nk * c.dx;
  f.z = *std::min_element(c.ground.begin(), c.ground.end());
  return f;
}

engine::vof::Mesh terrain_mesh(const terrain::ColumnMesh& c, const Frame& frame) {
  engine::vof::HexGridSpec s;
  s.ni = c.ni;
  s.nj = c.layers();
  s.nk = c.nk;
  s.node = [&](int i, int j, int k) { return frame.to_engine(c.node_x(i), c.node_y(k), c.node_z(i, k, j)); };
  s.blocked = [&](int i, int, int k) { return c.kept[std::size_t(k) * std::size_t(c.ni) + std::size_t(i)] == 0; };
  s.patch_names = {"sides", "sides", "ground", "atmosphere", "sides", "sides", "sides"};
  return engine::vof::structured_hex_mesh(s);
}

Columns columns_of(const terrain::ColumnMesh& c) {
  Columns out;
  out.ni = c.ni;
  out.nk = c.nk;
  out.layers = c.layers();
  out.plan_area = c.dx * c.dx;
  out.levels = c.levels;
  out.cells.assign(out.columns() * std::size_t(out.layers), -1);
  int next = 0;  // terrain_mesh's numbering: i fastest, then the layer, then k; left-out columns skipped
  for (int k = 0; k < c.nk; ++k)
    for (int j = 0; j < out.layers; ++j)
      for (int i = 0; i < c.ni; ++i) {
        const std::size_t col = std::size_t(k) * std::size_t(c.ni) + std::size_t(i);
        if (c.kept[col]) out.cells[col * std::size_t(out.layers) + std::size_t(j)] = next++;
      }
  return out;
}

}  // namespace runout::jobs::vof_terrain
