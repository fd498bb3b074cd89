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

#include "jobs/drivers/hazard_maps.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/zoning.hpp"
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
  for (const auto& name : order) {
    const auto w = ensemble::parameter_in_words(name);
    const std::string unit = w.unit.empty() ? "" : w.unit == "°" ? "°" : " " + w.unit;
    p.push_back("varied: " + w.words + " " + num(range[name].first) + unit + " – " + num(range[name].second) + unit);
  }
  for (auto& line : map_footer(g)) p.push_back(std::move(line));
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

// What the parts of the aggregate share: the ensemble, its members, the aggregate's grid and folder,
// the record being written and the maps' common part.
struct Aggregate {
  const ResolvedScenario& e;
  const std::vector<MemberResults>& members;
  const ensemble::AggregateSettings settings;
  const terrain::Grid& g;
  const std::string& out_dir;
  v1::EnsembleRecord& rec;
  figures::HazardMap base;
  std::string name;  // the maps' titles
  std::string out(const std::string& f) const { return (fs::path(out_dir) / f).string(); }
  void add(const std::string& f) { rec.add_outputs(f); }
};

// Every member's three rasters on the aggregate's grid, its record, which points of interest it
// reached and the path's runout criterion.
std::vector<MemberStack> read_members(Aggregate& a, std::vector<int>& reached, std::string& criterion,
                                      const std::function<bool(int, int)>& progress) {
  std::vector<MemberStack> stack(3);
  for (auto& s : stack) {
    s.cells = a.g.cells();
    s.members = int(a.members.size());
    s.v.resize(s.cells * a.members.size());
  }
  for (std::size_t m = 0; m < a.members.size(); ++m) {
    const auto r = member_record(a.members[m]);
    record_member(a.members[m], r, a.rec, reached);
    if (criterion.empty()) criterion = r.results().path().criterion();
    for (std::size_t q = 0; q < 3; ++q) {
      const std::string file = (fs::path(a.members[m].dir) / (std::string(kQuantities[q].raster) + ".tif")).string();
      const auto v = terrain::read_raster_on(file, a.g, "member " + std::to_string(a.members[m].member.index));
      float* dst = stack[q].v.data() + m * a.g.cells();
      for (std::size_t c = 0; c < v.size(); ++c) dst[c] = std::isfinite(v[c]) ? float(v[c]) : 0.0f;  // no data inside: not reached
    }
    if (progress && !progress(int(m + 1), int(a.members.size()))) throw AggregateStopped{};
  }
  return stack;
}

// The points of interest: the share of the members that reached each, in the record and on the maps.
void points_of_interest(Aggregate& a, const std::vector<int>& reached) {
  const auto& pois = a.e.scenario.outputs().points_of_interest();
  for (int k = 0; k < pois.size(); ++k) {
    const auto at = terrain::place_point(a.g, pois[k].x(), pois[k].y(), pois[k].crs(), "outputs.points_of_interest[" + std::to_string(k) + "]");
    const int n = std::size_t(k) < reached.size() ? reached[std::size_t(k)] : 0;
    auto* pp = a.rec.add_points_of_interest();
    pp->set_name(pois[k].name());
    pp->set_x(at.x);
    pp->set_y(at.y);
    pp->set_members_reached(n);
    pp->set_probability(double(n) / double(a.members.size()));
    a.base.points.push_back({pois[k].name() + ": P = " + num(std::round(pp->probability() * 1000) / 1000), at.x, at.y});
  }
}

// The probability that a member exceeds threshold t of quantity q: raster, style, record and map.
void write_probability(Aggregate& a, std::size_t q, const MemberStack& stack, double t) {
  const Quantity& Q = kQuantities[q];
  const auto& g = a.g;
  const auto p = ensemble::exceedance_probability(stack, t, Q.strict, g.outside);
  const std::string stem = std::string("probability_") + Q.word + "_" + num(t) + Q.file_unit;
  const std::string criterion_text = std::string(Q.title) + (Q.strict ? " > " : " >= ") + num(t) + " " + Q.unit +
                                     (q == 2 ? " where max depth > " + num(a.e.outline_threshold) + " m" : "");
  terrain::write_cog(a.out(stem + ".tif"), g, p,
                     {"probability that a member's " + criterion_text + " (" + std::to_string(a.members.size()) + " members)", "",
                      {{"THRESHOLD", num(t)}, {"MEMBERS", std::to_string(a.members.size())}}});
  figures::write_qml_ramp(a.out(stem + ".qml"), figures::probability_palette());
  for (const char* ext : {".tif", ".qml"}) a.add(stem + ext);
  auto* pr = a.rec.add_probabilities();
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
  if (!a.e.maps) return;
  figures::HazardMap m = a.base;
  m.palette = figures::probability_palette();
  m.palette.title = "probability that " + criterion_text;
  m.title = a.name + ": probability that " + criterion_text;
  m.values = p;
  figures::draw_hazard_map(a.out("map_" + stem + ".png"), a.out("map_" + stem + ".pdf"), g, m);
  for (const char* ext : {".png", ".pdf"}) a.add("map_" + stem + ext);
}

