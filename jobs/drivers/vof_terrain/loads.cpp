#include "jobs/drivers/vof_terrain/loads.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>

#include "engine/vof/loads.hpp"
#include "jobs/figures/load_plot.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::vof_terrain {

namespace vof = engine::vof;

StructureLoads::StructureLoads(const TerrainSetup& su, double interval) : su_(su), interval_(interval) {
  column_of_.assign(std::size_t(su.mesh.cells()), -1);
  layer_of_.assign(std::size_t(su.mesh.cells()), -1);
  for (std::size_t col = 0; col < su.columns.columns(); ++col)
    for (int j = 0; j < su.columns.layers; ++j)
      if (const int c = su.columns.cell(col, j); c >= 0) column_of_[std::size_t(c)] = int(col), layer_of_[std::size_t(c)] = j;
  for (const auto& name : su.structure_names) {
    Load l;
    l.name = name;
    l.patch = structure_patch(name);
    loads_.push_back(l);
  }
}

void StructureLoads::update(double t, double dt, const vof::VofBackend& s, const ColumnHazard& hazard) {
  const bool sample = t >= next_ - 1e-12;
  if (sample) next_ = t + interval_;
  const auto& m = s.mesh();
  for (auto& l : loads_) {
    const vof::PatchLoad pl = vof::patch_load(s, l.patch);
    // The engine's frame: x east, y up, z south.
    const double e = pl.force.x / 1000, n = -pl.force.z / 1000, u = pl.force.y / 1000, h = std::hypot(e, n);
    l.area = pl.area;
    l.impulse += 0.5 * (h + l.last_h) * dt;
    l.last_h = h;
    if (pl.max_pressure / 1000 > l.p_max) {
      l.p_max = pl.max_pressure / 1000;
      l.p_max_t = t;
      l.p_max_face = pl.max_face;
      const int o = m.owner[std::size_t(pl.max_face)], j = layer_of_[std::size_t(o)];
      const auto& lv = su_.columns.levels;  // the columns follow the ground: a wall face spans its layer, a roof lies under it
      const vof::Vec& S = m.Sf[std::size_t(pl.max_face)];
      const bool roof = std::abs(S.y) > 0.5 * m.magSf[std::size_t(pl.max_face)];
      l.p_max_height = roof ? lv[std::size_t(j)] : 0.5 * (lv[std::size_t(j)] + lv[std::size_t(j) + 1]);
    }
    if (h > l.peak) {
      l.peak = h, l.peak_t = t, l.peak_e = e, l.peak_n = n, l.peak_u = u;
      if (l.p_max_face >= 0) {  // the column in front of the face with the highest pressure so far
        const Profile p = hazard.profile(std::size_t(column_of_[std::size_t(m.owner[std::size_t(l.p_max_face)])]), s);
        l.front_h = p.height, l.front_a = p.alpha, l.front_s = p.speed;
      }
    }
    if (sample) {
      l.t.push_back(t), l.east.push_back(e), l.north.push_back(n), l.up.push_back(u), l.p.push_back(pl.max_pressure / 1000);
    }
  }
}

void StructureLoads::save(VofCheckpoint& cp) const {
  cp.figures["loads_next"] = next_;
  for (std::size_t a = 0; a < loads_.size(); ++a) {
    const auto& l = loads_[a];
    const std::string k = "structure" + std::to_string(a) + "_";
    const double f[] = {l.peak, l.peak_t, l.peak_e, l.peak_n, l.peak_u, l.impulse, l.last_h, l.p_max, l.p_max_t, l.p_max_height, double(l.p_max_face)};
    cp.series[k + "figures"] = std::vector<double>(std::begin(f), std::end(f));
    cp.series[k + "t"] = l.t, cp.series[k + "east"] = l.east, cp.series[k + "north"] = l.north, cp.series[k + "up"] = l.up, cp.series[k + "p"] = l.p;
    cp.series[k + "front_h"] = l.front_h, cp.series[k + "front_a"] = l.front_a, cp.series[k + "front_s"] = l.front_s;
  }
}

