#include "jobs/drivers/ensemble_aggregate.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/ensemble/statistics.hpp"
#include "jobs/figures/hazard_map.hpp"
#include "jobs/figures/histogram.hpp"
#include "jobs/figures/palette.hpp"
#include "jobs/figures/qml.hpp"
#include "jobs/formats/run_record.hpp"
#include "terrain/points.hpp"
#include "terrain/terrain.hpp"

namespace fs = std::filesystem;

namespace runout::jobs {

namespace {

using ensemble::MemberStack;

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

// The three hazard rasters the aggregate reads: name, how the probability counts ("max depth > t"
// as the outline counts, "max pressure >= t" as the zones do), the file's short name and unit.
struct Quantity {
  const char* raster;
  const char* word;  // in file names: probability_<word>_<threshold><unit>.tif
  const char* title;
  const char* unit;
  const char* file_unit;
  bool strict;
};
const Quantity kQuantities[] = {
    {"max_depth", "depth", "max depth", "m", "m", true},
    {"max_speed", "speed", "max speed", "m/s", "m_s", false},
    {"max_pressure", "pressure", "max pressure", "kPa", "kPa", false},
};

std::string percentile_tag(double p) {
  char b[32];
  if (p == std::floor(p)) std::snprintf(b, sizeof b, "p%02d", int(p));
  else std::snprintf(b, sizeof b, "p%g", p);
  return b;
}

// The finest member's grid: every member's rasters lie on it or are resampled onto it.
terrain::Grid aggregate_grid(const ResolvedScenario& e, const std::vector<MemberResults>& members) {
  terrain::DemRequest req = e.dem;
  for (const auto& m : members) {
    double r = 0;
    if (ensemble::number_at(m.member.scenario, "grid.resolution_m", r) && r > 0 && (req.resolution <= 0 || r < req.resolution))
      req.resolution = r;
  }
  return terrain::prepare_grid(req);
}

// A member's record, or an error naming the member.
v1::RunRecord member_record(const MemberResults& m) {
  try {
    return read_run_record((fs::path(m.dir) / "run.json").string());
  } catch (const std::exception& e) {
    throw std::runtime_error("member " + std::to_string(m.member.index) + " (" + ensemble::describe(m.member.values) +
                             "): its results cannot be read: " + e.what());
  }
}

// The maps' parameter block: what varied, the grid and the software.
std::vector<std::string> map_block(const ResolvedScenario& e, const std::vector<MemberResults>& members, const terrain::Grid& g) {
  std::vector<std::string> p;
  const auto& v = e.scenario.variations();
  p.push_back("ensemble: " + std::to_string(members.size()) + " members, " +
              (v.design() == "latin-hypercube" ? "latin hypercube" : "cross product") + " (depth-averaged Savage–Hutter)");
  std::map<std::string, std::pair<double, double>> range;
  std::vector<std::string> order;
  for (const auto& m : members)
    for (const auto& pv : m.member.values) {
      auto [it, fresh] = range.emplace(pv.parameter, std::pair{pv.value, pv.value});
      if (fresh) order.push_back(pv.parameter);
      it->second.first = std::min(it->second.first, pv.value);
      it->second.second = std::max(it->second.second, pv.value);
    }
  for (const auto& name : order)
    p.push_back("varied: " + name + " " + num(range[name].first) + " – " + num(range[name].second));
  p.push_back("grid: " + num(g.dx) + " m, " + std::to_string(g.nx) + " × " + std::to_string(g.ny) + " cells, " + g.crs_name);
  const auto sw = this_software();
  p.push_back("software: runout " + sw.version() + " (" + sw.git_commit().substr(0, 10) + ")");
  return p;
}

void write_runout_csv(const std::string& path, const std::vector<MemberResults>& members, const v1::EnsembleRecord& rec) {
  std::ofstream f(path, std::ios::trunc);
  f << "member";
  if (!members.empty())
    for (const auto& pv : members.front().member.values) f << "," << pv.parameter;
  f << ",scenario_hash,runout_s_m,alpha_deg,affected_area_m2,max_speed_m_s,max_pressure_kpa,release_volume_m3\n";
  char b[64];
  auto out = [&](double v) {
    std::snprintf(b, sizeof b, ",%.10g", v);
    f << (std::isfinite(v) ? b : ",");
  };
  for (std::size_t k = 0; k < members.size(); ++k) {
    const auto& m = rec.members(int(k));
    f << m.index();
    for (const auto& pv : m.values()) out(pv.value());
    f << "," << m.scenario_hash();
    out(m.has_runout_s_m() ? m.runout_s_m() : NAN);
    out(m.has_alpha_deg() ? m.alpha_deg() : NAN);
    out(m.affected_area_m2());
    out(m.max_speed_m_s());
    out(m.max_pressure_kpa());
    out(m.release_volume_m3());
    f << "\n";
  }
  if (!f.flush()) throw std::runtime_error("cannot write " + path);
}

// Per member: its figures in the record, and whether it reached each point of interest.
void record_member(const MemberResults& m, const v1::RunRecord& r, v1::EnsembleRecord& rec, std::vector<int>& reached) {
  auto* em = rec.add_members();
  em->set_index(m.member.index);
  for (const auto& pv : m.member.values) {
    auto* v = em->add_values();
    v->set_parameter(pv.parameter);
    v->set_value(pv.value);
  }
  em->set_scenario_hash(m.hash);
  const auto& res = r.results();
  if (res.path().has_runout_s_m()) em->set_runout_s_m(res.path().runout_s_m());
  if (res.path().has_alpha_deg()) em->set_alpha_deg(res.path().alpha_deg());
  em->set_affected_area_m2(res.affected_area_m2());
  em->set_max_pressure_kpa(res.max_pressure_kpa());
  em->set_release_volume_m3(r.release().volume_m3());
  em->set_max_speed_m_s(r.solver().max_speed_m_s());
  if (reached.empty()) reached.assign(std::size_t(res.points_of_interest_size()), 0);
  for (int k = 0; k < res.points_of_interest_size() && std::size_t(k) < reached.size(); ++k)
    reached[std::size_t(k)] += res.points_of_interest(k).inside_outline();
}

void runout_distribution(const std::vector<MemberResults>& members, const ensemble::AggregateSettings& a, const std::string& criterion,
                         v1::EnsembleRecord& rec) {
  auto* d = rec.mutable_runout();
  d->set_criterion(criterion);
  std::vector<double> s;
  for (const auto& m : rec.members())
    if (m.has_runout_s_m()) s.push_back(m.runout_s_m());
  d->set_members_reached(int(s.size()));
  if (s.empty()) return;
  double sum = 0;
  for (double x : s) sum += x;
  d->set_mean_m(sum / double(s.size()));
  for (double p : a.percentiles) d->add_percentiles_m(ensemble::percentile_of(s, p));
  d->set_min_m(s.front());
  d->set_max_m(s.back());
  (void)members;
}

}  // namespace

v1::EnsembleRecord aggregate_ensemble(const ResolvedScenario& e, const std::vector<MemberResults>& members, const std::string& out_dir,
                                      const std::function<bool(int, int)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  if (members.empty()) throw std::runtime_error("an ensemble without members");
  const auto settings = ensemble::aggregate_settings(e);
  const terrain::Grid g = aggregate_grid(e, members);
  auto out = [&](const std::string& f) { return (fs::path(out_dir) / f).string(); };
  v1::EnsembleRecord rec;
  *rec.mutable_software() = this_software();
  rec.set_kind("ensemble");
  *rec.mutable_scenario() = e.scenario;
  rec.set_design(e.scenario.variations().design().empty() ? "cross-product" : e.scenario.variations().design());
  {
    char b[32];
    const std::time_t now = std::time(nullptr);
    std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    rec.set_created_utc(b);
  }
  // Every member's three rasters on the aggregate's grid, and its record.
  std::vector<MemberStack> stack(3);
  for (auto& s : stack) {
    s.cells = g.cells();
    s.members = int(members.size());
    s.v.resize(s.cells * members.size());
  }
  std::vector<int> reached;
  std::string criterion;
  for (std::size_t m = 0; m < members.size(); ++m) {
    const auto r = member_record(members[m]);
    record_member(members[m], r, rec, reached);
    if (criterion.empty()) criterion = r.results().path().criterion();
    for (std::size_t q = 0; q < 3; ++q) {
      const std::string file = (fs::path(members[m].dir) / (std::string(kQuantities[q].raster) + ".tif")).string();
      const auto v = terrain::read_raster_on(file, g, "member " + std::to_string(members[m].member.index));
      float* dst = stack[q].v.data() + m * g.cells();
      for (std::size_t c = 0; c < v.size(); ++c) dst[c] = std::isfinite(v[c]) ? float(v[c]) : 0.0f;  // no data inside: not reached
    }
    if (progress && !progress(int(m + 1), int(members.size()))) throw AggregateStopped{};
  }
  auto& files = *rec.mutable_outputs();
  // Probabilities of exceedance.
  figures::HazardMap base;
  base.release = terrain::rasterize_releases(g, e.dem, e.releases);
  base.parameters = map_block(e, members, g);
  // The members' percentiles of max depth (written below), and the median's outline on the maps.
  const auto depth_pct = ensemble::percentiles(stack[0], settings.percentiles, g.outside);
  const auto p50 = std::find(settings.percentiles.begin(), settings.percentiles.end(), 50.0);
  base.max_depth = p50 != settings.percentiles.end() ? depth_pct[std::size_t(p50 - settings.percentiles.begin())]
                                                      : ensemble::percentiles(stack[0], {50}, g.outside)[0];
  base.outline_threshold = e.outline_threshold;
  const auto& pois = e.scenario.outputs().points_of_interest();
  for (int k = 0; k < pois.size(); ++k) {
    const auto at = terrain::place_point(g, pois[k].x(), pois[k].y(), pois[k].crs(), "outputs.points_of_interest[" + std::to_string(k) + "]");
    const int n = std::size_t(k) < reached.size() ? reached[std::size_t(k)] : 0;
    auto* pp = rec.add_points_of_interest();
    pp->set_name(pois[k].name());
    pp->set_x(at.x);
    pp->set_y(at.y);
    pp->set_members_reached(n);
    pp->set_probability(double(n) / double(members.size()));
    base.points.push_back({pois[k].name() + ": P = " + num(std::round(pp->probability() * 1000) / 1000), at.x, at.y});
  }
  const std::string name = e.scenario.name().empty() ? "runout" : e.scenario.name();
  for (std::size_t q = 0; q < 3; ++q) {
    const Quantity& Q = kQuantities[q];
    const auto& thresholds = q == 0 ? settings.depth_m : q == 1 ? settings.speed_m_s : settings.pressure_kpa;
    // A member's pressure counts where its max depth exceeds the outline threshold, as its pressure
    // zones count it: identical members give probability 1 exactly on their zones.
    MemberStack zoned;
    if (q == 2) {
      zoned = stack[2];
      for (std::size_t k = 0; k < zoned.v.size(); ++k)
        if (!(stack[0].v[k] > e.outline_threshold)) zoned.v[k] = 0;
    }
    for (double t : thresholds) {
      const auto p = ensemble::exceedance_probability(q == 2 ? zoned : stack[q], t, Q.strict, g.outside);
      const std::string stem = std::string("probability_") + Q.word + "_" + num(t) + Q.file_unit;
      const std::string criterion_text = std::string(Q.title) + (Q.strict ? " > " : " >= ") + num(t) + " " + Q.unit +
                                         (q == 2 ? " where max depth > " + num(e.outline_threshold) + " m" : "");
      terrain::write_cog(out(stem + ".tif"), g, p,
                         {"probability that a member's " + criterion_text + " (" + std::to_string(members.size()) + " members)", "",
                          {{"THRESHOLD", num(t)}, {"MEMBERS", std::to_string(members.size())}}});
      figures::write_qml_ramp(out(stem + ".qml"), figures::probability_palette());
      for (const char* ext : {".tif", ".qml"}) files.Add(stem + ext);
      auto* pr = rec.add_probabilities();
      pr->set_quantity(Q.raster);
      pr->set_threshold(t);
      pr->set_unit(Q.unit);
      pr->set_criterion(criterion_text);
      pr->set_file(stem + ".tif");
      double any = 0, half = 0, all = 0;
      for (double v : p) {
        if (!(v > 0)) continue;
        any += g.dx * g.dx;
        if (v >= 0.5) half += g.dx * g.dx;
        if (v == 1) all += g.dx * g.dx;
      }
      pr->set_area_any_m2(any);
      pr->set_area_half_m2(half);
      pr->set_area_all_m2(all);
      if (!e.maps) continue;
      figures::HazardMap m = base;
      m.palette = figures::probability_palette();
      m.palette.title = "probability that " + criterion_text;
      m.title = name + ": probability that " + criterion_text;
      m.values = p;
      figures::draw_hazard_map(out("map_" + stem + ".png"), out("map_" + stem + ".pdf"), g, m);
      for (const char* ext : {".png", ".pdf"}) files.Add("map_" + stem + ext);
    }
    // Percentiles of the maximum.
    const auto pv = q == 0 ? depth_pct : ensemble::percentiles(stack[q], settings.percentiles, g.outside);
    for (std::size_t k = 0; k < settings.percentiles.size(); ++k) {
      const std::string stem = std::string(Q.raster) + "_" + percentile_tag(settings.percentiles[k]);
      terrain::write_cog(out(stem + ".tif"), g, pv[k],
                         {"percentile " + num(settings.percentiles[k]) + " of the members' " + Q.title, Q.unit,
                          {{"PERCENTILE", num(settings.percentiles[k])}, {"MEMBERS", std::to_string(members.size())}}});
      figures::write_qml_ramp(out(stem + ".qml"), figures::hazard_palette(Q.raster));
      for (const char* ext : {".tif", ".qml"}) files.Add(stem + ext);
    }
  }
  for (double p : settings.percentiles) rec.add_percentiles(p);
  // The runout along the path.
  runout_distribution(members, settings, criterion, rec);
  write_runout_csv(out("runout_distribution.csv"), members, rec);
  files.Add("runout_distribution.csv");
  if (e.maps) {
    figures::Histogram h;
    h.title = name + ": runout along the path, " + std::to_string(members.size()) + " members";
    h.note = "runout point: the last cross-section where " + criterion + "; " + std::to_string(rec.runout().members_reached()) +
             " of " + std::to_string(members.size()) + " members reach one";
    h.x_label = "runout along the path (horizontal) [m]";
    for (const auto& m : rec.members())
      if (m.has_runout_s_m()) h.values.push_back(m.runout_s_m());
    for (int k = 0; k < rec.runout().percentiles_m_size(); ++k)
      h.marks.push_back({percentile_tag(settings.percentiles[std::size_t(k)]), rec.runout().percentiles_m(k)});
    figures::draw_histogram(out("runout_histogram.png"), out("runout_histogram.pdf"), h);
    for (const char* f : {"runout_histogram.png", "runout_histogram.pdf"}) files.Add(f);
  }
  *rec.mutable_grid() = grid_report(g);
  files.Add("run.json");
  rec.set_aggregate_seconds(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  write_record_json(out("run.json"), rec);
  return rec;
}

}  // namespace runout::jobs