// The members' percentiles of quantity q's maximum: rasters and styles.
void write_percentiles(Aggregate& a, std::size_t q, const std::vector<std::vector<double>>& pv) {
  const Quantity& Q = kQuantities[q];
  for (std::size_t k = 0; k < a.settings.percentiles.size(); ++k) {
    const std::string stem = std::string(Q.raster) + "_" + percentile_tag(a.settings.percentiles[k]);
    terrain::write_cog(a.out(stem + ".tif"), a.g, pv[k],
                       {"percentile " + num(a.settings.percentiles[k]) + " of the members' " + Q.title, Q.unit,
                        {{"PERCENTILE", num(a.settings.percentiles[k])}, {"MEMBERS", std::to_string(a.members.size())}}});
    figures::write_qml_ramp(a.out(stem + ".qml"), figures::hazard_palette(Q.raster));
    for (const char* ext : {".tif", ".qml"}) a.add(stem + ext);
  }
}

// The runout along the path: its distribution in the record, the CSV and the histogram.
void write_runout(Aggregate& a, const std::string& criterion) {
  runout_distribution(a.members, a.settings, criterion, a.rec);
  write_runout_csv(a.out("runout_distribution.csv"), a.members, a.rec);
  a.add("runout_distribution.csv");
  if (!a.e.maps) return;
  figures::Histogram h;
  h.title = a.name + ": runout along the path, " + std::to_string(a.members.size()) + " members";
  h.note = "runout point: the last cross-section where " + criterion + "; " + std::to_string(a.rec.runout().members_reached()) +
           " of " + std::to_string(a.members.size()) + " members reach one";
  h.x_label = "runout along the path (horizontal) [m]";
  for (const auto& m : a.rec.members())
    if (m.has_runout_s_m()) h.values.push_back(m.runout_s_m());
  for (int k = 0; k < a.rec.runout().percentiles_m_size(); ++k)
    h.marks.push_back({percentile_tag(a.settings.percentiles[std::size_t(k)]), a.rec.runout().percentiles_m(k)});
  figures::draw_histogram(a.out("runout_histogram.png"), a.out("runout_histogram.pdf"), h);
  for (const char* f : {"runout_histogram.png", "runout_histogram.pdf"}) a.add(f);
}


}  // namespace

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

// The record's head: software, kind, scenario, design, creation time.
v1::EnsembleRecord record_head(const ResolvedScenario& e) {
  v1::EnsembleRecord rec;
  *rec.mutable_software() = this_software();
  rec.set_kind(e.scenario.has_zoning() ? "zoning" : "ensemble");
  *rec.mutable_scenario() = e.scenario;
  rec.set_design(e.scenario.has_zoning() ? "return periods"
                 : e.scenario.variations().design().empty() ? "cross-product" : e.scenario.variations().design());
  char b[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  rec.set_created_utc(b);
  return rec;
}

v1::EnsembleRecord aggregate_ensemble(const ResolvedScenario& e, const std::vector<MemberResults>& members, const std::string& out_dir,
                                      const std::function<bool(int, int)>& progress) {
  if (e.scenario.has_zoning()) return aggregate_zoning(e, members, out_dir, progress);
  const auto t0 = std::chrono::steady_clock::now();
  if (members.empty()) throw std::runtime_error("an ensemble without members");
  const terrain::Grid g = aggregate_grid(e, members);
  v1::EnsembleRecord rec = record_head(e);
  Aggregate a{e, members, ensemble::aggregate_settings(e), g, out_dir, rec, {}, e.scenario.name().empty() ? "runout" : e.scenario.name()};
  std::vector<int> reached;
  std::string criterion;
  const std::vector<MemberStack> stack = read_members(a, reached, criterion, progress);
  const auto& settings = a.settings;
  a.base.release = terrain::rasterize_releases(g, e.dem, e.releases);
  a.base.parameters = map_block(e, members, g);
  // The members' percentiles of max depth (written below), and the median's outline on the maps.
  const auto depth_pct = ensemble::percentiles(stack[0], settings.percentiles, g.outside);
  const auto p50 = std::find(settings.percentiles.begin(), settings.percentiles.end(), 50.0);
  a.base.max_depth = p50 != settings.percentiles.end() ? depth_pct[std::size_t(p50 - settings.percentiles.begin())]
                                                        : ensemble::percentiles(stack[0], {50}, g.outside)[0];
  a.base.outline_threshold = e.outline_threshold;
  points_of_interest(a, reached);
  for (std::size_t q = 0; q < 3; ++q) {
    const auto& thresholds = q == 0 ? settings.depth_m : q == 1 ? settings.speed_m_s : settings.pressure_kpa;
    // A member's pressure counts where its max depth exceeds the outline threshold, as its pressure
    // zones count it: identical members give probability 1 exactly on their zones.
    MemberStack zoned;
    if (q == 2) {
      zoned = stack[2];
      for (std::size_t k = 0; k < zoned.v.size(); ++k)
        if (!(stack[0].v[k] > e.outline_threshold)) zoned.v[k] = 0;
    }
    for (double t : thresholds) write_probability(a, q, q == 2 ? zoned : stack[q], t);
    write_percentiles(a, q, q == 0 ? depth_pct : ensemble::percentiles(stack[q], settings.percentiles, g.outside));
  }
  for (double p : settings.percentiles) rec.add_percentiles(p);
  write_runout(a, criterion);
  *rec.mutable_grid() = grid_report(g);
  a.add("run.json");
  rec.set_aggregate_seconds(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  write_record_json(a.out("run.json"), rec);
  return rec;
}

}  // namespace runout::jobs
