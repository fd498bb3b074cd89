#include "jobs/drivers/vof_lab/monitors.hpp"

#include <algorithm>
#include <cmath>

#include "engine/vof/loads.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::vof_lab {

namespace vof = engine::vof;
constexpr double kPi = 3.14159265358979323846;

double median_between(const std::vector<double>& t, const std::vector<double>& v, double a, double b) {
  std::vector<double> w;
  for (std::size_t q = 0; q < t.size() && q < v.size(); ++q)
    if (t[q] >= a && t[q] <= b && std::isfinite(v[q])) w.push_back(v[q]);
  if (w.empty()) return double(NAN);
  std::nth_element(w.begin(), w.begin() + long(w.size() / 2), w.end());
  return w[w.size() / 2];
}

namespace {
// Plane set-ups: as in the 10 cm channel; 3D: the modelled width.
double per_width(const LabGrid& g) { return g.three_d ? 1.0 : 0.1 / g.width; }
}  // namespace

// ---- outflow ----

OutflowMonitor::OutflowMonitor(const LabSetup& su, double end_time) : per_width_(per_width(su.g)), end_time_(end_time) {
  for (const auto& p : su.m.patches)
    if (p.name.rfind("right", 0) == 0)
      for (int f = p.start; f < p.start + p.size; ++f) faces_.push_back(f);
}

void OutflowMonitor::sample(double, const vof::VofBackend& s) {
  double sum = 0;
  for (int f : faces_) sum += s.granular_flux()[std::size_t(f)];
  q.push_back(1000 * sum * per_width_);
}

void OutflowMonitor::write(v1::Monitors& rec, const std::vector<double>& t) const {
  // The outflow's plateau: the median over the second half of the run.
  rec.set_outflow_median_second_half_l_s_10cm(median_between(t, q, 0.5 * end_time_, 1e300));
  for (double v : q) rec.add_outflow_l_s_10cm(v);
}

// ---- gate ----

GateMonitor::GateMonitor(const LabSetup& su, const v1::Lab& L)
    : su_(su),
      column_((0 > L.x_min() && 0 < L.x_max()) ? std::clamp(int((0 - su.g.x0) / su.g.dx + 1e-9), 0, su.g.nx - 1) : -1),
      per_width_(per_width(su.g)),
      end_time_(L.end_time_s()) {
  const auto& m = su.m;
  for (int f = 0; f < m.n_internal; ++f)  // internal faces on the line x = 0, normal along x
    if (std::abs(m.Cf[std::size_t(f)].x) < 0.25 * su.g.dx && std::abs(m.Sf[std::size_t(f)].x) > 0.5 * m.magSf[std::size_t(f)])
      faces_.push_back(f);
}

void GateMonitor::sample(double, const vof::VofBackend& s) {
  const auto& m = su_.m;
  const auto& g = su_.g;
  double qg = 0;
  for (int f : faces_) qg += (m.Sf[std::size_t(f)].x > 0 ? 1 : -1) * s.granular_flux()[std::size_t(f)];
  flux.push_back(faces_.empty() ? NAN : 1000 * qg * per_width_);
  double sr = NAN;
  if (column_ >= 0) {
    double sy = 0, su = 0, syy = 0, syu = 0, n = 0;
    for (int jj = 0; jj < g.ny; ++jj) {
      const int cc = g.id(column_, jj, g.kc);
      if (cc < 0) continue;
      const auto k = std::size_t(cc);
      if (s.alpha()[k] <= 0.5) continue;
      const double y = g.y0 + (jj + 0.5) * g.dy, u = s.velocity()[k].x;
      sy += y, su += u, syy += y * y, syu += y * u, n += 1;
    }
    if (n >= 3) sr = (n * syu - sy * su) / (n * syy - sy * sy);
  }
  strain.push_back(sr);
}

void GateMonitor::write(v1::Monitors& rec, const std::vector<double>& t) const {
  rec.set_gate_flux_median_second_half_l_s_10cm(median_between(t, flux, 0.5 * end_time_, 1e300));
  for (double v : flux) rec.add_gate_flux_l_s_10cm(v);
  for (double v : strain) rec.add_gate_strain_rate_1_s(v);
}

// ---- moving share ----

void MovingShareMonitor::sample(double t, const vof::VofBackend& s) {
  double mat = 0, moving = 0;
  const auto n = s.alpha().size();
  for (std::size_t k = 0; k < n; ++k)
    if (s.alpha()[k] > 0.5) {
      mat += 1;
      if (vof::norm(s.velocity()[k]) > 0.01) moving += 1;
    }
  share.push_back(mat > 0 ? moving / mat : NAN);
  if (t_fluid < 0 && mat > 0 && moving >= 0.99 * mat) t_fluid = t;
}

