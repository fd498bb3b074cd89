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

}  // namespace runout::jobs::vof_terrain
