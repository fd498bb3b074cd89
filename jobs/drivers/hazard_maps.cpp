#include "jobs/drivers/hazard_maps.hpp"

#include "jobs/drivers/engine_run.hpp"

#include "jobs/drivers/hazard_outputs.hpp"

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "engine/vof/bc/conditions.hpp"
#include "engine/vof/models/registry.hpp"
#include "jobs/figures/hazard_map.hpp"
#include "jobs/figures/pen.hpp"
#include "jobs/figures/profile_plot.hpp"
#include "jobs/formats/run_record.hpp"
#include "terrain/points.hpp"

namespace runout::jobs {
namespace fs = std::filesystem;

namespace {

std::string num(double v) { return figures::label_number(v); }

std::string scenario_name(const ResolvedScenario& s) { return s.scenario.name().empty() ? "runout" : s.scenario.name(); }

// The structures' 3D loads (a 3D run's, or a nest's) on every map: a line each in the parameter block
// and the highest pressure at the structure, with the loads' verdict (vof_terrain::loads_verdict).
std::string sig3(double v) {  // three significant digits: the loads are no more precise
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

void add_structure_loads(const RunSummary& sum, figures::HazardMap& m) {
  std::vector<const StructureSummary*> with;
  for (const auto& q : sum.structures)
    if (q.loads) with.push_back(&q);
  if (sum.nest)
    for (const auto& q : sum.nest->structures)
      if (q.loads) with.push_back(&q);
  for (const auto* q : with) {
    const std::string verdict = q->loads_resolved ? "" : " (not design values: under-resolved, run.json structures[].loads_note)";
    m.parameters.push_back("3D loads on " + q->name + ": peak force " + sig3(q->peak_force_kn) + " kN, highest pressure " +
                           sig3(q->max_pressure_kpa) + " kPa" + verdict);
    m.points.push_back({structure_load_label(q->name, q->max_pressure_kpa, q->loads_resolved), q->x, q->y});
  }
}

// What every map of a run shows besides its quantity: release, outline, points, parameters.
figures::HazardMap map_base(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                            const MapOverlay& overlay, const RunSummary& sum) {
  figures::HazardMap base;
  base.release = h0;
  base.resistance = overlay.resistance;
  base.cover = overlay.cover;
  base.dams = overlay.dams;
  base.structures = overlay.structures;
  base.nest = overlay.nest;
  base.max_depth = hz.max_depth;
  base.outline_threshold = s.outline_threshold;
  base.parameters = map_parameters(s, grid, sum.release_volume_m3);
  for (const auto& n : sum.notes) base.parameters.push_back("note: " + n);  // run.json's notes, on every map
  for (const auto& p : overlay.points) base.points.push_back({p.name, p.x, p.y});
  add_structure_loads(sum, base);
  base.path = overlay.path;
  base.path_marks = overlay.path_marks;
  return base;
}

void draw_map(const terrain::Grid& grid, const std::string& stem, const figures::HazardMap& m, const std::string& out_dir, RunSummary& sum) {
  figures::draw_hazard_map((fs::path(out_dir) / (stem + ".png")).string(), (fs::path(out_dir) / (stem + ".pdf")).string(), grid, m);
  sum.files.push_back(stem + ".png");
  sum.files.push_back(stem + ".pdf");
}

// The points of interest on the grid.
std::vector<PlacedPoint> place_points_of_interest(const ResolvedScenario& s, const terrain::Grid& grid) {
  std::vector<PlacedPoint> out;
  const auto& pts = s.scenario.outputs().points_of_interest();
  for (int k = 0; k < pts.size(); ++k) {
    const auto at = terrain::place_point(grid, pts[k].x(), pts[k].y(), pts[k].crs(), "outputs.points_of_interest[" + std::to_string(k) + "]");
    out.push_back({pts[k].name(), at.x, at.y, std::size_t(at.j) * std::size_t(grid.nx) + std::size_t(at.i)});
  }
  return out;
}

}  // namespace

OutputInputs read_output_inputs(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0) {
  OutputInputs in;
  in.points = place_points_of_interest(s, grid);
  if (!s.path.line_path.empty()) {
    in.path = terrain::read_line(grid, s.path.line_path, s.path.crs, "path.line_path");
    in.path_source = s.path.line_path;
  } else {  // until the run gives the flow's own path (use_flow_path)
    const auto [mx, my] = release_centroid(grid, h0);
    if (std::isfinite(mx)) in.path = products::steepest_descent(grid, mx, my);
    in.path_source = "steepest descent from the release's centroid";
  }
  if (!s.observed_outline.empty()) {
    in.observed = terrain::rasterize_polygons(grid, s.observed_outline, s.observed_crs, "observations.outline_path");
    if (std::find(in.observed.begin(), in.observed.end(), 1) == in.observed.end())
      throw terrain::TerrainError("observations.outline_path: '" + s.observed_outline + "' covers no cell of the domain");
  }
  for (std::size_t a = 0; a < s.resistance.size(); ++a) {  // each area must lie on the domain
    const std::string field = "resistance.areas[" + std::to_string(a) + "].path";
    const auto cells = terrain::rasterize_polygons(grid, s.resistance[a].path, s.resistance[a].crs, field);
    if (std::find(cells.begin(), cells.end(), 1) == cells.end())
      throw terrain::TerrainError(field + ": '" + s.resistance[a].path + "' covers no cell of the domain");
    in.resistance_areas.push_back(cells);
  }
  // Each area of cover, read with the releases' rules (an area on no cell of the domain is refused,
  // naming its field).
  for (const auto& c : s.cover) in.cover_areas.push_back(terrain::rasterize_releases(grid, s.dem, {c.release}));
  for (const auto& d : s.dams) in.dams.push_back(terrain::rasterize_dam(grid, d.request));
  for (const auto& d : s.structures) in.structures.push_back(terrain::rasterize_dam(grid, d.request));
  return in;
}

void use_flow_path(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const std::vector<double>& max_depth,
                   const std::vector<std::array<double, 3>>& centres, OutputInputs& in) {
  if (!s.path.line_path.empty()) return;  // the user's line stands
  std::vector<products::TrackPoint> track;
  for (const auto& c : centres)
    if (std::isfinite(c[1]) && std::isfinite(c[2])) track.push_back({c[0], c[1], c[2]});
  // The path must reach the flow's farthest point: the mass centre's path where its cross-sections
  // take that point in (a flow that stayed together), else the longest flow line (a flow that split,
  // or whose mass centre left the outline, has its farthest reach off the mass centre's path).
  std::pair<double, double> far{NAN, NAN};
  auto longest = products::longest_flow_line(grid, h0, max_depth, s.outline_threshold, &far);
  auto centre = products::track_inside_outline(grid, track, max_depth, s.outline_threshold) ? products::flow_path(grid, track, h0)
                                                                                            : products::Line{};
  char b[300];
  if (centre.size() >= 2 && (longest.empty() || products::distance_to_line(centre, far.first, far.second) <= 0.5 * s.path.width_m)) {
    in.path = std::move(centre);
    std::snprintf(b, sizeof b, "the flow's mass centre (%zu frames to t = %g s), extended to the release's top and to the domain's edge",
                  track.size(), track.back().t);
  } else if (longest.size() >= 2) {
    in.path = std::move(longest);
    std::snprintf(b, sizeof b,
                  "the longest flow line through the outline from the release's top to its farthest cell (%.0f, %.0f), extended to the "
                  "domain's edge (the mass centre's path does not reach that cell)",
                  far.first, far.second);
  } else {
    return;
  }
  in.path_source = b;
}

void write_path_outputs(const ResolvedScenario& s, const products::PathProfile& p, const std::string& out_dir, RunSummary& sum) {
  products::write_profile_csv((fs::path(out_dir) / "path_profile.csv").string(), p);
  figures::ProfilePlot plot;
  plot.title = scenario_name(s) + ": profiles along the path";
  plot.s = p.s;
  plot.z = p.z;
  plot.series = {{"max depth [m]", p.depth}, {"max speed [m/s]", p.speed}, {"max pressure [kPa]", p.pressure_kpa}};
  char note[200];
  if (p.runout) {
    plot.runout_s = p.s[*p.runout];
    plot.alpha_deg = p.alpha_deg;
    std::snprintf(note, sizeof note, "runout point at %.0f m (%s), alpha %.1f°; the largest of each cross-section %.0f m wide",
                  plot.runout_s, p.criterion.c_str(), p.alpha_deg, s.path.width_m);
  } else {
    std::snprintf(note, sizeof note, "no cross-section reaches %s", p.criterion.c_str());
  }
  plot.note = note;
  if (p.beta) plot.beta_s = p.s[*p.beta];
  sum.files.push_back("path_profile.csv");
  if (!s.maps) return;
  figures::draw_profile_plot((fs::path(out_dir) / "map_path_profile.png").string(), (fs::path(out_dir) / "map_path_profile.pdf").string(), plot);
  for (const char* f : {"map_path_profile.png", "map_path_profile.pdf"}) sum.files.push_back(f);
}

namespace {

// A line of the parameter block, "what: caption, label = value unit, ...", with the material's
// values read by their field names.
class ParameterLine {
 public:
  ParameterLine(std::string_view what, std::string_view caption, const v1::Material& m)
      : line_(std::string(what) + ": " + std::string(caption)), m_(m) {}
  void add(std::string_view label, std::string_view unit, double v) {
    const std::string u(unit == "deg" ? "°" : unit == "kg/m3" ? "kg/m³" : unit);
    line_ += ", " + std::string(label) + " = " + num(v) + (u.empty() ? "" : u.rfind("°", 0) == 0 ? u : " " + u);
  }
  /// The field's value in `v`; false when it is unset (or not a number).
  bool value(std::string_view field, double& v) const {
    const auto* f = m_.GetDescriptor()->FindFieldByName(std::string(field));
    if (!f || f->cpp_type() != google::protobuf::FieldDescriptor::CPPTYPE_DOUBLE) return false;
    v = m_.GetReflection()->GetDouble(m_, f);
    return !f->has_presence() || m_.GetReflection()->HasField(m_, f);
  }
  const std::string& text() const { return line_; }

