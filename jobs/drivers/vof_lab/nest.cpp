#include "jobs/drivers/vof_lab/nest.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>

#include "engine/sh1d.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::vof_lab {

namespace {

namespace vof = engine::vof;
constexpr double kPi = 3.14159265358979323846;

double cell_dx(const v1::Lab& L) { return (L.x_max() - L.x_min()) / L.nx(); }

// The left side's inflow (the scenario's checks make it the one boundary on the left).
int left_inflow(const v1::Lab& L) {
  for (int k = 0; k < L.boundaries_size(); ++k)
    if (L.boundaries(k).side() == "left" && L.boundaries(k).kind() == "inflow") return k;
  throw ScenarioError("lab.nest: needs the whole left side an inflow");
}

// delta where the bottom is a Coulomb condition, else phi (a stick wall carries at most tan(phi) p).
double bed_friction_deg(const v1::Lab& L, const Material& mat) {
  for (const auto& b : L.boundaries())
    if (b.side() == "bottom" && (b.kind() == "coulomb-slip" || b.kind() == "coulomb-friction")) return mat.delta_deg;
  return mat.phi_deg;
}

}  // namespace

void FaceRecord::at(double time, double& depth, double& speed) const {
  depth = speed = 0;
  if (t.empty() || time <= t.front()) return;
  if (time >= t.back()) {
    depth = h.back(), speed = u.back();
    return;
  }
  const std::size_t k = std::size_t(std::upper_bound(t.begin(), t.end(), time) - t.begin());  // t[k-1] <= time < t[k]
  const double a = (time - t[k - 1]) / (t[k] - t[k - 1]);
  depth = h[k - 1] + a * (h[k] - h[k - 1]);
  speed = u[k - 1] + a * (u[k] - u[k - 1]);
}

double FaceRecord::volume_until(double time) const {
  double v = 0;
  for (std::size_t k = 1; k < t.size() && t[k - 1] < time; ++k) {
    const double t1 = std::min(t[k], time), a = (t1 - t[k - 1]) / (t[k] - t[k - 1]);
    const double q0 = h[k - 1] * u[k - 1], q1 = h[k - 1] * u[k - 1] + a * (h[k] * u[k] - h[k - 1] * u[k - 1]);
    v += 0.5 * (q0 + q1) * (t1 - t[k - 1]);
  }
  return v * width;
}

double FaceRecord::max_speed() const {
  double m = 0;
  for (const double s : u) m = std::max(m, std::abs(s));
  return m;
}

v1::Lab nest_part(const v1::Lab& L) {
  v1::Lab p = L;
  const LabNestFace face = lab_nest_face(L);
  p.set_x_min(face.x);
  p.set_nx(face.cells);
  p.clear_nest();
  return p;
}

FaceRecord record_face(const v1::Lab& L, const Material& mat) {
  namespace e = engine;
  const auto& in = L.boundaries(left_inflow(L));
  FaceRecord rec;
  rec.x = nest_part(L).x_min();
  rec.width = L.nz() > 0 ? L.z_max() - L.z_min() : cell_dx(L);
  rec.bed_friction_deg = bed_friction_deg(L, mat);
  // Four cells of the depth-averaged run to one of the lab's along x.
  rec.cells = 4 * L.nx();
  const auto ch = e::Channel1D::uniform(rec.cells, (L.x_max() - L.x_min()) / rec.cells, L.x_min(), L.inclination_deg() * kPi / 180);
  e::Sh1dConfig cfg;
  cfg.material.density = mat.rho;
  cfg.material.phi = mat.phi_deg * kPi / 180;
  cfg.material.delta = rec.bed_friction_deg * kPi / 180;
  cfg.material.earth_pressure = e::EarthPressure::unity;
  cfg.time.t_end = L.end_time_s();
  cfg.left = e::Boundary1D::inflow;
  cfg.right = e::Boundary1D::outflow;
  cfg.inflow.t = {0.0};
  cfg.inflow.h = {in.inflow_height()};
  cfg.inflow.u = {in.inflow_u0() + 0.5 * in.inflow_dudy() * in.inflow_height()};  // the profile's mean
  cfg.gauge.xi = rec.x;
  cfg.gauge.record = [&rec](double t, double h, double u) {
    rec.t.push_back(t);
    rec.h.push_back(h);
    rec.u.push_back(u);
  };
  e::Sh1dState s0;
  s0.h.assign(std::size_t(rec.cells), 0.0);
  s0.m.assign(std::size_t(rec.cells), 0.0);
  try {
    const auto r = e::run_sh1d(ch, cfg, s0);
    rec.steps = r.steps;
    rec.wall_s = r.wall_seconds;
  } catch (const std::invalid_argument& ex) {
    throw ScenarioError(std::string("lab.nest: the depth-averaged run of the chute: ") + ex.what());
  }
  return rec;
}

