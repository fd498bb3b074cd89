#include "jobs/drivers/vof_terrain/hazard.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::vof_terrain {

namespace vof = engine::vof;

ColumnHazard::ColumnHazard(const Columns& cols, const vof::Mesh& m, std::vector<double> cos_slope, HazardSettings s,
                           std::vector<Tracked> tracked)
    : cols_(cols), m_(m), cos_(std::move(cos_slope)), set_(s), tracked_(std::move(tracked)) {
  const std::size_t n = cols.grid_cells();
  hz_.max_depth.assign(n, 0);
  hz_.max_speed.assign(n, 0);
  hz_.max_pressure.assign(n, 0);
  hz_.arrival_time.assign(n, std::numeric_limits<double>::quiet_NaN());
  hz_.final_depth.assign(n, 0);
  max_surface_.assign(n, 0);
  max_stress_.assign(n, 0);
  deepest_t_.assign(tracked_.size(), std::numeric_limits<double>::quiet_NaN());
  deepest_.resize(tracked_.size());
}

ColumnHazard::Column ColumnHazard::column(std::size_t gc, const vof::VofBackend& s) const {
  Column out;
  const auto& a = s.alpha();
  const auto& u = s.velocity();
  const auto& p = s.pressure();
  double vol = 0, stress = 0;
  vof::Vec mom;
  int kept = 0;
  const int n = cols_.refinement * cols_.refinement;
  for (int q = 0; q < n; ++q) {
    const std::size_t col = cols_.sub_column(gc, q);
    if (cols_.cell(col, 0) < 0) continue;
    ++kept;
    int top = -1;
    for (int j = 0; j < cols_.layers; ++j) {
      const int c = cols_.cell(col, j);
      const double w = a[std::size_t(c)] * m_.volume[std::size_t(c)];
      vol += w;
      mom = mom + w * u[std::size_t(c)];
      if (a[std::size_t(c)] >= 0.5) top = c;
    }
    if (top >= 0) out.surface_speed = std::max(out.surface_speed, norm(u[std::size_t(top)]));
    // The ground cell's pressure less the air column's weight above it (the top cell's pressure and
    // the air between the two centres).
    const int c0 = cols_.cell(col, 0), cn = cols_.cell(col, cols_.layers - 1);
    stress += p[std::size_t(c0)] - p[std::size_t(cn)] - set_.rho_air * 9.81 * (m_.centre[std::size_t(cn)].y - m_.centre[std::size_t(c0)].y);
  }
  if (kept == 0) return out;
  out.depth = vol / (n * cols_.plan_area) * cos_[gc];
  if (vol > 0) out.speed = norm(mom) / vol;
  out.ground_stress = stress / kept;
  return out;
}

Profile ColumnHazard::profile(std::size_t col, const vof::VofBackend& s) const {
  Profile p;
  for (int j = 0; j < cols_.layers; ++j) {
    const int c = cols_.cell(col, j);
    if (c < 0) continue;  // inside a structure
    p.height.push_back(0.5 * (cols_.levels[std::size_t(j)] + cols_.levels[std::size_t(j) + 1]));
    p.alpha.push_back(s.alpha()[std::size_t(c)]);
    p.speed.push_back(norm(s.velocity()[std::size_t(c)]));
  }
  return p;
}

void ColumnHazard::update(double t, const vof::VofBackend& s) {
  const std::size_t n = cols_.grid_cells();
  for (std::size_t col = 0; col < n; ++col) {
    const Column c = column(col, s);  // zero where no column of the cell is meshed
    hz_.max_depth[col] = std::max(hz_.max_depth[col], c.depth);
    if (c.depth > set_.flow_threshold) {
      hz_.max_speed[col] = std::max(hz_.max_speed[col], c.speed);
      hz_.max_pressure[col] = std::max(hz_.max_pressure[col], set_.rho * c.speed * c.speed);
      max_surface_[col] = std::max(max_surface_[col], c.surface_speed);
      max_stress_[col] = std::max(max_stress_[col], c.ground_stress);
      if (std::isnan(hz_.arrival_time[col])) hz_.arrival_time[col] = t;
    }
  }
  for (std::size_t q = 0; q < tracked_.size(); ++q) {
    const Tracked& tr = tracked_[q];
    const double d = column(tr.grid_cell, s).depth;
    if (d > set_.flow_threshold && !(hz_.max_depth[tr.grid_cell] > d)) {
      deepest_t_[q] = t;
      deepest_[q] = profile(tr.column, s);
    }
  }
}

std::vector<double> ColumnHazard::depth(const vof::VofBackend& s) const {
  std::vector<double> d(cols_.grid_cells(), 0.0);
  for (std::size_t col = 0; col < d.size(); ++col) d[col] = column(col, s).depth;
  return d;
}

void ColumnHazard::finish(const vof::VofBackend& s) { hz_.final_depth = depth(s); }

void ColumnHazard::save(VofCheckpoint& cp) const {
  cp.series["max_depth"] = hz_.max_depth;
  cp.series["max_speed"] = hz_.max_speed;
  cp.series["max_pressure"] = hz_.max_pressure;
  cp.series["arrival_time"] = hz_.arrival_time;
  cp.series["max_surface_speed"] = max_surface_;
  cp.series["max_ground_stress"] = max_stress_;
  cp.series["deepest_time"] = deepest_t_;
  for (std::size_t q = 0; q < tracked_.size(); ++q) {
    const std::string k = "deepest_" + std::to_string(q);
    cp.series[k + "_alpha"] = deepest_[q].alpha;
    cp.series[k + "_speed"] = deepest_[q].speed;
  }
}

void ColumnHazard::restore(const VofCheckpoint& cp, const std::string& path) {
  auto take = [&](const char* name, std::vector<double>& into, std::size_t n) {
    auto it = cp.series.find(name);
    if (it == cp.series.end() || it->second.size() != n)
      throw ScenarioError("checkpoint " + path + ": its hazard map " + name + " is missing or of another grid");
    into = it->second;
  };
  const std::size_t n = cols_.grid_cells();
  take("max_depth", hz_.max_depth, n);
  take("max_speed", hz_.max_speed, n);
  take("max_pressure", hz_.max_pressure, n);
  take("arrival_time", hz_.arrival_time, n);
  take("max_surface_speed", max_surface_, n);
  take("max_ground_stress", max_stress_, n);
  take("deepest_time", deepest_t_, tracked_.size());
  for (std::size_t q = 0; q < tracked_.size(); ++q) {
    const std::string k = "deepest_" + std::to_string(q);
    Profile& p = deepest_[q];
    p = {};
    if (std::isnan(deepest_t_[q])) continue;
    take((k + "_alpha").c_str(), p.alpha, std::size_t(cols_.layers));
    take((k + "_speed").c_str(), p.speed, std::size_t(cols_.layers));
    for (int j = 0; j < cols_.layers; ++j) p.height.push_back(0.5 * (cols_.levels[std::size_t(j)] + cols_.levels[std::size_t(j) + 1]));
  }
}

}  // namespace runout::jobs::vof_terrain
