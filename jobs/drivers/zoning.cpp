#include "jobs/drivers/zoning.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "jobs/drivers/hazard_maps.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/figures/hazard_map.hpp"
#include "jobs/figures/qml.hpp"
#include "jobs/formats/run_record.hpp"
#include "jobs/products/zoning.hpp"
#include "terrain/points.hpp"
#include "terrain/terrain.hpp"

namespace fs = std::filesystem;

namespace runout::jobs {
namespace {

constexpr const char* kGuideline =
    "BFF & EISLF (1984): Richtlinien zur Berücksichtigung der Lawinengefahr bei raumwirksamen Tätigkeiten (Swiss guideline)";

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

// One scenario's rasters on the zoning's grid.
struct ScenarioRasters {
  std::vector<double> depth, pressure;
};

// The file stem of a return period: "30y".
std::string period_tag(double t) { return num(t) + "y"; }

// Each member's maximum depth and pressure on the grid, its record in rec, the points it reached.
std::vector<ScenarioRasters> read_scenarios(const std::vector<MemberResults>& members, const terrain::Grid& g, v1::EnsembleRecord& rec,
                                            const std::function<bool(int, int)>& progress) {
  std::vector<ScenarioRasters> out;
  std::vector<int> reached;
  for (std::size_t m = 0; m < members.size(); ++m) {
    record_member(members[m], member_record(members[m]), rec, reached);
    const std::string what = "the " + period_tag(members[m].member.return_period_y) + " scenario (member " + std::to_string(m) + ")";
    auto read = [&](const char* r) {
      auto v = terrain::read_raster_on((fs::path(members[m].dir) / (std::string(r) + ".tif")).string(), g, what);
      for (double& x : v) x = std::isfinite(x) ? x : 0.0;
      return v;
    };
    out.push_back({read("max_depth"), read("max_pressure")});
    if (progress && !progress(int(m + 1), int(members.size()))) throw AggregateStopped{};
  }
  return out;
}

// Each scenario's depth and pressure rasters and its pressure map beside the zones, named by its
// return period.
void copy_scenario_files(const std::vector<MemberResults>& members, const std::string& out_dir, v1::EnsembleRecord& rec) {
  for (const auto& m : members) {
    const std::string tag = period_tag(m.member.return_period_y);
    for (const auto& [from, to] : {std::pair<std::string, std::string>{"max_pressure.tif", "max_pressure_" + tag + ".tif"},
                                   {"max_depth.tif", "max_depth_" + tag + ".tif"},
                                   {"map_max_pressure.png", "map_max_pressure_" + tag + ".png"},
                                   {"map_max_pressure.pdf", "map_max_pressure_" + tag + ".pdf"}}) {
      const fs::path src = fs::path(m.dir) / from;
      if (!fs::exists(src)) continue;
      fs::copy_file(src, fs::path(out_dir) / to, fs::copy_options::overwrite_existing);
      rec.add_outputs(to);
    }
  }
}

// The record's zoning part: the rule, each scenario's reach, each zone's area (from its polygons).
void record_zoning(const products::ZoningRule& rule, const std::vector<MemberResults>& members, const std::vector<ScenarioRasters>& sc,
                   const std::vector<std::uint8_t>& zones, const std::vector<terrain::ClassArea>& areas, const terrain::Grid& g,
                   v1::ZoningResult& z) {
  z.set_guideline(kGuideline);
  z.set_red_pressure_kpa(rule.red_pressure_kpa);
  z.set_frequent_y(rule.frequent_y);
  z.set_design_y(rule.design_y);
  z.set_reach_criterion("max depth > " + num(rule.reach_depth_m) + " m");
  const double cell = g.dx * g.dx;
  const auto classes = products::zone_classes(rule);
  for (std::size_t k = 0; k < classes.size(); ++k) {
    auto* r = z.add_zones();
    r->set_name(classes[k].name);
    r->set_cells(std::count(zones.begin(), zones.end(), std::uint8_t(k + 1)));
    r->set_area_m2(double(r->cells()) * cell);
    if (k < areas.size()) r->set_polygons(areas[k].polygons);
  }
  for (std::size_t m = 0; m < members.size(); ++m) {
    auto* s = z.add_scenarios();
    s->set_return_period_y(members[m].member.return_period_y);
    s->set_member(members[m].member.index);
    double reached = 0, red = 0, top = 0;
    for (std::size_t k = 0; k < zones.size(); ++k) {
      if (!(sc[m].depth[k] > rule.reach_depth_m)) continue;
      reached += cell;
      if (sc[m].pressure[k] >= rule.red_pressure_kpa) red += cell;
      top = std::max(top, sc[m].pressure[k]);
    }
    s->set_reached_area_m2(reached);
    s->set_red_pressure_area_m2(red);
    s->set_max_pressure_kpa(top);
  }
}

// The zones' map: the zones coloured, the release and each point of interest with its zone, the rule
// and the scenarios in the parameter block.
void draw_zones(const ResolvedScenario& e, const products::ZoningRule& rule, const std::vector<MemberResults>& members,
                const std::vector<std::uint8_t>& zones, const terrain::Grid& g, v1::ZoningResult& z, const std::string& out_dir,
                v1::EnsembleRecord& rec) {
  figures::HazardMap m;
  m.palette = products::zone_palette(rule);
  m.title = (e.scenario.name().empty() ? std::string("runout") : e.scenario.name()) + ": hazard zones";
  m.values.assign(zones.begin(), zones.end());
  m.release = terrain::rasterize_releases(g, e.dem, e.releases);
  m.parameters.push_back("zones by the Swiss guideline (BFF & EISLF 1984)");
  m.parameters.push_back("red: ≥ " + num(rule.red_pressure_kpa) + " kPa up to " + num(rule.design_y) + " y, or reached up to " +
                         num(rule.frequent_y) + " y");
  m.parameters.push_back("reached: " + z.reach_criterion());
  for (const auto& mr : members) {  // its values after the return period (the first)
    const auto& v = mr.member.values;
    const std::vector<ensemble::ParameterValue> own(v.begin() + (v.empty() ? 0 : 1), v.end());
    m.parameters.push_back(period_tag(mr.member.return_period_y) + ": " + (own.empty() ? "the scenario's values" : ensemble::describe(own)));
  }
  for (auto& line : map_footer(g)) m.parameters.push_back(std::move(line));
  const auto& pois = e.scenario.outputs().points_of_interest();
  const char* names[4] = {"", "yellow", "blue", "red"};
  for (int k = 0; k < pois.size(); ++k) {
    const auto at = terrain::place_point(g, pois[k].x(), pois[k].y(), pois[k].crs(), "outputs.points_of_interest[" + std::to_string(k) + "]");
    auto* p = z.add_points_of_interest();
    p->set_name(pois[k].name());
    p->set_x(at.x);
    p->set_y(at.y);
    p->set_zone(names[zones[std::size_t(at.j) * g.nx + at.i]]);
    m.points.push_back({pois[k].name() + (p->zone().empty() ? "" : ": " + p->zone()), at.x, at.y});
  }
  if (!e.maps) return;
  const auto out = [&](const std::string& f) { return (fs::path(out_dir) / f).string(); };
  figures::draw_hazard_map(out("map_zones.png"), out("map_zones.pdf"), g, m);
  for (const char* f : {"map_zones.png", "map_zones.pdf"}) rec.add_outputs(f);
}

}  // namespace

v1::EnsembleRecord aggregate_zoning(const ResolvedScenario& e, const std::vector<MemberResults>& members, const std::string& out_dir,
                                    const std::function<bool(int, int)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  if (members.size() < 2) throw std::runtime_error("a zoning needs at least two scenarios");
  const terrain::Grid g = aggregate_grid(e, members);
  v1::EnsembleRecord rec = record_head(e);
  const auto settings = ensemble::aggregate_settings(e);
  const products::ZoningRule rule{settings.red_pressure_kpa, settings.frequent_y, settings.design_y, e.outline_threshold};
  const auto sc = read_scenarios(members, g, rec, progress);
  std::vector<products::ZoningScenario> in;
  for (std::size_t m = 0; m < members.size(); ++m) in.push_back({members[m].member.return_period_y, &sc[m].depth, &sc[m].pressure});
  const auto zones = products::zones(rule, in, g.outside);
  const auto out = [&](const std::string& f) { return (fs::path(out_dir) / f).string(); };
  const auto classes = products::zone_classes(rule);
  terrain::write_class_cog(out("zones.tif"), g, zones, classes,
                           {"hazard zones from the scenarios by return period (0: none, 1 yellow, 2 blue, 3 red)", ""});
  figures::write_qml_classes(out("zones.qml"), products::zone_palette(rule));
  const auto areas = terrain::write_class_polygons(out("zones.geojson"), out("zones.gpkg"), "zones", g, zones, classes, "zone");
  std::vector<std::string> names;
  for (const auto& c : classes) names.push_back(c.name);
  const std::string style = figures::qml_polygon_classes(products::zone_palette(rule), names);
  terrain::add_layer_style(out("zones.gpkg"), "zones", "runout hazard zones", style);
  figures::write_qml(out("zones_polygons.qml"), style);
  for (const char* f : {"zones.tif", "zones.tif.aux.xml", "zones.qml", "zones.geojson", "zones.gpkg", "zones_polygons.qml"})
    if (fs::exists(out(f))) rec.add_outputs(f);
  auto* z = rec.mutable_zoning();
  record_zoning(rule, members, sc, zones, areas, g, *z);
  draw_zones(e, rule, members, zones, g, *z, out_dir, rec);
  copy_scenario_files(members, out_dir, rec);
  *rec.mutable_grid() = grid_report(g);
  rec.add_outputs("run.json");
  rec.set_aggregate_seconds(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  write_record_json(out("run.json"), rec);
  return rec;
}

}  // namespace runout::jobs