void MovingShareMonitor::write(v1::Monitors& rec, const std::vector<double>&) const {
  rec.set_fluidised_time_s(t_fluid >= 0 ? t_fluid : NAN);
  for (double v : share) rec.add_moving_share(v);
}

// ---- shock ----

ShockMonitor::ShockMonitor(const LabSetup& su, const v1::Lab& L)
    : su_(su), end_wall_(su.has_inflow), x_max_(L.x_max()), length_(L.x_max() - L.x_min()) {
  for (const auto& lb : L.boundaries()) end_wall_ &= lb.side() != "right";
  for (const auto& lb : L.boundaries())
    if (lb.kind() == "inflow") inflow_speed_ = std::max(inflow_speed_, lb.inflow_u0() + 0.5 * lb.inflow_dudy() * lb.inflow_height());
}

void ShockMonitor::sample(double, const vof::VofBackend& s) {
  if (!end_wall_) return;
  const auto& g = su_.g;
  int i = g.nx - 1;
  for (; i >= 0; --i) {
    double depth = 0, flux = 0;
    for (int jj = 0; jj < g.ny; ++jj)
      if (const int c2 = g.id(i, jj, g.kc); c2 >= 0) {
        const double a = std::clamp(s.alpha()[std::size_t(c2)], 0.0, 1.0) * g.dy;
        depth += a;
        flux += a * vof::norm(s.velocity()[std::size_t(c2)]);
      }
    if (depth < 2 * g.dy || flux >= std::max(0.5 * inflow_speed_, 0.05) * depth) break;  // at least 5 cm/s
  }
  x.push_back(i < g.nx - 1 ? g.x0 + (i + 1) * g.dx : NAN);
}

void ShockMonitor::write(v1::Monitors& rec, const std::vector<double>& t) const {
  if (!end_wall_) return;
  // The shock's speed upstream: least-squares slope of its position over the samples that lie
  // between 0.1 m from the end wall and 80 % of the channel (clear of the corner and the inflow).
  double st = 0, sx = 0, stt = 0, stx = 0, n = 0, formed = NAN;
  for (std::size_t q = 0; q < t.size(); ++q) {
    const double xs = x[q];
    if (std::isnan(xs)) continue;
    if (std::isnan(formed)) formed = t[q];
    const double d = x_max_ - xs;
    if (d < 0.1 || d > 0.8 * length_) continue;
    st += t[q], sx += xs, stt += t[q] * t[q], stx += t[q] * xs, n += 1;
  }
  rec.set_shock_formed_s(formed);
  rec.set_shock_speed_upstream_m_s(n >= 3 ? -(n * stx - st * sx) / (n * stt - st * st) : NAN);
  rec.set_shock_samples_in_fit(int(n));
  for (double v : x) rec.add_shock_x_m(v);
}

// ---- surface angle ----

SurfaceAngleMonitor::SurfaceAngleMonitor(const LabSetup& su, const v1::Lab& L, double every)
    : su_(su),
      rotating_(L.rotation_period_s() > 0),
      centre_{0.5 * (L.x_min() + L.x_max()), 0.5 * (L.y_min() + L.y_max()), 0},
      period_(L.rotation_period_s()),
      every_(every) {}

void SurfaceAngleMonitor::sample(double t, const vof::VofBackend& s) {
  if (!rotating_) return;
  const auto& m = su_.m;
  double n = 0, mx = 0, my = 0, sxx = 0, sxy = 0, syy = 0;
  for (int f = 0; f < m.n_internal; ++f) {
    const int o = m.owner[std::size_t(f)], nb = m.neighbour[std::size_t(f)];
    const double ao = s.alpha()[std::size_t(o)], an = s.alpha()[std::size_t(nb)];
    if ((ao - 0.5) * (an - 0.5) >= 0) continue;
    const double w = (0.5 - ao) / (an - ao);
    const vof::Vec& po = m.centre[std::size_t(o)];
    const vof::Vec& pn = m.centre[std::size_t(nb)];
    const double x = po.x + w * (pn.x - po.x), y = po.y + w * (pn.y - po.y);
    if (std::hypot(x - centre_.x, y - centre_.y) > 0.05) continue;
    n += 1, mx += x, my += y, sxx += x * x, sxy += x * y, syy += y * y;
  }
  if (n < 3) {
    angle.push_back(NAN);
    layer.push_back(NAN);
    return;
  }
  mx /= n, my /= n;
  const double cxx = sxx / n - mx * mx, cxy = sxy / n - mx * my, cyy = syy / n - my * my;
  const double dir = 0.5 * std::atan2(2 * cxy, cxx - cyy);  // the principal axis
  layer.push_back(flowing_layer(s, mx, my, dir));
  const vof::Vec gv = su_.config.gravity(t);
  const double horizontal = std::atan2(gv.y, gv.x) + 0.5 * kPi;
  double d = std::fmod(std::abs(dir - horizontal), kPi);
  if (d > 0.5 * kPi) d = kPi - d;
  angle.push_back(d * 180 / kPi);
}

