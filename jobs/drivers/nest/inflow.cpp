#include "jobs/drivers/nest/inflow.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::nest {

namespace vof = engine::vof;

namespace {

// Per face of the patch: the record's grid face and the face's layer (its owner's).
struct FaceMap {
  int start = 0;
  std::vector<int> grid_face, layer;
};

FaceMap map_faces(const vof_terrain::TerrainSetup& su, const NestBoundary& b) {
  const vof::Mesh& m = su.mesh;
  const vof::Patch& p = m.patch("nest");
  std::map<std::pair<std::size_t, int>, int> by_cell_side;
  for (std::size_t k = 0; k < b.faces().size(); ++k) by_cell_side[{b.faces()[k].inside, b.faces()[k].side}] = int(k);
  std::vector<int> layer_of(std::size_t(m.cells()), -1);
  for (std::size_t col = 0; col < su.columns.columns(); ++col)
    for (int j = 0; j < su.columns.layers; ++j)
      if (const int c = su.columns.cell(col, j); c >= 0) layer_of[std::size_t(c)] = j;
  FaceMap out;
  out.start = p.start;
  const auto& g = su.grid;
  const double w = su.columns_mesh.dx;
  for (int f = p.start; f < p.start + p.size; ++f) {
    const vof::Vec n = (1.0 / m.magSf[std::size_t(f)]) * m.Sf[std::size_t(f)];  // out of the nest; engine frame: x east, z south
    const vof::Vec in = m.Cf[std::size_t(f)] - (0.25 * w) * n;
    const double east = su.frame.east(in), north = su.frame.north(in);
    const int i = int(std::floor((east - g.x_min) / g.dx)), j = int(std::floor((north - g.y_min) / g.dx));
    const int side = std::abs(n.x) > std::abs(n.z) ? (n.x < 0 ? 0 : 1) : (n.z > 0 ? 2 : 3);
    const auto it = by_cell_side.find({std::size_t(j) * std::size_t(g.nx) + std::size_t(i), side});
    if (i < 0 || j < 0 || i >= g.nx || j >= g.ny || it == by_cell_side.end())
      throw ScenarioError("nest: a face of the nest's mesh boundary at (" + std::to_string(east) + ", " + std::to_string(north) +
                          ") lies on no boundary face of the nest's grid cells");
    out.grid_face.push_back(it->second);
    out.layer.push_back(layer_of[std::size_t(m.owner[std::size_t(f)])]);
  }
  return out;
}

}  // namespace

vof::PatchBc nest_inflow(const vof_terrain::TerrainSetup& su, const NestBoundary& b) {
  auto map = std::make_shared<const FaceMap>(map_faces(su, b));
  const std::vector<double> levels = su.columns.levels;
  const double dx = su.grid.dx;
  const vof::Mesh* m = &su.mesh;
  vof::PatchBc bc;
  bc.type = "nest_inflow";
  bc.timed_inflow = [map, levels, dx, m, &b](int f, double t0, double t1, vof::Vec& U, double& alpha) {
    const std::size_t q = std::size_t(f - map->start);
    FaceInflow in;
    if (!b.inflow(std::size_t(map->grid_face[q]), t0, t1, in)) return false;
    const double H = std::clamp(in.depth, 0.01, levels.back());
    const int j = map->layer[q];
    const double lo = levels[std::size_t(j)], hi = levels[std::size_t(j) + 1];
    alpha = std::clamp((H - lo) / (hi - lo), 0.0, 1.0);
    if (!(alpha > 0)) return false;
    const vof::Vec n_in = (-1.0 / m->magSf[std::size_t(f)]) * m->Sf[std::size_t(f)];
    const vof::Vec uh{in.east, 0, -in.north};
    const vof::Vec along = uh - dot(uh, n_in) * n_in;
    U = (in.q / (H * dx)) * n_in + along;
    return true;
  };
  return bc;
}

double nest_max_step(const vof_terrain::TerrainSetup& su, const NestBoundary& b, double co) {
  return co * su.columns_mesh.dx / std::max(1.0, b.max_speed());
}

}  // namespace runout::jobs::nest
