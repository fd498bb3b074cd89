#include "jobs/drivers/vof_terrain/corridor.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "engine/sh2d.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "terrain/column_mesh.hpp"

namespace runout::jobs::vof_terrain {

double corridor_margin(const v1::TerrainMesh& m, double dx) {
  if (m.has_corridor_margin_m()) return m.corridor_margin_m();
  return std::max(150.0, 2 * dx);
}

std::vector<std::uint8_t> footprint_corridor(const terrain::Grid& g, const std::vector<double>& max_depth, double threshold,
                                             const std::vector<double>& h0, double margin_m, int* footprint_cells) {
  std::vector<std::uint8_t> in(g.cells(), 0);
  int n = 0;
  for (std::size_t c = 0; c < g.cells(); ++c) {
    in[c] = (max_depth[c] > threshold) || (c < h0.size() && h0[c] > 0);
    n += in[c];
  }
  if (footprint_cells) *footprint_cells = n;
  return terrain::dilate_cells(g, in, margin_m);
}

Corridor build_corridor(const ResolvedScenario& r, const terrain::Grid& g, const std::vector<double>& h0) {
  const auto& me = r.scenario.mesh();
  Corridor c;
  c.kind = me.corridor().empty() ? "footprint" : me.corridor();
  if (c.kind == "none") return c;
  if (c.kind == "polygon") {
    c.path = r.corridor_path;
    const std::string what = "mesh.corridor_path";
    c.cells = terrain::rasterize_polygons(g, r.corridor_path, me.corridor_crs(), what);
    std::size_t covered = 0, left_out = 0;
    for (std::size_t k = 0; k < g.cells(); ++k) {
      covered += c.cells[k] != 0;
      left_out += h0[k] > 0 && !c.cells[k];
    }
    if (covered == 0) throw ScenarioError(what + ": '" + r.corridor_path + "' covers no cell of the domain");
    if (left_out > 0 && !r.nest_part)  // a nest's release outside it is the depth-averaged run's
      throw ScenarioError(what + ": '" + r.corridor_path + "' leaves " + std::to_string(left_out) +
                          " release cell(s) out: the release must lie inside the corridor");
    return c;
  }
  // "footprint": the depth-averaged engine on the same grid, release, material and numerics, as the
  // depth-averaged driver runs it (without outputs).
  const auto t0 = std::chrono::steady_clock::now();
  const engine::Terrain2D t = engine_terrain(g);
  engine::Sh2dConfig cfg = r.config;
  cfg.time.progress = {};
  cfg.snapshot = {};
  cfg.snapshot_interval = 0;
  cfg.checkpoint = {};
  cfg.checkpoint_interval = 0;
  const engine::Sh2dResult res = engine::run_sh2d(t, cfg, engine::state_from_normal_depth(t, h0));
  c.footprint_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  c.margin_m = corridor_margin(me, g.dx);
  c.cells = footprint_corridor(g, res.hazard.max_depth, r.config.flow_threshold, h0, c.margin_m, &c.footprint_cells);
  return c;
}

std::vector<std::uint8_t> corridor_edge_faces(const Columns& cols, const engine::vof::Mesh& m, const terrain::Grid& g) {
  std::vector<std::uint8_t> out(std::size_t(m.faces()), 0);
  const int p = m.patch_index("sides");
  if (p < 0) return out;
  std::vector<int> column_of(std::size_t(m.cells()), -1);
  for (std::size_t col = 0; col < cols.columns(); ++col)
    for (int j = 0; j < cols.layers; ++j)
      if (cols.cell(col, j) >= 0) column_of[std::size_t(cols.cell(col, j))] = int(col);
  const auto& sides = m.patches[std::size_t(p)];
  for (int f = sides.start; f < sides.start + sides.size; ++f) {
    const int col = column_of[std::size_t(m.owner[std::size_t(f)])];
    int i = col % cols.ni, k = col / cols.ni;
    const auto& s = m.Sf[std::size_t(f)];  // horizontal: x east, z south
    if (std::abs(s.x) >= std::abs(s.z)) i += s.x > 0 ? 1 : -1;
    else k += s.z > 0 ? -1 : 1;
    if (i < 0 || k < 0 || i >= cols.ni || k >= cols.nk) continue;  // the grid's edge
    const std::size_t nb = cols.grid_cell(std::size_t(k) * std::size_t(cols.ni) + std::size_t(i));
    if (g.outside.empty() || g.outside[nb] == 0) out[std::size_t(f)] = 1;
  }
  return out;
}

}  // namespace runout::jobs::vof_terrain