 private:
  std::string line_;
  const v1::Material& m_;
};

// The friction law's line of the parameter block, from the law's own rows (engine/friction): its
// caption and each parameter the scenario sets, with the internal friction angle where given.
std::string friction_line(const engine::FrictionLaw& law, const v1::Material& m) {
  ParameterLine line("friction", law.caption, m);
  for (const auto& p : law.parameters) {
    if (p.field.empty()) break;
    double v = 0;
    if (!line.value(p.field, v)) {  // unset: what the row says it means, another parameter's value or a number
      const std::string_view means = p.unset.substr(0, p.unset.find(','));
      const auto other = std::find_if(law.parameters.begin(), law.parameters.end(), [&](const auto& q) { return q.symbol == means; });
      char* end = nullptr;
      const std::string text(means);
      if (other != law.parameters.end() && !other->field.empty()) (void)line.value(other->field, v);
      else if (v = std::strtod(text.c_str(), &end); text.empty() || *end != '\0') continue;
    }
    line.add(p.label, p.unit, v);
  }
  double phi = 0;
  if (line.value("internal_friction_deg", phi)) line.add("φ", "°", phi);
  return line.text();
}

// The 3D engine's granular viscosity and bed, from their rows (engine/vof/models, engine/vof/bc):
// the model's caption and each parameter's value in the material; the bed's condition and, where
// it takes one, its friction angle.
std::vector<std::string> viscosity_lines(const v1::Material& m, const std::string& bed_name) {
  const auto* model = engine::vof::find_granular_viscosity(m.rheology());
  std::string type = bed_name;
  std::replace(type.begin(), type.end(), '-', '_');
  const auto* bc = engine::vof::find_boundary_condition(type);
  if (!model || !bc) return {};
  ParameterLine line("granular viscosity", model->caption, m);
  for (const auto& p : model->parameters) {
    double v = 0;
    if (!p.field.empty() && line.value(p.material_name(), v)) line.add(p.label, p.unit, v);
  }
  ParameterLine bed("bed", bc->caption, m);
  double delta = 0;
  if (bc->bed_friction && bed.value("bed_friction_deg", delta)) bed.add("δ", "°", delta);
  return {line.text(), bed.text()};
}

// "v" where every item's get(item) is v, else "lo–hi" (items not empty).
template <class Items, class Get>
std::string value_range(const Items& items, Get get) {
  double lo = get(items.front()), hi = lo;
  for (const auto& a : items) {
    lo = std::min(lo, get(a));
    hi = std::max(hi, get(a));
  }
  return lo == hi ? num(lo) : num(lo) + "–" + num(hi);
}

// The resistance areas on the maps: how many, their drag coefficient and detrainment (the range where
// areas differ), and the band, or "drag everywhere" without detrainment.
std::string resistance_line(const ResolvedScenario& s) {
  auto range = [&](auto get) { return value_range(s.resistance, get); };
  const auto& b = s.config.resistance;
  std::string line = "resistance: " + std::to_string(s.resistance.size()) + (s.resistance.size() == 1 ? " area" : " areas") +
                     ", c = " + range([](const ResistanceAreaSettings& a) { return a.c; });
  if (!b.detrainment) return line + ", drag everywhere, no detrainment";
  return line + ", K = " + range([](const ResistanceAreaSettings& a) { return a.k_det; }) + " Pa, drag at " + num(b.depth_min) + "–" +
         num(b.depth_max) + " m and " + num(b.speed_min) + "–" + num(b.speed_max) + " m/s";
}

// The erodible cover on the maps: how many areas, the law (with e_b) and the cover's density.
std::string cover_line(const ResolvedScenario& s) {
  const auto& e = s.config.cover;
  return "entrainment: " + std::to_string(s.cover.size()) + (s.cover.size() == 1 ? " area" : " areas") +
         (e.ploughing ? ", ploughing" : ", erosion e_b = " + num(e.erosion_energy) + " J/kg") + ", cover " +
         value_range(s.cover, [](const CoverAreaSettings& a) { return a.density; }) + " kg/m³";
}

}  // namespace

std::string structure_load_label(const std::string& name, double max_pressure_kpa, bool resolved) {
  return name + ": " + sig3(max_pressure_kpa) + " kPa" + (resolved ? "" : ", not resolved");
}

std::vector<std::string> map_parameters(const ResolvedScenario& s, const terrain::Grid& grid, double release_volume_m3) {
  const auto& m = s.scenario.material();
  std::vector<std::string> p;
  p.push_back("engine: " + std::string(engine_row(s.engine).caption));
  if (s.engine == kVofTerrainEngine)
    for (auto& line : viscosity_lines(m, s.scenario.vof().bed())) p.push_back(std::move(line));
  else
    p.push_back(friction_line(*s.config.material.rheology, m));
  p.push_back("density: " + num(m.density_kg_m3()) + " kg/m³");
  if (!s.resistance.empty()) p.push_back(resistance_line(s));
  if (!s.cover.empty()) p.push_back(cover_line(s));
  for (const auto& d : s.dams)
    p.push_back("dam: " + d.name + (d.request.has_height ? ", " + num(d.request.height) + " m high" : ", height from '" + d.request.height_attribute + "'"));
  for (const auto& d : s.structures)
    p.push_back("structure: " + d.name +
                (d.request.has_height                   ? ", " + num(d.request.height) + " m high"
                 : !d.request.top_attribute.empty()  ? ", top from '" + d.request.top_attribute + "'"
                 : !d.request.surface_path.empty()   ? ", top from the surface model '" + fs::path(d.request.surface_path).filename().string() + "'"
                                                     : ", height from '" + d.request.height_attribute + "'"));
  p.push_back("release: " + num(std::round(release_volume_m3)) + " m³ in " + std::to_string(s.releases.size()) +
              (s.releases.size() == 1 ? " release" : " releases"));
  for (auto& line : map_footer(grid)) p.push_back(std::move(line));
  return p;
}

std::vector<std::string> map_footer(const terrain::Grid& grid) {
  const auto sw = this_software();
  return {"grid: " + num(grid.dx) + " m, " + std::to_string(grid.nx) + " × " + std::to_string(grid.ny) + " cells, " + grid.crs_name,
          "software: runout " + sw.version() + " (" + sw.git_commit().substr(0, 10) + ")"};
}

void write_hazard_maps(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                       const std::vector<std::vector<double>>& values, const products::ZoneMap& zones, const MapOverlay& overlay,
                       const std::string& out_dir, RunSummary& sum) {
  const std::string name = scenario_name(s);
  const figures::HazardMap base = map_base(s, grid, h0, hz, overlay, sum);
  auto draw = [&](const std::string& quantity, figures::HazardMap m) { draw_map(grid, "map_" + quantity, m, out_dir, sum); };
  for (std::size_t q = 0; q < hazard_rasters().size(); ++q) {
    const auto& r = hazard_rasters()[q];
    figures::HazardMap m = base;
    m.palette = figures::hazard_palette(r.name);
    m.title = name + ": " + m.palette.title;
    // Every quantity only where the flow is mapped (inside the outline): speed, pressure and arrival
    // time reach out to the flow threshold, where a film of a centimetre would colour the map.
    m.values = figures::inside_outline(values[q], hz.max_depth, s.outline_threshold);
    m.colour_note = "coloured inside the outline only (max depth > " + num(s.outline_threshold) + " m)";
    m.show_maximum = true;
    if (r.name == "max_pressure") m.boundaries.push_back({zones.cls, zones.palette});
    draw(r.name, std::move(m));
  }
  figures::HazardMap z = base;
  z.palette = zones.palette;
  z.title = name + ": pressure zones";
  z.values.assign(zones.cls.begin(), zones.cls.end());
  // The zone map colours class k + 1 with zone k: its palette's bounds become the class numbers.
  for (std::size_t k = 0; k < z.palette.classes.size(); ++k) z.palette.classes[k].from = double(k + 1);
  z.palette.title = "pressure zones (max pressure where max depth > " + num(s.outline_threshold) + " m)";
  draw("pressure_zones", std::move(z));
}

void write_score_map(const ResolvedScenario& s, const terrain::Grid& grid, const std::vector<double>& h0, const engine::HazardMaps& hz,
                     const products::OutlineScores& scores, const MapOverlay& overlay, const std::string& out_dir, RunSummary& sum) {
  figures::HazardMap m = map_base(s, grid, h0, hz, overlay, sum);
  m.palette = products::score_palette();
  m.title = scenario_name(s) + ": simulated against the observed outline";
  m.values.assign(scores.cls.begin(), scores.cls.end());
  char b[160];
  std::snprintf(b, sizeof b, "critical success index %.2f; ROC point: false positive rate %.3f, true positive rate %.2f", scores.csi,
                scores.fpr, scores.tpr);
  m.parameters.insert(m.parameters.begin(), b);
  std::snprintf(b, sizeof b, "observed %.0f m², simulated %.0f m², hits %.0f m²", scores.observed_m2, scores.simulated_m2, scores.tp_m2);
  m.parameters.insert(m.parameters.begin() + 1, b);
  draw_map(grid, "map_observation", m, out_dir, sum);
}

std::vector<v1::PointReport> point_reports(const std::vector<PlacedPoint>& points, const engine::HazardMaps& hz,
                                           const std::vector<double>& pressure_kpa, const products::ZoneMap& zones, double outline_threshold) {
  std::vector<v1::PointReport> out;
  for (const auto& p : points) {
    auto* r = &out.emplace_back();
    r->set_name(p.name);
    r->set_x(p.x);
    r->set_y(p.y);
    r->set_max_depth_m(hz.max_depth[p.cell]);
    r->set_max_speed_m_s(hz.max_speed[p.cell]);
    r->set_max_pressure_kpa(pressure_kpa[p.cell]);
    const int z = zones.cls[p.cell];
    r->set_zone(z > 0 ? zones.classes[std::size_t(z) - 1].name : "");
    if (std::isfinite(hz.arrival_time[p.cell])) r->set_arrival_time_s(hz.arrival_time[p.cell]);
    r->set_inside_outline(hz.max_depth[p.cell] > outline_threshold);
  }
  return out;
}

}  // namespace runout::jobs