// The flowing layer's thickness at the centre (the rigid bulk is at rest on the fixed mesh, the box
// turning gravity): along the surface line's normal into the sand, the deepest sand cell within 2 cm
// of the normal through the points' centroid that moves faster than 10 % of the fastest there and
// 5 mm/s, plus half a cell (the reference method's measure, validation.md B1).
double SurfaceAngleMonitor::flowing_layer(const vof::VofBackend& s, double mx, double my, double dir) const {
  const auto& m = su_.m;
  double nx = -std::sin(dir), ny = std::cos(dir), sgn = 0;
  for (int c = 0; c < m.cells(); ++c) {
    const vof::Vec& p = m.centre[std::size_t(c)];
    sgn += (s.alpha()[std::size_t(c)] - 0.5) * ((p.x - mx) * nx + (p.y - my) * ny);
  }
  if (sgn > 0) nx = -nx, ny = -ny;  // the normal points into the air
  double fastest = 0;
  std::vector<std::pair<double, double>> col;  // (depth, speed)
  for (int c = 0; c < m.cells(); ++c) {
    if (s.alpha()[std::size_t(c)] <= 0.5) continue;
    const vof::Vec& p = m.centre[std::size_t(c)];
    const double depth = -((p.x - mx) * nx + (p.y - my) * ny), along = std::abs((p.x - mx) * ny - (p.y - my) * nx);
    if (along >= 0.02 || depth <= -0.004) continue;
    const vof::Vec& u = s.velocity()[std::size_t(c)];
    const double speed = std::hypot(u.x, u.y);
    col.emplace_back(depth, speed);
    fastest = std::max(fastest, speed);
  }
  if (col.empty()) return NAN;
  double deepest = -HUGE_VAL;
  for (const auto& [depth, speed] : col)
    if (speed > 0.1 * fastest && speed > 0.005) deepest = std::max(deepest, depth);
  return std::isfinite(deepest) ? deepest + 0.5 * su_.g.dx : 0.0;
}

void SurfaceAngleMonitor::write(v1::Monitors& rec, const std::vector<double>& t) const {
  if (!rotating_) return;
  // Once the material flows (after the first quarter of the samples that pass 90 % of the peak
  // angle): the mean and spread of the surface angle, and its mean over each quarter turn (the
  // box's 90 deg symmetry: a periodic response repeats every quarter turn).
  double peak_angle = 0;
  for (double a : angle)
    if (!std::isnan(a)) peak_angle = std::max(peak_angle, a);
  double onset = NAN;
  for (std::size_t q = 0; q < t.size(); ++q)
    if (!std::isnan(angle[q]) && angle[q] >= 0.9 * peak_angle) {
      onset = t[q];
      break;
    }
  const double quarter = 0.25 * period_;
  double sum_a = 0, sum_aa = 0, cnt = 0, sum_layer = 0, n_layer = 0;
  std::vector<double> qsum(64, 0.0), qn(64, 0.0);
  for (std::size_t q = 0; q < t.size(); ++q) {
    if (std::isnan(onset) || t[q] < onset + 0.25 * quarter || std::isnan(angle[q])) continue;
    sum_a += angle[q], sum_aa += angle[q] * angle[q], cnt += 1;
    if (!std::isnan(layer[q])) sum_layer += layer[q], n_layer += 1;
    const auto k = std::min<std::size_t>(63, std::size_t(t[q] / quarter));
    qsum[k] += angle[q], qn[k] += 1;
  }
  const double mean = cnt > 0 ? sum_a / cnt : NAN;
  rec.set_surface_angle_onset_s(onset);
  rec.set_surface_angle_mean_deg(mean);
  rec.set_surface_angle_std_deg(cnt > 1 ? std::sqrt(std::max(0.0, sum_aa / cnt - mean * mean)) : NAN);
  for (std::size_t k = 0; k < qsum.size(); ++k)
    if (qn[k] >= 0.5 * quarter / every_) rec.add_surface_angle_quarter_turn_means_deg(qsum[k] / qn[k]);  // sampled for half a quarter turn
  for (double v : angle) rec.add_surface_angle_deg(v);
  rec.set_flowing_layer_mean_m(n_layer > 0 ? sum_layer / n_layer : NAN);
  for (double v : layer) rec.add_flowing_layer_m(v);
}