void attach_face(const FaceRecord& rec, const v1::Lab& part, const vof::Mesh& m, vof::VofConfig& c) {
  const std::string name = "left-" + std::to_string(left_inflow(part));
  if (m.patch_index(name) < 0) throw ScenarioError("lab.nest: the 3D run's mesh has no upstream side");
  const double dy = (part.y_max() - part.y_min()) / part.ny();
  const vof::Patch& p = m.patch(name);
  std::vector<double> lo(std::size_t(p.size));  // each face's lower edge above the bed
  for (int q = 0; q < p.size; ++q) lo[std::size_t(q)] = m.Cf[std::size_t(p.start + q)].y - 0.5 * dy - part.y_min();
  auto r = std::make_shared<const FaceRecord>(rec);
  vof::PatchBc bc;
  bc.type = "nest_inflow";
  bc.timed_inflow = [r, lo, dy, start = p.start](int f, double t0, double t1, vof::Vec& U, double& alpha) {
    double h = 0, u = 0;
    r->at(0.5 * (t0 + t1), h, u);
    alpha = std::clamp((h - lo[std::size_t(f - start)]) / dy, 0.0, 1.0);
    if (!(alpha > 0 && u > 0)) return false;
    U = vof::Vec{u, 0, 0};
    return true;
  };
  c.bc[name] = bc;
  c.dt_max = std::min(c.dt_max, c.max_co * cell_dx(part) / std::max(1.0, rec.max_speed()));
}

void FaceBalance::step(const vof::VofBackend& s, double dt) {
  const vof::Mesh& m = s.mesh();
  for (int f = m.n_internal; f < m.faces(); ++f) {
    const double q = s.granular_flux()[std::size_t(f)] * dt;
    if (q < 0) in -= q;
    else out += q;
  }
}

void write_nest(const FaceRecord& rec, const FaceBalance& bal, double v_final, double t, int mesh_cells, double dx, v1::NestResult& out) {
  const double da = rec.volume_until(t);
  out.set_mesh_cells(mesh_cells);
  out.set_column_width_m(dx);
  out.set_recorded_steps(int(rec.steps));
  out.set_inflow_depth_averaged_m3(da);
  out.set_inflow_3d_m3(bal.in);
  out.set_inflow_relative_difference(da > 0 ? std::abs(bal.in - da) / da : NAN);
  out.set_volume_error_3d(std::abs(v_final + bal.out - bal.in) / std::max(bal.in, 1e-300));
  char b[200];
  std::snprintf(b, sizeof b, "3D on x >= %.4f m; the chute above on the depth-averaged engine (1D, %d cells, bed friction %.1f deg)", rec.x,
                rec.cells, rec.bed_friction_deg);
  out.set_maps(b);
}

void write_face_csv(const std::string& path, const FaceRecord& rec) {
  std::ofstream f(path);
  f << "time_s,depth_m,velocity_m_s,discharge_m2_s\n";
  char b[160];
  for (std::size_t k = 0; k < rec.t.size(); ++k) {
    std::snprintf(b, sizeof b, "%.6f,%.6e,%.6e,%.6e\n", rec.t[k], rec.h[k], rec.u[k], rec.h[k] * rec.u[k]);
    f << b;
  }
  if (!f) throw std::runtime_error(path + ": cannot write it");
}

}  // namespace runout::jobs::vof_lab
