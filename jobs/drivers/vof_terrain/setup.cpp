#include "jobs/drivers/vof_terrain/setup.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/sh2d.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/vof_terrain/release.hpp"

namespace runout::jobs::vof_terrain {

namespace {

// The scenario's mesh block over the defaults chosen from the release.
terrain::ColumnMeshSpec mesh_spec(const v1::TerrainMesh& m, double max_vertical) {
  terrain::ColumnMeshSpec s = default_column_mesh(max_vertical);
  if (m.has_first_layer_m()) s.first_layer_m = m.first_layer_m();
  s.growth = m.growth();
  if (m.has_band_height_m()) s.band_height_m = m.band_height_m();
  return s;  // terrain::layer_levels checks them
}

std::string fixed(double v, int digits) {
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

}  // namespace

int choose_refinement(int asked, double dx, double max_vertical_m, long columns, int layers, std::string& reason) {
  if (asked > 0) {
    reason = "mesh.refinement " + std::to_string(asked);
    return asked;
  }
  int want = 1;
  while (want < 4 && dx / want > kRefinementDepths * max_vertical_m) want *= 2;
  int r = want;
  while (r > 1 && double(columns) * r * r * layers > kRefinementCellBudget) r /= 2;
  reason = "the rule (mesh.refinement 0): columns of " + fixed(dx, 1) + " m within " + fixed(kRefinementDepths, 0) +
           " times the thickest release column (" + fixed(max_vertical_m, 2) + " m) need " + std::to_string(want);
  if (r < want)
    reason += "; " + std::to_string(columns) + " columns x " + std::to_string(layers) + " layers x " + std::to_string(want * want) +
              " would exceed " + fixed(kRefinementCellBudget, 0) + " cells, so " + std::to_string(r);
  return r;
}

void build_terrain_setup(const ResolvedScenario& r, TerrainSetup& out) {
  out.grid = terrain::prepare_grid(r.dem, &out.dem);
  out.h0 = terrain::rasterize_releases(out.grid, r.dem, r.releases, &out.release);
  out.output_inputs = read_output_inputs(r, out.grid, out.h0);  // a bad point, line or outline: refused before the run
  // Vertical thickness and the slope's cosine exactly as the depth-averaged engine takes them.
  const engine::Terrain2D t = engine_terrain(out.grid);
  out.vertical = engine::state_from_normal_depth(t, out.h0).H;
  out.cos_slope = engine::SurfaceGeometry::from(t).c;
  out.spec = mesh_spec(r.scenario.mesh(), *std::max_element(out.vertical.begin(), out.vertical.end()));
  out.corridor = build_corridor(r, out.grid, out.h0);
  out.domain_columns = 0;
  long unrefined = 0;  // the corridor's columns inside the domain, one per grid cell
  for (std::size_t c = 0; c < out.grid.cells(); ++c) {
    const bool inside = out.grid.outside.empty() || out.grid.outside[c] == 0;
    out.domain_columns += inside;
    unrefined += inside && (out.corridor.cells.empty() || out.corridor.cells[c] != 0);
  }
  const auto& me = r.scenario.mesh();
  const int asked = me.has_refinement() ? me.refinement() : 1;
  if (asked < 0 || asked > 8) throw terrain::TerrainError("mesh.refinement: must lie in [0, 8], got " + std::to_string(asked));
  out.spec.refinement = choose_refinement(asked, out.grid.dx, *std::max_element(out.vertical.begin(), out.vertical.end()), unrefined,
                                          int(terrain::layer_levels(out.spec).size()) - 1, out.refinement_reason);
  out.domain_columns *= out.spec.refinement * out.spec.refinement;
  out.columns_mesh = terrain::column_mesh(out.grid, out.spec, out.corridor.cells);
  std::vector<terrain::DamRequest> structures;
  for (const auto& st : r.structures) {
    structures.push_back(st.request);
    out.structure_names.push_back(st.name);
  }
  terrain::place_structures(out.columns_mesh, out.grid, structures);
  out.frame = frame_of(out.columns_mesh);
  out.columns = columns_of(out.columns_mesh);
  out.mesh = terrain_mesh(out.columns_mesh, out.frame, out.structure_names);
  out.quality = engine::vof::mesh_quality(out.mesh);
  out.corridor_edge = corridor_edge_faces(out.columns, out.mesh, out.grid);
  if (r.nest_part) {  // the nest's boundary: its own patch, the depth-averaged run's inflow (jobs/drivers/nest/)
    const auto edge = out.corridor_edge;
    engine::vof::split_patch(out.mesh, "sides", "nest", [&](int f) { return edge[std::size_t(f)] != 0; });
    out.corridor_edge = corridor_edge_faces(out.columns, out.mesh, out.grid);
  }
  out.alpha = release_alpha(out.columns_mesh, out.vertical, r.nest_part);
  out.volume_on_mesh = 0;
  for (std::size_t c = 0; c < out.alpha.size(); ++c) out.volume_on_mesh += out.alpha[c] * out.mesh.volume[c];
  const auto& pts = r.scenario.vof().profiles();
  for (int k = 0; k < pts.size(); ++k) {
    const auto& p = pts[k];
    NamedPoint np;
    np.name = p.name();
    np.at = terrain::place_point(out.grid, p.x(), p.y(), p.crs(), "vof.profiles[" + std::to_string(k) + "]");
    np.column = std::size_t(np.at.j) * std::size_t(out.grid.nx) + std::size_t(np.at.i);
    // The refined column holding the point, within its grid cell.
    const int R = out.columns.refinement;
    const double cw = out.columns_mesh.dx;
    const int fi = std::clamp(int(std::floor((np.at.x - out.grid.x_min) / cw)), np.at.i * R, np.at.i * R + R - 1);
    const int fk = std::clamp(int(std::floor((np.at.y - out.grid.y_min) / cw)), np.at.j * R, np.at.j * R + R - 1);
    np.mesh_column = std::size_t(fk) * std::size_t(out.columns.ni) + std::size_t(fi);
    out.points.push_back(np);
  }
}

}  // namespace runout::jobs::vof_terrain
