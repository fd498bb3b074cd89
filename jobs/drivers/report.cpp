#include "jobs/drivers/report.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "jobs/drivers/hazard_maps.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/figures/palette.hpp"
#include "jobs/figures/pen.hpp"
#include "jobs/formats/run_record.hpp"
#include "jobs/products/zones.hpp"

namespace runout::jobs {
namespace fs = std::filesystem;

namespace {

std::string num(double v, int digits = 4) {
  if (!std::isfinite(v)) return "–";
  char b[48];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return figures::label_number(std::stod(b), std::fabs(v) >= 10000);
}

std::string today_utc() {
  const std::time_t t = std::time(nullptr);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%d", std::gmtime(&t));
  return b;
}

// A raster of the run on its grid; the error names the file.
std::vector<double> raster(const fs::path& dir, const std::string& name, const terrain::Grid& g) {
  const auto p = dir / name;
  if (!fs::exists(p)) throw std::runtime_error("report: " + p.string() + " is missing (the report reads the run's own files)");
  return terrain::read_raster_on(p.string(), g, "report");
}

// path_profile.csv's columns (s, x, y, z, depth, speed, pressure), one vector each; empty without it.
std::vector<std::vector<double>> read_profile(const fs::path& csv) {
  std::vector<std::vector<double>> cols(7);
  std::ifstream f(csv);
  std::string row;
  std::getline(f, row);
  for (int line = 2; std::getline(f, row); ++line) {
    std::stringstream ss(row);
    for (auto& col : cols) {
      std::string c;
      std::getline(ss, c, ',');
      try {
        col.push_back(c.empty() ? NAN : std::stod(c));
      } catch (const std::exception&) {
        throw std::runtime_error("report: " + csv.string() + " line " + std::to_string(line) + ": '" + c + "' is not a number");
      }
    }
  }
  return cols;
}

// The profile plot of the path analysis, as the run drew it.
std::optional<figures::ProfilePlot> profile(const v1::RunRecord& rec, const std::vector<std::vector<double>>& cols, const std::string& title) {
  if (cols[0].size() < 2 || !rec.results().has_path()) return std::nullopt;
  const auto& p = rec.results().path();
  figures::ProfilePlot plot;
  plot.title = title + ": profiles along the path";
  plot.s = cols[0];
  plot.z = cols[3];
  plot.series = {{"max depth [m]", cols[4]}, {"max speed [m/s]", cols[5]}, {"max pressure [kPa]", cols[6]}};
  if (p.has_runout_s_m()) {
    plot.runout_s = p.runout_s_m();
    plot.alpha_deg = p.alpha_deg();
    plot.note = "runout point at " + num(p.runout_s_m()) + " m (" + p.criterion() + "), alpha " + num(p.alpha_deg(), 3) + "°";
  }
  if (p.has_beta_s_m()) plot.beta_s = p.beta_s_m();
  return plot;
}

std::vector<figures::ReportSection> summary(const v1::RunRecord& rec) {
  const auto& re = rec.results();
  const auto& mb = rec.mass_balance();
  std::vector<figures::ReportSection> out;
  out.push_back({"Parameters", {rec.parameters().begin(), rec.parameters().end()}});
  out.push_back({"Mass balance",
                 {"released " + num(mb.volume_initial_m3(), 6) + " m³, at the end " + num(mb.volume_final_m3(), 6) + " m³ on the grid, " +
                      num(mb.volume_outflow_m3(), 6) + " m³ left it" +
                      (mb.volume_entrained_m3() > 0 ? ", " + num(mb.volume_entrained_m3(), 6) + " m³ entrained" : "") +
                      (mb.volume_detrained_m3() > 0 ? ", " + num(mb.volume_detrained_m3(), 6) + " m³ left in resistance areas" : "") +
                      "; relative volume error " + num(mb.relative_error(), 2)}});
  std::vector<std::string> r = {
      "affected area (" + re.affected_area_criterion() + "): " + num(re.affected_area_m2() / 1e6, 3) + " km²",
      "maximum depth " + num(re.max_depth_m(), 3) + " m, maximum speed " + num(rec.solver().max_speed_m_s(), 3) + " m/s, maximum pressure " +
          num(re.max_pressure_kpa(), 4) + " kPa",
      "simulated " + num(rec.solver().simulated_s(), 4) + " s in " + std::to_string(rec.solver().steps()) + " steps (stop: " +
          rec.solver().stop() + ")"};
  if (re.has_path() && re.path().has_runout_s_m())
    r.insert(r.begin(), "runout " + num(re.path().runout_s_m(), 4) + " m along the path (" + re.path().criterion() + "), runout angle α " +
                            num(re.path().alpha_deg(), 3) + "°; the path: " + re.path().source());
  for (const auto& n : rec.notes()) r.push_back("note: " + n);
  out.push_back({"Results", r});
  return out;
}

// The maps' extent: the outline and the release with a margin of a tenth (at least 200 m), on the grid.
std::array<double, 4> extent(const terrain::Grid& g, const std::vector<double>& depth, const std::vector<double>& release, double threshold) {
  double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const std::size_t k = std::size_t(j) * g.nx + i;
      if (!(depth[k] > threshold) && !(release[k] > 0)) continue;
      x0 = std::min(x0, g.x_min + i * g.dx), x1 = std::max(x1, g.x_min + (i + 1) * g.dx);
      y0 = std::min(y0, g.y_min + j * g.dx), y1 = std::max(y1, g.y_min + (j + 1) * g.dx);
    }
  if (!(x1 > x0)) return {};
  const double m = std::max(200.0, 0.1 * std::max(x1 - x0, y1 - y0));
  return {std::max(g.x_min, x0 - m), std::max(g.y_min, y0 - m), std::min(g.x_min + g.nx * g.dx, x1 + m), std::min(g.y_min + g.ny * g.dx, y1 + m)};
}

// The structures: the flow next to each (the run's maps) and, from a 3D run or a nest's, its loads
// with their verdict.
figures::ReportTable structures_table(const v1::RunRecord& rec) {
  figures::ReportTable t{"Structures", {"structure", "height [m]", "flow next to it [m]", "ρu² next to it [kPa]", "3D peak force [kN]",
                                        "3D highest pressure [kPa]", "3D loads"}, {}};
  for (const auto& q : rec.structures()) {
    const v1::StructureResult* l = q.has_peak_force_kn() ? &q : nullptr;
    for (const auto& n : rec.nest().structures())
      if (n.name() == q.name() && n.has_peak_force_kn()) l = &n;
    t.rows.push_back({q.name(), num(q.height_max_m(), 3), num(q.max_depth_next_m(), 3), num(q.max_pressure_next_kpa(), 4),
                      l ? num(l->peak_force_kn(), 4) : "–", l ? num(l->max_pressure_kpa(), 4) : "–",
                      !l ? "–" : l->loads_resolved() ? "resolved" : "not design values (under-resolved)"});
  }
  return t;
}

}  // namespace

