#include "jobs/drivers/vof_terrain/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/sh2d.hpp"
#include "jobs/drivers/hazard_outputs.hpp"

namespace runout::jobs::vof_terrain {

Frame frame_of(const terrain::ColumnMesh& c) {
  Frame f;
  f.x = c.x_min + 0.5 * c.ni * c.dx;
  f.y = c.y_min + 0.5 * c.nk * c.dx;
  f.z = *std::min_element(c.ground.begin(), c.ground.end());
  return f;
}

engine::vof::Mesh terrain_mesh(const terrain::ColumnMesh& c, const Frame& frame, const std::vector<std::string>& structure_names) {
  engine::vof::HexGridSpec s;
  s.ni = c.ni;
  s.nj = c.layers();
  s.nk = c.nk;
  s.node = [&](int i, int j, int k) { return frame.to_engine(c.node_x(i), c.node_y(k), c.node_z(i, k, j)); };
  s.blocked = [&](int i, int j, int k) {
    const std::size_t col = std::size_t(k) * std::size_t(c.ni) + std::size_t(i);
    return c.kept[col] == 0 || j < c.base_of(col);
  };
  s.patch_names = {"sides", "sides", "ground", "atmosphere", "sides", "sides", "sides"};
  engine::vof::Mesh m = engine::vof::structured_hex_mesh(s);
  // A structure's faces: those of "sides" whose far side (a quarter column beyond the face) lies in
  // one of its columns.
  auto column_beyond = [&](int f) -> long {
    const engine::vof::Vec n = (1.0 / m.magSf[std::size_t(f)]) * m.Sf[std::size_t(f)];
    const engine::vof::Vec p = m.Cf[std::size_t(f)] + (0.25 * c.dx) * n;
    const double east = frame.east(p), north = frame.north(p);
    const int i = int(std::floor((east - c.x_min) / c.dx)), k = int(std::floor((north - c.y_min) / c.dx));
    if (i < 0 || k < 0 || i >= c.ni || k >= c.nk) return -1;
    return long(k) * c.ni + i;
  };
  for (std::size_t a = 0; a < structure_names.size() && !c.structure.empty(); ++a)
    engine::vof::split_patch(m, "sides", structure_patch(structure_names[a]), [&](int f) {
      const long col = column_beyond(f);
      return col >= 0 && c.structure[std::size_t(col)] == int(a);
    });
  return m;
}

Columns columns_of(const terrain::ColumnMesh& c) {
  Columns out;
  out.ni = c.ni;
  out.nk = c.nk;
  out.layers = c.layers();
  out.refinement = c.refinement;
  out.plan_area = c.dx * c.dx;
  out.levels = c.levels;
  out.cells.assign(out.columns() * std::size_t(out.layers), -1);
  int next = 0;  // terrain_mesh's numbering: i fastest, then the layer, then k; left-out columns skipped
  for (int k = 0; k < c.nk; ++k)
    for (int j = 0; j < out.layers; ++j)
      for (int i = 0; i < c.ni; ++i) {
        const std::size_t col = std::size_t(k) * std::size_t(c.ni) + std::size_t(i);
        if (c.kept[col] && j >= c.base_of(col)) out.cells[col * std::size_t(out.layers) + std::size_t(j)] = next++;
      }
  return out;
}

engine::vof::MeshColumns bed_columns(const Columns& cols, const engine::vof::Mesh& m, const terrain::Grid& g) {
  engine::vof::MeshColumns out;
  std::vector<int> face_of(std::size_t(m.cells()), -1);
  const auto& ground = m.patch("ground");
  for (int f = ground.start; f < ground.start + ground.size; ++f) face_of[std::size_t(m.owner[std::size_t(f)])] = f;
  const auto geo = engine::SurfaceGeometry::from(engine_terrain(g));
  out.start.push_back(0);
  for (std::size_t col = 0; col < cols.columns(); ++col) {
    if (cols.cell(col, 0) < 0) continue;
    out.bed_face.push_back(face_of[std::size_t(cols.cell(col, 0))]);
    for (int j = 0; j < cols.layers; ++j) out.cells.push_back(cols.cell(col, j));
    out.start.push_back(int(out.cells.size()));
    // x east, z south: the horizontal velocity (east, north) is (u.x, -u.z).
    const std::size_t gc = cols.grid_cell(col);
    const double c = geo.c[gc];
    engine::vof::Tensor K;
    K.g[0][0] = c * geo.hxx[gc];
    K.g[0][2] = K.g[2][0] = -c * geo.hxy[gc];
    K.g[2][2] = c * geo.hyy[gc];
    out.curvature.push_back(K);
  }
  return out;
}

}  // namespace runout::jobs::vof_terrain
