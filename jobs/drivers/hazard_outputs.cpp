#include "jobs/drivers/hazard_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "jobs/drivers/hazard_maps.hpp"
#include "jobs/figures/qml.hpp"
#include "jobs/products/zones.hpp"

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

std::pair<double, double> release_centroid(const terrain::Grid& grid, const std::vector<double>& h0) {
  double mx = 0, my = 0, m = 0;
  for (int j = 0; j < grid.ny; ++j)
    for (int i = 0; i < grid.nx; ++i) {
      const double v = h0[std::size_t(j) * grid.nx + i];
      m += v;
      mx += v * grid.cx(i);
      my += v * grid.cy(j);
    }
  return {mx / m, my / m};
}

// The maximum depth, the affected area and the runout from the release's centroid.
void hazard_figures(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                    RunSummary& sum) {
  if (s.engine == kDepthAveragedEngine)  // the depth-averaged engine's limit (the 3D engine reports its mesh's quality)
    if (const auto steep = steep_terrain_note(s, grid, h0, hz); !steep.empty()) sum.notes.push_back(steep);
  const auto [mx, my] = release_centroid(grid, h0);
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

std::string steep_terrain_note(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz) {
  const auto slope = terrain::slope_deg(grid);
  long released = 0, reached = 0;
  double steepest = 0;
  for (std::size_t k = 0; k < slope.size(); ++k) {
    if (!(slope[k] > kSteepSlopeDeg) || (!grid.outside.empty() && grid.outside[k])) continue;
    const bool rel = h0[k] > 0, flow = hz.max_depth[k] > s.outline_threshold;
    released += rel;
    reached += flow && !rel;
    if (rel || flow) steepest = std::max(steepest, slope[k]);
  }
  if (released + reached == 0) return "";
  char b[200];
  std::snprintf(b, sizeof b,
                "near-vertical terrain: %ld cell(s) of the release and %ld further cell(s) of the flow are steeper than %.0f deg "
                "(steepest %.1f deg)",
                released, reached, kSteepSlopeDeg, steepest);
  return std::string(b) +
         ": the depth-averaged model holds h / cos(slope) of a vertical column there (twice the thickness at 60 deg, six times at "
         "80 deg), so depth, speed and pressure on and just below these cells are not reliable; check them against the DEM (a "
         "cliff, or an artefact) before using the maps there";
}

namespace {

// The zones' names in class order (the polygons' `name` field).
std::vector<std::string> zone_names(const products::ZoneMap& z) {
  std::vector<std::string> names;
  for (const auto& c : z.classes) names.push_back(c.name);
  return names;
}

std::string affected_area_criterion(double outline_threshold) { return "max depth > " + json_number(outline_threshold) + " m"; }

// The pressure zones: the class raster with its QGIS style, and the polygons.
void write_zones(const terrain::Grid& grid, const products::ZoneMap& z, const std::string& out_dir,
                 RunSummary& sum, HazardOutputs& out) {
  auto path = [&](const std::string& name) { return (fs::path(out_dir) / name).string(); };
  terrain::write_class_cog(path("pressure_zones.tif"), grid, z.cls, z.classes,
                           {"pressure hazard zones by the maximum pressure rho u^2 (0: none)", ""});
  figures::write_qml_classes(path("pressure_zones.qml"), z.palette);
  out.zone_areas = terrain::write_class_polygons(path("pressure_zones.geojson"), path("pressure_zones.gpkg"), "pressure_zones", grid,
                                                 z.cls, z.classes, "kpa");
  // The polygons' style: in the GeoPackage (QGIS's default) and as a file of its own (the raster's
  // pressure_zones.qml would otherwise be taken for the GeoJSON's).
  const std::string style = figures::qml_polygon_classes(z.palette, zone_names(z));
  terrain::add_layer_style(path("pressure_zones.gpkg"), "pressure_zones", "runout pressure zones", style);
  figures::write_qml(path("pressure_zones_polygons.qml"), style);
  // GeoTIFF keeps the zones' names (GDAL's category names) in its sidecar.
  for (const char* f : {"pressure_zones.tif", "pressure_zones.tif.aux.xml", "pressure_zones.qml", "pressure_zones_polygons.qml"})
    if (fs::exists(path(f))) sum.files.push_back(f);
  if (out.outline.geojson) sum.files.push_back("pressure_zones.geojson");
  sum.files.push_back("pressure_zones.gpkg");
}

}  // namespace

HazardOutputs write_hazard_outputs(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0,
                                   const engine::HazardMaps& hz, const OutputInputs& in, const std::string& out_dir, RunSummary& sum) {
  auto out = [&](const std::string& name) { return (fs::path(out_dir) / name).string(); };
  HazardOutputs res;
  // Every hazard raster in its unit, once: for the files, the maps, the path and the points.
  std::vector<std::vector<double>> values;
  for (const auto& r : hazard_rasters()) {
    auto& v = values.emplace_back(terrain::masked_outside(grid, hz.*r.map));
    for (double& x : v) x *= r.scale;
    if (std::find(s.rasters.begin(), s.rasters.end(), r.name) == s.rasters.end()) continue;
    terrain::write_cog(out(r.name + ".tif"), grid, v, {r.description, r.unit});
    figures::write_qml_ramp(out(r.name + ".qml"), figures::hazard_palette(r.name));
    sum.files.push_back(r.name + ".tif");
    sum.files.push_back(r.name + ".qml");
  }
  // The ground and the release on the run's grid, for GIS and for `runout report`.
  terrain::write_cog(out("elevation.tif"), grid, terrain::masked_outside(grid, grid.z), {"ground elevation on the run's grid", "m"});
  terrain::write_cog(out("release.tif"), grid, terrain::masked_outside(grid, h0), {"release thickness (0: not released)", "m"});
  for (const char* f : {"elevation.tif", "release.tif"}) sum.files.push_back(f);
  res.parameters = map_parameters(s, grid, sum.release_volume_m3);
  auto raster = [&](const std::string& name) -> const std::vector<double>& {
    const auto& all = hazard_rasters();
    return values[std::size_t(std::find_if(all.begin(), all.end(), [&](const HazardRaster& r) { return r.name == name; }) - all.begin())];
  };
  const auto& pressure_kpa = raster("max_pressure");
  for (double v : pressure_kpa)
    if (std::isfinite(v)) res.max_pressure_kpa = std::max(res.max_pressure_kpa, v);
  // The path analysis reads the maps as written (the pressure before the zones' outline mask).
  MapOverlay overlay;
  overlay.points = in.points;
  overlay.path = in.path;
  for (const auto& cells : in.resistance_areas) {  // the cells of any area
    overlay.resistance.resize(cells.size(), 0);
    for (std::size_t k = 0; k < cells.size(); ++k) overlay.resistance[k] |= cells[k];
  }
  for (const auto& dam : in.dams) {  // the cells of any dam
    overlay.dams.resize(dam.height.size(), 0);
    for (std::size_t k = 0; k < dam.height.size(); ++k) overlay.dams[k] |= dam.height[k] > 0;
  }
  overlay.nest = in.nest;
  for (const auto& st : in.structures) {  // the cells of any structure
    overlay.structures.resize(st.height.size(), 0);
    for (std::size_t k = 0; k < st.height.size(); ++k) overlay.structures[k] |= st.height[k] > 0;
  }
  for (const auto& d : in.cover_areas) {  // the cells of any area of cover
    overlay.cover.resize(d.size(), 0);
    for (std::size_t k = 0; k < d.size(); ++k) overlay.cover[k] |= d[k] > 0;
  }
  res.path_source = in.path_source;
  if (overlay.path.size() >= 2) {
    res.path = products::analyse_path(grid, overlay.path, {raster("max_depth"), raster("max_speed"), pressure_kpa, h0}, s.path);
    if (res.path->runout) sum.path_runout_m = res.path->s[*res.path->runout];
    sum.path_criterion = res.path->criterion;
    write_path_outputs(s, *res.path, out_dir, sum);
    if (res.path->runout) overlay.path_marks.push_back({"runout", res.path->x[*res.path->runout], res.path->y[*res.path->runout]});
    if (res.path->beta) overlay.path_marks.push_back({"β", res.path->x[*res.path->beta], res.path->y[*res.path->beta]});
  } else {
    sum.notes.push_back("no path analysis: the path has no length on the grid");
  }
  res.outline = terrain::write_outline(out("outline.geojson"), out("outline.gpkg"), grid, hz.max_depth, s.outline_threshold);
  terrain::add_layer_style(out("outline.gpkg"), "runout_outline", "runout outline", figures::qml_outline());
  figures::write_qml(out("outline.qml"), figures::qml_outline());
  sum.files.push_back("outline.qml");
  if (res.outline.geojson) sum.files.push_back("outline.geojson");
  else sum.notes.push_back("outline.geojson and pressure_zones.geojson not written: the grid's CRS is local (no geographic coordinates)");
  sum.files.push_back("outline.gpkg");
  // The zones inside the outline: a fringe thinner than the outline's depth exerts no pressure that
  // a zone should stand for, and a zone outside the outline would contradict it.
  std::vector<double> zone_pressure = pressure_kpa;
  for (std::size_t k = 0; k < zone_pressure.size(); ++k)
    if (!(hz.max_depth[k] > s.outline_threshold)) zone_pressure[k] = NAN;
  const auto zones = products::pressure_zones(s.pressure_zones, zone_pressure);
  write_zones(grid, zones, out_dir, sum, res);
  res.points = point_reports(in.points, hz, pressure_kpa, zones, s.outline_threshold);
  if (s.maps) write_hazard_maps(s, grid, h0, hz, values, zones, overlay, out_dir, sum);
  if (!in.observed.empty()) {
    std::vector<std::uint8_t> simulated(grid.cells());
    for (std::size_t k = 0; k < simulated.size(); ++k) simulated[k] = hz.max_depth[k] > s.outline_threshold;
    res.scores = products::outline_scores(grid, simulated, in.observed);
    if (s.maps) write_score_map(s, grid, h0, hz, *res.scores, overlay, out_dir, sum);
  }
  return res;
}

void record_hazard_results(const ResolvedScenario& s, const RunSummary& sum, const HazardOutputs& out, v1::ResultsReport& re) {
  re.set_affected_area_m2(sum.affected_area_m2);
  re.set_affected_area_criterion(affected_area_criterion(s.outline_threshold));
  re.set_outline_polygons(out.outline.polygons);
  re.set_outline_area_m2(out.outline.area_m2);
  re.set_runout_from_release_centroid_m(sum.runout_m);
  re.set_max_depth_m(sum.max_depth);
  re.set_outline_threshold_m(s.outline_threshold);
  re.set_max_pressure_kpa(out.max_pressure_kpa);
  re.set_pressure_zones_criterion("max pressure rho u^2 where " + affected_area_criterion(s.outline_threshold));
  const auto& zones = s.pressure_zones;
  for (std::size_t k = 0; k < zones.size(); ++k) {
    auto* z = re.add_pressure_zones();
    z->set_name(zones[k].name);
    z->set_from_kpa(zones[k].from_kpa);
    if (k + 1 < zones.size()) z->set_to_kpa(zones[k + 1].from_kpa);
    z->set_polygons(out.zone_areas[k].polygons);
    z->set_area_m2(out.zone_areas[k].area_m2);
  }
  for (const auto& p : out.points) *re.add_points_of_interest() = p;
  if (out.path) {
    const auto& p = *out.path;
    auto* pr = re.mutable_path();
    pr->set_source(out.path_source);
    pr->set_criterion(p.criterion);
    pr->set_length_m(p.length);
    pr->set_section_spacing_m(p.spacing);
    if (p.runout) {
      pr->set_runout_s_m(p.s[*p.runout]);
      for (double v : {p.x[*p.runout], p.y[*p.runout], p.z[*p.runout]}) pr->add_runout_xyz(v);
      pr->set_alpha_deg(p.alpha_deg);
    }
    if (p.beta) {
      pr->set_beta_s_m(p.s[*p.beta]);
      for (double v : {p.x[*p.beta], p.y[*p.beta], p.z[*p.beta]}) pr->add_beta_xyz(v);
    }
    pr->set_runout_zone_area_m2(p.runout_zone_area_m2);
  }
  if (out.scores) {
    auto* sc = re.mutable_observation_scores();
    const auto& o = *out.scores;
    sc->set_criterion(affected_area_criterion(s.outline_threshold));
    sc->set_observed_area_m2(o.observed_m2);
    sc->set_simulated_area_m2(o.simulated_m2);
    sc->set_true_positive_m2(o.tp_m2);
    sc->set_false_positive_m2(o.fp_m2);
    sc->set_false_negative_m2(o.fn_m2);
    sc->set_true_negative_m2(o.tn_m2);
    sc->set_critical_success_index(o.csi);
    sc->set_true_positive_rate(o.tpr);
    sc->set_false_positive_rate(o.fpr);
  }
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
  *rec.mutable_grid() = grid_report(g);
  auto* rel = rec.mutable_release();
  rel->set_polygons(r.polygons);
  rel->set_cells(int(r.cells));
  rel->set_area_m2(r.area_m2);
  rel->set_volume_m3(r.volume_m3);
  for (const auto& note : r.notes) rel->add_notes(note);
}

v1::GridReport grid_report(const terrain::Grid& g) {
  v1::GridReport gr;
  gr.set_crs(g.crs_name);
  gr.set_nx(g.nx);
  gr.set_ny(g.ny);
  gr.set_cell_size_m(g.dx);
  gr.set_x_min(g.x_min);
  gr.set_y_min(g.y_min);
  return gr;
}

std::vector<StructureSummary> structure_summaries(const ResolvedScenario& s, const terrain::Grid& grid,
                                                  const std::vector<terrain::DamCells>& cells, const engine::HazardMaps& hz) {
  std::vector<StructureSummary> out;
  for (std::size_t a = 0; a < cells.size() && a < s.structures.size(); ++a) {
    const auto& h = cells[a].height;
    StructureSummary q;
    long n = 0;
    q.name = s.structures[a].name;
    q.cells = cells[a].cells;
    auto on = [&](int i, int j) { return i >= 0 && j >= 0 && i < grid.nx && j < grid.ny && h[std::size_t(j) * grid.nx + i] > 0; };
    for (int j = 0; j < grid.ny; ++j)
      for (int i = 0; i < grid.nx; ++i) {
        const std::size_t k = std::size_t(j) * grid.nx + i;
        if (on(i, j)) {
          q.height_max_m = std::max(q.height_max_m, h[k]);
          q.x += grid.x_min + (i + 0.5) * grid.dx, q.y += grid.y_min + (j + 0.5) * grid.dx, ++n;
          continue;
        }
        if (!(on(i - 1, j) || on(i + 1, j) || on(i, j - 1) || on(i, j + 1))) continue;
        q.max_depth_next_m = std::max(q.max_depth_next_m, hz.max_depth[k]);
        if (!hz.max_pressure.empty()) q.max_pressure_next_kpa = std::max(q.max_pressure_next_kpa, hz.max_pressure[k] / 1000);
      }
    if (n > 0) q.x /= double(n), q.y /= double(n);
    out.push_back(q);
  }
  return out;
}

void record_structure(const StructureSummary& q, v1::StructureResult* r) {
  r->set_name(q.name);
  r->set_x(q.x);
  r->set_y(q.y);
  r->set_cells(int(q.cells));
  r->set_height_max_m(q.height_max_m);
  r->set_max_depth_next_m(q.max_depth_next_m);
  r->set_max_pressure_next_kpa(q.max_pressure_next_kpa);
  if (!q.loads) return;
  r->set_loads_resolved(q.loads_resolved);
  r->set_loads_note(q.loads_note);
  r->set_column_width_m(q.column_width_m);
  r->set_peak_force_kn(q.peak_force_kn);
  r->set_peak_force_time_s(q.peak_force_time_s);
  r->set_peak_force_east_kn(q.peak_force_east_kn);
  r->set_peak_force_north_kn(q.peak_force_north_kn);
  r->set_peak_force_up_kn(q.peak_force_up_kn);
  r->set_impulse_kn_s(q.impulse_kn_s);
  r->set_max_pressure_kpa(q.max_pressure_kpa);
  r->set_max_pressure_time_s(q.max_pressure_time_s);
  r->set_max_pressure_height_m(q.max_pressure_height_m);
  r->set_wall_area_m2(q.wall_area_m2);
  for (double v : q.front_height_m) r->add_front_profile_height_m(v);
  for (double v : q.front_alpha) r->add_front_profile_alpha(v);
  for (double v : q.front_speed_m_s) r->add_front_profile_speed_m_s(v);
}

void record_structures(const RunSummary& sum, v1::RunRecord& rec) {
  for (const auto& q : sum.structures) record_structure(q, rec.add_structures());
}

}  // namespace runout::jobs
