#include "jobs/drivers/hazard_outputs.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "jobs/figures/map.hpp"

namespace runout::jobs {
namespace fs = std::filesystem;

// The engine's grid: the prepared grid with its local origin at the grid's centre.
engine::Terrain2D engine_terrain(const terrain::Grid& grid) {
  engine::Terrain2D t;
  t.nx = grid.nx;
  t.ny = grid.ny;
  t.dx = t.dy = grid.dx;
  t.x0 = -0.5 * (grid.nx - 1) * grid.dx;
  t.y0 = -0.5 * (grid.ny - 1) * grid.dx;
  t.z = grid.z;
  t.outside = grid.outside;
  return t;
}

// The maximum depth, the affected area and the runout from the release's centroid.
void hazard_figures(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                    RunSummary& sum) {
  double mx = 0, my = 0, m = 0;
  for (int j = 0; j < grid.ny; ++j)
    for (int i = 0; i < grid.nx; ++i) {
      const double v = h0[std::size_t(j) * grid.nx + i];
      m += v;
      mx += v * grid.cx(i);
      my += v * grid.cy(j);
    }
  mx /= m;
  my /= m;
  long affected = 0;
  for (int j = 0; j < grid.ny; ++j)
    for (int i = 0; i < grid.nx; ++i) {
      const std::size_t k = std::size_t(j) * grid.nx + i;
      sum.max_depth = std::max(sum.max_depth, hz.max_depth[k]);
      if (hz.max_depth[k] <= s.outline_threshold) continue;
      ++affected;
      sum.runout_m = std::max(sum.runout_m, std::hypot(grid.cx(i) - mx, grid.cy(j) - my));
    }
  sum.affected_area_m2 = double(affected) * grid.dx * grid.dx;
}

void require_finite_figures(std::initializer_list<std::pair<const char*, double>> figures) {
  // The engines stop a run whose state turns non-finite; this guards what the records would say.
  for (const auto& [name, v] : figures)
    if (!std::isfinite(v))
      throw std::runtime_error(std::string("the run's ") + name + " is not finite (" + json_number(v) +
                               "): the flow state became NaN or infinite; no results written");
}

// The hazard rasters the scenario asks for (hazard_rasters()), the outline and the map; their names
// go to sum.files.
terrain::OutlineReport write_hazard_outputs(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0,
                                            const engine::HazardMaps& hz, const std::string& out_dir, RunSummary& sum) {
  auto out = [&](const std::string& name) { return (fs::path(out_dir) / name).string(); };
  for (const auto& name : s.rasters)
    for (const auto& r : hazard_rasters())
      if (r.name == name) {
        terrain::write_cog(out(name + ".tif"), grid, terrain::masked_outside(grid, hz.*r.map), r.description);
        sum.files.push_back(name + ".tif");
      }
  const auto outline = terrain::write_outline(out("outline.geojson"), out("outline.gpkg"), grid, hz.max_depth, s.outline_threshold);
  if (outline.geojson) sum.files.push_back("outline.geojson");
  else sum.notes.push_back("outline.geojson not written: the grid's CRS is local (no geographic coordinates)");
  sum.files.push_back("outline.gpkg");
  figures::MapRequest mreq;
  mreq.title = s.scenario.name().empty() ? "runout" : s.scenario.name();
  if (mreq.title.size() > 60) mreq.title = mreq.title.substr(0, 57) + "...";
  mreq.outline_threshold = s.outline_threshold;
  mreq.scale = grid.nx * grid.ny > 1000000 ? 1 : 2;
  figures::write_map_png(out("map.png"), grid, hz.max_depth, h0, mreq);
  sum.files.push_back("map.png");
  return outline;
}

void record_inputs(v1::RunRecord& rec, const terrain::DemReport& d, const terrain::Grid& g, const terrain::ReleaseReport& r) {
  auto* dem = rec.mutable_dem();
  dem->set_source_crs(d.source_crs);
  dem->set_source_resolution_m(d.source_resolution_m);
  dem->set_z_min_m(d.z_min);
  dem->set_z_max_m(d.z_max);
  dem->set_slope_mean_deg(d.slope_mean_deg);
  dem->set_slope_p90_deg(d.slope_p90_deg);
  dem->set_slope_max_deg(d.slope_max_deg);
  dem->set_cells_without_data(int(d.cells_without_data));
  dem->set_cells_outside_area(int(d.cells_outside_area));
  auto* gr = rec.mutable_grid();
  gr->set_crs(g.crs_name);
  gr->set_nx(g.nx);
  gr->set_ny(g.ny);
  gr->set_cell_size_m(g.dx);
  gr->set_x_min(g.x_min);
  gr->set_y_min(g.y_min);
  auto* rel = rec.mutable_release();
  rel->set_polygons(r.polygons);
  rel->set_cells(int(r.cells));
  rel->set_area_m2(r.area_m2);
  rel->set_volume_m3(r.volume_m3);
  for (const auto& note : r.notes) rel->add_notes(note);
}

}  // namespace runout::jobs