void StructureLoads::restore(const VofCheckpoint& cp, const std::string& path) {
  if (loads_.empty()) return;
  if (!cp.figures.count("loads_next")) throw ScenarioError("checkpoint " + path + ": damaged (no structure loads)");
  next_ = cp.figures.at("loads_next");
  for (std::size_t a = 0; a < loads_.size(); ++a) {
    auto& l = loads_[a];
    const std::string k = "structure" + std::to_string(a) + "_";
    for (const char* part : {"figures", "t", "east", "north", "up", "p", "front_h", "front_a", "front_s"})
      if (!cp.series.count(k + part)) throw ScenarioError("checkpoint " + path + ": damaged (no loads of structure '" + l.name + "')");
    const auto& f = cp.series.at(k + "figures");
    if (f.size() != 11) throw ScenarioError("checkpoint " + path + ": damaged (the loads of structure '" + l.name + "')");
    l.peak = f[0], l.peak_t = f[1], l.peak_e = f[2], l.peak_n = f[3], l.peak_u = f[4], l.impulse = f[5], l.last_h = f[6];
    l.p_max = f[7], l.p_max_t = f[8], l.p_max_height = f[9], l.p_max_face = int(f[10]);
    l.t = cp.series.at(k + "t"), l.east = cp.series.at(k + "east"), l.north = cp.series.at(k + "north"), l.up = cp.series.at(k + "up");
    l.p = cp.series.at(k + "p");
    l.front_h = cp.series.at(k + "front_h"), l.front_a = cp.series.at(k + "front_a"), l.front_s = cp.series.at(k + "front_s");
  }
}

void loads_verdict(double column_width_m, StructureSummary& q) {
  const double depth = q.max_depth_next_m;
  q.column_width_m = column_width_m;
  q.loads_resolved = depth > 0 && column_width_m <= 0.25 * depth;
  char b[512];
  if (q.loads_resolved)
    std::snprintf(b, sizeof b, "columns %.3g m wide for a flow %.3g m deep next to it: the impact is resolved (at most a quarter of the depth)",
                  column_width_m, depth);
  else
    std::snprintf(b, sizeof b,
                  "not design values: columns %.3g m wide for a flow %.3g m deep next to it do not resolve the impact (they must be at most "
                  "a quarter of the depth, %.3g m); on wider columns the flow passes the wall's cells without stopping and the loads "
                  "grow as the columns shrink (validation.md D4)",
                  column_width_m, depth, 0.25 * depth);
  q.loads_note = b;
}

void StructureLoads::summarise(std::vector<StructureSummary>& out) const {
  for (const auto& l : loads_)
    for (auto& q : out) {
      if (q.name != l.name) continue;
      q.loads = true;
      q.peak_force_kn = l.peak, q.peak_force_time_s = l.peak_t;
      q.peak_force_east_kn = l.peak_e, q.peak_force_north_kn = l.peak_n, q.peak_force_up_kn = l.peak_u;
      q.impulse_kn_s = l.impulse, q.max_pressure_kpa = l.p_max, q.max_pressure_time_s = l.p_max_t;
      q.max_pressure_height_m = l.p_max_height, q.wall_area_m2 = l.area;
      q.front_height_m = l.front_h, q.front_alpha = l.front_a, q.front_speed_m_s = l.front_s;
      loads_verdict(su_.columns_mesh.dx, q);
    }
}

std::string StructureLoads::write_csv(const std::string& out_dir) const {
  const std::string name = "structure_loads.csv";
  std::ofstream f(out_dir + "/" + name);
  f << "time_s,structure,force_east_kn,force_north_kn,force_up_kn,force_horizontal_kn,max_pressure_kpa\n";
  char b[256];
  for (const auto& l : loads_)
    for (std::size_t q = 0; q < l.t.size(); ++q) {
      std::snprintf(b, sizeof b, "%.4f,\"%s\",%.4f,%.4f,%.4f,%.4f,%.4f\n", l.t[q], l.name.c_str(), l.east[q], l.north[q], l.up[q],
                    std::hypot(l.east[q], l.north[q]), l.p[q]);
      f << b;
    }
  if (!f) throw std::runtime_error(out_dir + "/" + name + ": cannot write it");
  return name;
}

std::vector<std::string> StructureLoads::write_plot(const std::string& out_dir, const std::string& title) const {
  figures::LoadPlot p;
  p.title = "Loads on the structures: " + title;
  p.note = "the pressure's force on walls and roof, horizontal part (the wall's shear is not included); every " +
           std::to_string(int(std::lround(interval_ * 1000))) + " ms";
  bool any = false;
  for (const auto& l : loads_) {
    figures::LoadPlot::Structure s{l.name, l.t, {}, l.p};
    for (std::size_t q = 0; q < l.t.size(); ++q) s.force_kn.push_back(std::hypot(l.east[q], l.north[q]));
    any = any || s.t.size() >= 2;
    p.structures.push_back(std::move(s));
  }
  if (!any) return {};
  figures::draw_load_plot(out_dir + "/structure_loads.png", out_dir + "/structure_loads.pdf", p);
  return {"structure_loads.png", "structure_loads.pdf"};
}

}  // namespace runout::jobs::vof_terrain