// ---- the collection ----

// ---- the obstacles' load ----

ObstacleLoadMonitor::ObstacleLoadMonitor(const LabSetup& su, double end_time) : end_time_(end_time) {
  for (const auto& p : su.m.patches)
    if (p.name == "obstacle") enabled_ = p.size > 0;
}

void ObstacleLoadMonitor::sample(double, const vof::VofBackend& s) {
  if (!enabled_) return;
  const vof::PatchLoad l = vof::patch_load(s, "obstacle");
  area_ = l.area;
  fx.push_back(l.force.x);
  fy.push_back(l.force.y);
  fz.push_back(l.force.z);
  pmax.push_back(l.max_pressure);
}

void ObstacleLoadMonitor::write(v1::Monitors& rec, const std::vector<double>& t) const {
  if (!enabled_ || fx.empty()) return;
  auto* o = rec.mutable_obstacle_load();
  o->set_area_m2(area_);
  double impulse = 0;
  for (std::size_t q = 0; q < fx.size() && q < t.size(); ++q) {
    const double f = std::sqrt(fx[q] * fx[q] + fy[q] * fy[q] + fz[q] * fz[q]);
    if (f > o->peak_force_n()) {
      o->set_peak_force_n(f);
      o->set_peak_force_time_s(t[q]);
    }
    if (q > 0) impulse += 0.5 * (fx[q] + fx[q - 1]) * (t[q] - t[q - 1]);
    o->set_max_pressure_pa(std::max(o->max_pressure_pa(), pmax[q]));
    o->add_force_x_n(fx[q]);
    o->add_force_y_n(fy[q]);
    o->add_force_z_n(fz[q]);
    o->add_max_pressure_series_pa(pmax[q]);
  }
  o->set_impulse_x_n_s(impulse);
  o->set_force_x_median_second_half_n(median_between(t, fx, 0.5 * end_time_, 1e300));
  o->set_force_y_median_second_half_n(median_between(t, fy, 0.5 * end_time_, 1e300));
  o->set_force_z_median_second_half_n(median_between(t, fz, 0.5 * end_time_, 1e300));
}

namespace {
double monitor_interval(const v1::Lab& L) { return std::min(0.01, L.end_time_s() / 50); }
}  // namespace

LabMonitors::LabMonitors(const LabSetup& su, const v1::Lab& L, double t_start)
    : outflow(su, L.end_time_s()),
      gate(su, L),
      shock(su, L),
      surface(su, L, monitor_interval(L)),
      obstacle(su, L.end_time_s()),
      every_(monitor_interval(L)),
      next_(t_start + monitor_interval(L)) {}

std::vector<Monitor*> LabMonitors::all() { return {&surface, &outflow, &gate, &moving, &shock, &obstacle}; }

void LabMonitors::after_step(double time, const vof::VofBackend& s) {
  if (time < next_ - 1e-12) return;
  for (Monitor* m : all()) m->sample(time, s);
  t.push_back(time);
  next_ += every_;
}

void LabMonitors::save(VofCheckpoint& cp) {
  cp.series["t"] = t;
  for (Monitor* m : all())
    for (auto [name, v] : m->series()) cp.series[name] = *v;
  cp.figures["t_fluid"] = moving.t_fluid;
  cp.figures["next_mon"] = next_;
}

void LabMonitors::restore(const VofCheckpoint& cp, const std::string& path) {
  std::vector<std::pair<const char*, std::vector<double>*>> all_series = {{"t", &t}};
  for (Monitor* m : all())
    if (m != &obstacle || obstacle.enabled())  // a set-up without obstacles may continue a checkpoint without their series
      for (auto s : m->series()) all_series.push_back(s);
  for (auto [name, v] : all_series) {
    const auto it = cp.series.find(name);
    if (it == cp.series.end()) throw ScenarioError("checkpoint " + path + ": damaged (no series '" + name + "')");
    *v = it->second;
  }
  const auto tf = cp.figures.find("t_fluid"), nm = cp.figures.find("next_mon");
  if (tf == cp.figures.end() || nm == cp.figures.end()) throw ScenarioError("checkpoint " + path + ": damaged (no monitor times)");
  moving.t_fluid = tf->second;
  next_ = nm->second;
}

void LabMonitors::write(v1::RunRecord& rec) const {
  auto* mo = rec.mutable_monitors();
  for (double v : t) mo->add_t_s(v);
  for (const Monitor* m : std::vector<const Monitor*>{&moving, &outflow, &gate, &surface, &shock, &obstacle}) m->write(*mo, t);
}

}  // namespace runout::jobs::vof_lab