std::vector<figures::ReportTable> report_tables(const v1::RunRecord& rec) {
  figures::ReportTable pts{"Points of interest", {"point", "max depth [m]", "max speed [m/s]", "max pressure [kPa]", "zone", "arrival [s]", "inside the outline"}, {}};
  for (const auto& p : rec.results().points_of_interest())
    pts.rows.push_back({p.name(), num(p.max_depth_m(), 3), num(p.max_speed_m_s(), 3), num(p.max_pressure_kpa(), 4), p.zone().empty() ? "–" : p.zone(),
                        p.has_arrival_time_s() ? num(p.arrival_time_s(), 3) : "–", p.inside_outline() ? "yes" : "no"});
  figures::ReportTable zones{"Pressure zones (" + rec.results().pressure_zones_criterion() + ")", {"zone", "from [kPa]", "to [kPa]", "area [km²]", "polygons"}, {}};
  for (const auto& z : rec.results().pressure_zones())
    zones.rows.push_back({z.name(), num(z.from_kpa()), z.has_to_kpa() ? num(z.to_kpa()) : "–", num(z.area_m2() / 1e6, 3), std::to_string(z.polygons())});
  std::vector<figures::ReportTable> out{pts, zones};
  if (rec.structures_size() > 0) out.push_back(structures_table(rec));
  return out;
}

bool write_report_output(const std::string& run_dir, const std::string& paper, RunSummary& sum) {
  const fs::path pdf = fs::path(run_dir) / "report.pdf", part = fs::path(run_dir) / "report.pdf.part";
  try {
    ReportOptions opt;
    opt.paper = paper;
    write_run_report(run_dir, part.string(), opt);
    fs::rename(part, pdf);
    return true;
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove(part, ec);
    sum.notes.push_back(std::string("report.pdf not written (outputs.report): ") + e.what());
    return false;
  }
}

