#include "jobs/drivers/vof_lab/setup.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::vof_lab {

namespace {

namespace vof = engine::vof;

// The block: a plane mesh one cell (dx) thick, or a 3D block with nz cells across the channel.
LabGrid lab_grid(const v1::Lab& L) {
  LabGrid g;
  g.three_d = L.nz() > 0;
  g.nx = L.nx();
  g.ny = L.ny();
  g.nz = g.three_d ? L.nz() : 1;
  g.x0 = L.x_min();
  g.y0 = L.y_min();
  g.dx = (L.x_max() - L.x_min()) / g.nx;
  g.dy = (L.y_max() - L.y_min()) / g.ny;
  g.z0 = g.three_d ? L.z_min() : 0;
  g.dz = g.three_d ? (L.z_max() - L.z_min()) / g.nz : g.dx;
  g.width = g.three_d ? L.z_max() - L.z_min() : g.dx;
  return g;
}

// The mesh of the block (obstacles cut out) or of the curved chute; on the chute also the cells'
// bed coordinates.
void build_mesh(const v1::Lab& L, LabSetup& s) {
  const LabGrid& g = s.g;
  auto blocked = [&L, y0 = g.y0](const vof::Vec& c) {
    for (const auto& o : L.obstacles())
      if (in_obstacle(o, c, y0)) return true;
    return false;
  };
  try {
    if (L.has_chute()) {
      const ChuteBed bed(L);
      vof::HexGridSpec h;
      h.ni = g.nx, h.nj = g.ny, h.nk = g.nz;
      h.node = [&](int i, int j, int k) { return bed.point(g.x0 + i * g.dx, j * g.dy, g.z0 + k * g.dz); };
      s.m = vof::structured_hex_mesh(h);
      s.local.resize(std::size_t(s.m.cells()));
      for (int k = 0; k < g.nz; ++k)
        for (int j = 0; j < g.ny; ++j)
          for (int i = 0; i < g.nx; ++i)
            s.local[std::size_t((k * g.ny + j) * g.nx + i)] = {g.x0 + (i + 0.5) * g.dx, (j + 0.5) * g.dy, g.z0 + (k + 0.5) * g.dz};
    } else if (g.three_d) {
      vof::Block3Spec b3;
      b3.x0 = L.x_min(), b3.x1 = L.x_max(), b3.y0 = L.y_min(), b3.y1 = L.y_max(), b3.z0 = L.z_min(), b3.z1 = L.z_max();
      b3.nx = g.nx, b3.ny = g.ny, b3.nz = g.nz;
      b3.blocked = blocked;
      s.m = vof::block_mesh_3d(b3);
    } else {
      vof::BlockSpec b;
      b.x0 = L.x_min(), b.x1 = L.x_max(), b.y0 = L.y_min(), b.y1 = L.y_max();
      b.nx = g.nx, b.ny = g.ny;
      b.thickness = g.dx;
      b.blocked_if = blocked;
      s.m = vof::block_mesh(b);
    }
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(std::string(L.has_chute() ? "lab.chute: " : "lab.obstacles: ") + e.what());
  }
  if (s.local.empty()) s.local = s.m.centre;
}

// The grid's map from positions to mesh cells, and the centre line's slice.
void map_cells(const v1::Lab& L, LabSetup& s) {
  LabGrid& g = s.g;
  g.cell.assign(std::size_t(g.nx) * g.ny * g.nz, -1);
  for (int c = 0; c < s.m.cells(); ++c) {
    const auto& p = s.local[std::size_t(c)];
    const int i = std::clamp(int((p.x - g.x0) / g.dx), 0, g.nx - 1), j = std::clamp(int((p.y - g.y0) / g.dy), 0, g.ny - 1),
              k = g.three_d ? std::clamp(int((p.z - g.z0) / g.dz), 0, g.nz - 1) : 0;
    g.cell[g.at(i, j, k)] = c;
  }
  g.kc = g.three_d ? std::clamp(int((0.5 * (L.z_min() + L.z_max()) - g.z0) / g.dz), 0, g.nz - 1) : 0;
}

bool inside(const v1::LabRegion& f, const vof::Vec& p) {
  if (f.cap_radius() > 0) {  // a spherical cap on the bed
    const double r = f.cap_radius(), q = r * r - (p.x - f.cap_x()) * (p.x - f.cap_x()) - (p.z - f.cap_z()) * (p.z - f.cap_z());
    return q > 0 && p.y < std::sqrt(q) - (r - f.cap_height());
  }
  if (f.polygon_xy_size() == 0) return p.x >= f.x_min() && p.x <= f.x_max() && p.y >= f.y_min() && p.y <= f.y_max();
  return in_polygon(f.polygon_xy(), p.x, p.y);
}

// Cells cut by a fill's outline get the share of their cell inside it, sampled on 4 x 4 (x 4 in
// 3D) points: a stair-stepped surface is locally steeper than phi at every step, and its corner
// cells fail at once (on the static B9 heap at 2.5 mm one reached 0.12 m/s).
void fill(const v1::Lab& L, LabSetup& s) {
  const LabGrid& g = s.g;
  s.alpha.assign(std::size_t(s.m.cells()), 0.0);
  const int ns = 4;
  const int nsz = g.three_d ? ns : 1;
  for (int k = 0; k < s.m.cells(); ++k) {
    const vof::Vec& c = s.local[std::size_t(k)];
    int in = 0;
    for (int a = 0; a < ns; ++a)
      for (int b = 0; b < ns; ++b)
        for (int e = 0; e < nsz; ++e) {
          const vof::Vec q{c.x + ((a + 0.5) / ns - 0.5) * g.dx, c.y + ((b + 0.5) / ns - 0.5) * g.dy,
                           g.three_d ? c.z + ((e + 0.5) / nsz - 0.5) * g.dz : c.z};
          for (const auto& f : L.fill())
            if (inside(f, q)) {
              ++in;
              break;
            }
        }
    s.alpha[std::size_t(k)] = double(in) / (ns * ns * nsz);
  }
  s.v0 = 0;
  for (int k = 0; k < s.m.cells(); ++k) s.v0 += s.alpha[std::size_t(k)] * s.m.volume[std::size_t(k)];
}

}  // namespace

void build_setup(const v1::Lab& L, LabSetup& out) {
  out.mat = lab_material(L);
  out.g = lab_grid(L);
  build_mesh(L, out);
  map_cells(L, out);
  out.config = lab_config(L, out.mat);
  apply_boundaries(L, out.mat, out.m, out.config);
  for (const auto& lb : L.boundaries()) out.has_inflow |= lb.kind() == "inflow";
  fill(L, out);
  if (out.v0 <= 0 && !out.has_inflow)
    throw ScenarioError("lab.fill: no cell has material from the fill regions (and no inflow feeds the channel)");
}

}  // namespace runout::jobs::vof_lab