figures::ReportLayout write_run_report(const std::string& run_dir, const std::string& pdf_path, const ReportOptions& opt) {
  const fs::path dir(run_dir);
  if (!fs::exists(dir / "run.json")) throw std::runtime_error("report: " + (dir / "run.json").string() + " is missing: not a run's folder");
  const auto rec = read_run_record((dir / "run.json").string());
  if (rec.engine() != "depth-averaged" && rec.engine() != "vof-terrain")
    throw std::runtime_error("report: " + run_dir + " is not a run on terrain (" +
                             (rec.engine().empty() ? "an ensemble's or a zoning's folder: report a member's or a scenario's folder"
                                                   : "a " + rec.engine() + " run") +
                             ")");
  if (!fs::exists(dir / "elevation.tif")) throw std::runtime_error("report: " + (dir / "elevation.tif").string() + " is missing (the report reads the run's own files)");
  figures::Report r;
  r.paper = opt.paper;
  r.dpi = opt.dpi;
  r.grid = terrain::grid_of_raster((dir / "elevation.tif").string(), "report");
  const auto& g = r.grid;
  r.title = rec.scenario().name().empty() ? "runout" : rec.scenario().name();
  r.subtitle = "Hazard maps of a " + rec.engine() + " run of " + rec.created_utc() + ", runout " + rec.software().version() + " (" +
               rec.software().git_commit().substr(0, 10) + "); report of " + today_utc();
  r.sections = summary(rec);
  r.tables = report_tables(rec);
  std::string dem = rec.inputs_size() > 0 ? fs::path(rec.inputs(0).path()).filename().string() : rec.scenario().dem().path();
  r.footer = r.title + "  ·  DEM: " + dem + " (" + rec.dem().source_crs() + ", " + num(rec.dem().source_resolution_m(), 3) + " m; its owner's terms apply)  ·  runout " +
             rec.software().version();
  r.disclaimer = "These maps are the result of a numerical model with the parameters above on the DEM named; they show what that model gives, "
                 "not an observation. Hazard zones for land-use planning are drawn by the responsible experts, who weigh the model's results "
                 "with the avalanche history, the terrain and the snow climate.";
  const double thr = rec.results().outline_threshold_m();
  const auto depth = raster(dir, "max_depth.tif", g), release = raster(dir, "release.tif", g);
  r.extent = extent(g, depth, release, thr);
  figures::HazardMap base;
  base.release = release;
  base.max_depth = depth;
  base.outline_threshold = thr;
  for (const auto& p : rec.results().points_of_interest()) base.points.push_back({p.name(), p.x(), p.y()});
  for (const auto* list : {&rec.structures(), &rec.nest().structures()})  // the structures with 3D loads, as on the run's maps
    for (const auto& q : *list)
      if (q.has_peak_force_kn())
        base.points.push_back({structure_load_label(q.name(), q.max_pressure_kpa(), q.loads_resolved()), q.x(), q.y()});
  const auto cols = read_profile(dir / "path_profile.csv");
  for (std::size_t k = 0; k < cols[1].size(); ++k) base.path.emplace_back(cols[1][k], cols[2][k]);
  r.profile = profile(rec, cols, r.title);
  if (rec.results().has_path()) {
    const auto& p = rec.results().path();
    if (p.runout_xyz_size() >= 2) base.path_marks.push_back({"runout", p.runout_xyz(0), p.runout_xyz(1)});
    if (p.beta_xyz_size() >= 2) base.path_marks.push_back({"β", p.beta_xyz(0), p.beta_xyz(1)});
  }
  for (const auto& q : hazard_rasters()) {
    if (!fs::exists(dir / (q.name + ".tif"))) continue;
    figures::HazardMap m = base;
    m.palette = figures::hazard_palette(q.name);
    m.title = r.title + ": " + m.palette.title;
    m.values = figures::inside_outline(raster(dir, q.name + ".tif", g), depth, thr);
    m.colour_note = "coloured inside the outline only (max depth > " + num(thr) + " m)";
    m.show_maximum = true;
    if (q.name == "max_pressure") {  // the zones' boundaries, by the run's own zones and rule (as its map)
      std::vector<ZoneThreshold> zones;
      for (const auto& z : rec.results().pressure_zones()) zones.push_back({z.name(), z.from_kpa()});
      const auto zm = products::pressure_zones(zones, m.values);
      m.boundaries.push_back({zm.cls, zm.palette});
    }
    r.maps.push_back(std::move(m));
  }
  return figures::write_report(pdf_path, r);
}

}  // namespace runout::jobs
