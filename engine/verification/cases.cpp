#include "engine/verification/cases.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>

#include "engine/names.hpp"
#include "engine/sh1d.hpp"
#include "engine/sh2d.hpp"
#include "engine/verification/exact.hpp"
#include "engine/verification/vof_cases.hpp"

namespace runout::engine::verification {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<double> pick(const Options& o, std::vector<double> moderate, const std::vector<double>& finer) {
  if (!o.resolutions.empty()) return o.resolutions;
  if (o.full) moderate.insert(moderate.end(), finer.begin(), finer.end());
  return moderate;
}

std::string variant(const std::string& engine, const Options& o) {
  return engine + "-" + std::string(name_of(kLimiterNames, o.limiter));
}

/// Observed order between consecutive rows from the named error metric (rows sorted coarse to fine).
void fill_orders(std::vector<Row>& rows, const std::string& metric) {
  for (std::size_t k = 1; k < rows.size(); ++k) {
    const Metric* a = rows[k - 1].metric(metric);
    const Metric* b = rows[k].metric(metric);
    if (!a || !b || a->value <= 0 || b->value <= 0 || rows[k - 1].variant != rows[k].variant) continue;
    rows[k].order = std::log(a->value / b->value) / std::log(rows[k - 1].dx / rows[k].dx);
  }
}

/// Orders from `metric` between neighbouring rows, and the observed order over all rows (least-squares
/// slope of log(error) against log(dx): pairwise orders of tiny errors scatter) checked against
/// `min_order` as `name` on the finest row.
void check_order(std::vector<Row>& rows, const std::string& metric, const std::string& name, double min_order) {
  fill_orders(rows, metric);
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const auto& r : rows) {
    const Metric* m = r.metric(metric);
    if (!m || !(m->value > 0)) continue;
    const double x = std::log(r.dx), y = std::log(m->value);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    ++n;
  }
  if (n >= 2) rows.back().metrics.push_back({name, (n * sxy - sx * sy) / (n * sxx - sx * sx), min_order, false});
}

/// An inclined plane in map coordinates with cells of size ds along the slope (dx = ds cos zeta),
/// falling in +x; cell centre i lies at slope coordinate xs0 + (i + 1/2) ds.
Terrain2D plane(int nx, int ny, double ds, double dy, double zeta, double xs0, double y0) {
  Terrain2D t;
  t.nx = nx;
  t.ny = ny;
  t.dx = ds * std::cos(zeta);
  t.dy = dy;
  t.x0 = (xs0 + 0.5 * ds) * std::cos(zeta);
  t.y0 = y0 + 0.5 * dy;
  t.z.resize(t.cells());
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) t.z[std::size_t(j) * nx + i] = -std::tan(zeta) * (t.x0 + i * t.dx);
  return t;
}

Material coulomb(double delta_deg) {
  Material m;
  m.rheology = Rheology::coulomb;
  m.delta = delta_deg * kDeg;
  m.phi = std::max(delta_deg, 30.0) * kDeg;
  return m;
}

// ---------------------------------------------------------------- A1 dam break
std::vector<Row> case_a1(const Options& o) {
  const exact::DamBreak ex{22 * kDeg, 21 * kDeg, 1.0};
  const double t_end = 5.0, xa = -40, xb = 50;
  // The front is where the depth falls to a threshold, in the exact solution and in the run alike:
  // 0.1 m (10 % of h0, the depth hazard maps outline) is checked; 1 mm is reported. The exact tail
  // ahead of it is a degenerate rarefaction (h ~ (x_f - x)^2) that central schemes under-resolve,
  // so the 1 mm position lags (docs/verification.md).
  auto x_at = [&](double thr) {
    return t_end * (2 * ex.c0() + 0.5 * ex.m() * t_end - 3 * std::sqrt(ex.g * std::cos(ex.zeta) * thr));
  };
  auto front_of = [&](const std::vector<double>& h, double x0, double dx, double thr) {
    for (int i = int(h.size()) - 2; i >= 0; --i)
      if (h[i] > thr) {
        const double f = (h[i] - thr) / (h[i] - h[i + 1]);
        return x0 + (i + 0.5 + f) * dx;
      }
    return x0;
  };
  std::vector<Row> rows;
  for (const bool two_d : {false, true}) {
    const auto res = two_d ? pick(o, {1.0, 0.5, 0.25}, {0.125}) : pick(o, {2.0, 1.0, 0.5, 0.25}, {0.125, 0.0625});
    for (double ds : res) {
      const auto t0 = std::chrono::steady_clock::now();
      const int n = int(std::lround((xb - xa) / ds));
      std::vector<double> h(n), xc(n);
      Row row;
      row.case_id = "A1";
      row.dx = ds;
      double mass0 = 0, mass1 = 0;
      if (!two_d) {
        auto ch = Channel1D::uniform(n, ds, xa, ex.zeta);
        Sh1dConfig cfg;
        cfg.material = coulomb(21);
        cfg.limiter = o.limiter;
        cfg.time.t_end = t_end;
        Sh1dState s;
        s.h.resize(n);
        s.m.assign(n, 0);
        for (int i = 0; i < n; ++i) s.h[i] = ch.centre(i) <= 0 ? ex.h0 : 0.0;
        const auto r = run_sh1d(ch, cfg, s);
        row.cell_updates = double(r.steps) * n;
        h = r.state.h;
        for (int i = 0; i < n; ++i) xc[i] = ch.centre(i);
        row.variant = variant("1d", o);
        row.cells = n;
      } else {
        const int ny = 3;
        auto terr = plane(n, ny, ds, 1.0, ex.zeta, xa, 0);
        Sh2dConfig cfg;
        cfg.material = coulomb(21);
        cfg.limiter = o.limiter;
        cfg.time.t_end = t_end;
        cfg.south = cfg.north = Boundary2D::wall;
        std::vector<double> h0(terr.cells());
        for (int j = 0; j < ny; ++j)
          for (int i = 0; i < n; ++i) h0[std::size_t(j) * n + i] = xa + (i + 0.5) * ds <= 0 ? ex.h0 : 0.0;
        const auto r = run_sh2d(terr, cfg, state_from_normal_depth(terr, h0));
        row.cell_updates = r.diag.cell_updates;
        for (int i = 0; i < n; ++i) {
          h[i] = r.hazard.final_depth[std::size_t(1) * n + i];
          xc[i] = xa + (i + 0.5) * ds;
        }
        row.variant = variant("2d", o);
        row.cells = long(n) * ny;
      }
      double e1 = 0, s1 = 0;
      for (int i = 0; i < n; ++i) {
        double he, ue;
        ex.at(xc[i], t_end, he, ue);
        e1 += std::abs(h[i] - he);
        s1 += he;
      }
      (void)mass0;
      (void)mass1;
      const double front = front_of(h, xa, ds, 0.1), front_thin = front_of(h, xa, ds, 1e-3);
      const bool target = std::abs(ds - 0.25) < 1e-9 || ds < 0.25;
      row.metrics.push_back({"L1_rel_depth", e1 / s1, target ? 0.01 : kNaN});
      row.metrics.push_back({"front_err_cells", std::abs(front - x_at(0.1)) / ds, target ? 2.0 : kNaN});
      row.metrics.push_back({"front_m", front});
      row.metrics.push_back({"front_1mm_lag_m", x_at(1e-3) - front_thin});
      row.wall_s = seconds_since(t0);
      rows.push_back(row);
    }
  }
  fill_orders(rows, "L1_rel_depth");
  return rows;
}

// ---------------------------------------------------------------- A2 parabolic cap
// Compared at t = 5 s: later, a smooth wiggle grows at the cap's crest (amplitude ~1e-3 of the depth
// by t = 10 s, every limiter) and the observed order becomes erratic (docs/verification.md).
std::vector<Row> case_a2(const Options& o) {
  const exact::ParabolicCap ex{35 * kDeg, 25 * kDeg, 1.0, 80.0, 4.0, 0.0};
  const double t_end = 5.0, xa = -90, xb = 150;
  std::vector<Row> rows;
  for (double across : pick(o, {100, 200, 400}, {800})) {
    const auto t0 = std::chrono::steady_clock::now();
    const double ds = 2 * ex.L0 / across;
    const int n = int(std::lround((xb - xa) / ds));
    auto ch = Channel1D::uniform(n, ds, xa, ex.zeta);
    Sh1dConfig cfg;
    cfg.material = coulomb(25);
    cfg.limiter = o.limiter;
    cfg.time.t_end = t_end;
    cfg.left = cfg.right = Boundary1D::wall;
    Sh1dState s;
    s.h.resize(n);
    s.m.assign(n, 0);
    for (int i = 0; i < n; ++i) {
      double h, u;
      ex.at(ch.centre(i), 0, h, u);
      s.h[i] = h;
    }
    const auto r = run_sh1d(ch, cfg, s);
    const double L = ex.half_length(t_end), xc = ex.centre(t_end);
    double e_all = 0, s_all = 0, e_in = 0, s_in = 0;
    for (int i = 0; i < n; ++i) {
      double he, ue;
      ex.at(ch.centre(i), t_end, he, ue);
      const double e = std::abs(r.state.h[i] - he);
      e_all += e;
      s_all += he;
      if (std::abs((ch.centre(i) - xc) / L) < 0.8) {
        e_in += e;
        s_in += he;
      }
    }
    Row row;
    row.case_id = "A2";
    row.variant = variant("1d", o);
    row.cells = n;
    row.dx = ds;
    const bool target = across >= 400 - 1e-9;
    row.metrics.push_back({"L1_rel_depth", e_all / s_all, target ? 0.005 : kNaN});
    row.metrics.push_back({"L1_rel_depth_core", e_in / s_in});
    row.metrics.push_back({"mass_rel_err", std::abs(r.mass_final - r.mass_initial) / r.mass_initial, 1e-12});
    row.metrics.push_back({"cells_across_cap", across});
    row.wall_s = seconds_since(t0);
    rows.push_back(row);
  }
  // The observed order away from the margins must reach 1.5 on the finest pair.
  check_order(rows, "L1_rel_depth_core", "order_core", 1.5);
  return rows;
}

// ---------------------------------------------------------------- A3 elliptic cap (2D)
// The similarity solution takes the friction along the slope's fall line (|u| ~ u), which is exact
// only without friction: with delta = 25 deg its own error is a few tenths of a percent, so the L1
// error against it levels off near 0.5 %. The figures of the issue (centre, depth, half-axes) are
// checked on that case; the frictionless run checks the convergence order.
std::vector<Row> case_a3(const Options& o) {
  std::vector<Row> rows;
  for (const double delta : {25.0, 0.0}) {
    const exact::EllipticCap ex{35 * kDeg, delta * kDeg, 1.0, 1.0, 80.0, 80.0, 4.0};
    const double t_end = 5.0, xa = -100, xb = delta > 0 ? 125 : 180, yb = 95;
    const auto sh = ex.at(t_end);
    std::vector<Row> part;
    for (double ds : pick(o, {4.0, 2.0, 1.0}, {0.5})) {
      const auto t0 = std::chrono::steady_clock::now();
      const int nx = int(std::lround((xb - xa) / ds)), ny = int(std::lround(2 * yb / ds));
      auto terr = plane(nx, ny, ds, ds, ex.zeta, xa, -yb);
      std::vector<double> h0(terr.cells());
      auto xs = [&](int i) { return xa + (i + 0.5) * ds; };
      auto ys = [&](int j) { return -yb + (j + 0.5) * ds; };
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const double X = xs(i) / ex.Lx, Y = ys(j) / ex.Ly;
          h0[std::size_t(j) * nx + i] = std::max(0.0, ex.H * (1 - X * X - Y * Y));
        }
      Sh2dConfig cfg;
      cfg.material = coulomb(delta);
      cfg.limiter = o.limiter;
      cfg.time.t_end = t_end;
      const auto r = run_sh2d(terr, cfg, state_from_normal_depth(terr, h0));
      const auto& h = r.hazard.final_depth;
      double m = 0, mx = 0, my = 0, hmax = 0, e1 = 0, s1 = 0;
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const double v = h[std::size_t(j) * nx + i];
          m += v;
          mx += v * xs(i);
          my += v * ys(j);
          hmax = std::max(hmax, v);
          const double X = (xs(i) - sh.centre) / sh.half_length, Y = ys(j) / sh.half_width;
          const double he = std::max(0.0, sh.max_depth * (1 - X * X - Y * Y));
          e1 += std::abs(v - he);
          s1 += he;
        }
      const double cx = mx / m, cy = my / m;
      double vx = 0, vy = 0;
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const double v = h[std::size_t(j) * nx + i];
          vx += v * (xs(i) - cx) * (xs(i) - cx);
          vy += v * (ys(j) - cy) * (ys(j) - cy);
        }
      // For a paraboloid cap the second moment is a^2 / 6 of the half-axis a.
      const double a = std::sqrt(6 * vx / m), b = std::sqrt(6 * vy / m);
      Row row;
      row.case_id = "A3";
      row.variant = variant("2d", o) + (delta > 0 ? "" : "-frictionless");
      row.cell_updates = r.diag.cell_updates;
      row.cells = long(nx) * ny;
      row.dx = ds;
      const bool target = delta > 0 && ds <= 1.0 + 1e-9;
      auto lim = [&](double v) { return target ? v : kNaN; };
      row.metrics.push_back({"centre_rel_err", std::abs(cx - sh.centre) / sh.centre, lim(0.005)});
      row.metrics.push_back({"max_depth_rel_err", std::abs(hmax - sh.max_depth) / sh.max_depth, lim(0.02)});
      row.metrics.push_back({"half_length_rel_err", std::abs(a - sh.half_length) / sh.half_length, lim(0.02)});
      row.metrics.push_back({"half_width_rel_err", std::abs(b - sh.half_width) / sh.half_width, lim(0.02)});
      row.metrics.push_back({"L1_rel_depth", e1 / s1});
      row.metrics.push_back({"mass_rel_err", r.diag.volume_error(), 1e-12});
      row.wall_s = seconds_since(t0);
      part.push_back(row);
    }
    if (delta == 0) check_order(part, "L1_rel_depth", "order", 1.2);
    else fill_orders(part, "L1_rel_depth");
    for (auto& r : part) rows.push_back(std::move(r));
  }
  return rows;
}

// ---------------------------------------------------------------- A4 at rest stays at rest
std::vector<Row> case_a4(const Options& o) {
  std::vector<Row> rows;
  const double t_end = 100.0;
  for (int which = 0; which < 2; ++which) {
    const auto t0 = std::chrono::steady_clock::now();
    Terrain2D terr;
    std::vector<double> h0;
    Sh2dConfig cfg;
    cfg.limiter = o.limiter;
    cfg.time.t_end = t_end;
    std::string name;
    if (which == 0) {
      // AvaFrame's flat-plane pile: h(r) = min(4, max(0, 4 - 0.1 (r - 20))), 5 m cells.
      name = "pile-flat";
      terr.nx = terr.ny = 201;
      terr.dx = terr.dy = 5.0;
      terr.x0 = terr.y0 = -500.0;
      terr.z.assign(terr.cells(), 0.0);
      h0.resize(terr.cells());
      for (int j = 0; j < terr.ny; ++j)
        for (int i = 0; i < terr.nx; ++i) {
          const double r = std::hypot(terr.x0 + i * terr.dx, terr.y0 + j * terr.dy);
          h0[std::size_t(j) * terr.nx + i] = std::min(4.0, std::max(0.0, 4.0 - 0.1 * (r - 20.0)));
        }
      cfg.material = coulomb(std::atan(0.2) / kDeg);  // mu = 0.2 > surface slope 0.1
    } else {
      // Uniform 2 m layer on a 20 degree plane, delta = 25 degrees, oblique aspect.
      name = "layer-20deg";
      terr.nx = terr.ny = 60;
      terr.dx = terr.dy = 5.0;
      terr.z.resize(terr.cells());
      const double s = std::tan(20 * kDeg);
      for (int j = 0; j < terr.ny; ++j)
        for (int i = 0; i < terr.nx; ++i)
          terr.z[std::size_t(j) * terr.nx + i] = -s * (std::cos(0.6) * i * terr.dx + std::sin(0.6) * j * terr.dy);
      h0.assign(terr.cells(), 2.0);
      cfg.material = coulomb(25);
    }
    const auto init = state_from_normal_depth(terr, h0);
    const auto r = run_sh2d(terr, cfg, init);
    double dh = 0;
    for (std::size_t k = 0; k < h0.size(); ++k) dh = std::max(dh, std::abs(r.state.H[k] - init.H[k]));
    Row row;
    row.case_id = "A4";
    row.variant = variant("2d", o) + "-" + name;
    row.cells = long(terr.cells());
    row.dx = terr.dx;
    row.metrics.push_back({"max_speed", r.diag.max_speed, 1e-12});
    row.metrics.push_back({"max_depth_change", dh, 1e-12});
    row.metrics.push_back({"mass_rel_err", r.diag.volume_error(), 1e-12});
    row.metrics.push_back({"t_end", r.diag.t});
    row.wall_s = seconds_since(t0);
    rows.push_back(row);
  }
  return rows;
}

// ---------------------------------------------------------------- A5 steady chute
std::vector<Row> case_a5(const Options& o) {
  const exact::SteadyChute ex{35 * kDeg, 25 * kDeg, 1.0, 1.0, 5.0, 0.0};
  std::vector<Row> rows;
  for (double ds : pick(o, {2.0, 1.0, 0.5}, {0.25})) {
    const auto t0 = std::chrono::steady_clock::now();
    const int n = int(std::lround(100.0 / ds));
    auto ch = Channel1D::uniform(n, ds, 0.0, ex.zeta);
    Sh1dConfig cfg;
    cfg.material = coulomb(25);
    cfg.limiter = o.limiter;
    cfg.time.t_end = 40.0;
    cfg.left = Boundary1D::inflow;
    cfg.right = Boundary1D::outflow;
    cfg.inflow = Hydrograph{{0.0}, {ex.h0}, {ex.u0}};
    Sh1dState s;
    s.h.assign(n, 0.0);
    s.m.assign(n, 0.0);
    const auto r = run_sh1d(ch, cfg, s);
    double eu = 0, su = 0, eh = 0, shh = 0;
    for (int i = 0; i < n; ++i) {
      const double ue = ex.velocity(ch.centre(i)), he = ex.depth(ch.centre(i));
      const double u = r.state.h[i] > 1e-6 ? r.state.m[i] / r.state.h[i] : 0.0;
      eu += std::abs(u - ue);
      su += ue;
      eh += std::abs(r.state.h[i] - he);
      shh += he;
    }
    Row row;
    row.case_id = "A5";
    row.variant = variant("1d", o);
    row.cells = n;
    row.dx = ds;
    const bool target = ds <= 0.5 + 1e-9;
    row.metrics.push_back({"L1_rel_velocity", eu / su, target ? 0.01 : kNaN});
    row.metrics.push_back({"L1_rel_depth", eh / shh, target ? 0.02 : kNaN});
    row.wall_s = seconds_since(t0);
    rows.push_back(row);
  }
  // Converging to the exact profile: the depth error must fall at least at first order.
  check_order(rows, "L1_rel_depth", "order_depth", 1.0);
  return rows;
}

// ---------------------------------------------------------------- A6/A7 slope to run-out terrain
// Downslope profile along s: 30 degrees for s < -50 m, the inclination falling linearly to zero at
// s = +50 m, flat beyond: z(s) = -(100/theta0) ln cos(theta(s)) in the transition.
double runout_profile(double s) {
  const double th0 = 30 * kDeg;
  if (s >= 50) return 0.0;
  if (s >= -50) return -(100 / th0) * std::log(std::cos(th0 * (50 - s) / 100));
  return -(100 / th0) * std::log(std::cos(th0)) + std::tan(th0) * (-50 - s);
}

struct RunoutFigures {
  double runout = 0, area = 0, ring = 0, tan_alpha = 0, tan_alpha_path = 0, mass_err = 0;
  long cells = 0;
  double wall = 0;
};

RunoutFigures runout_run(double angle_deg, double dx, const Options& o, bool curvature = true) {
  const auto t0 = std::chrono::steady_clock::now();
  const double half = 220, a = angle_deg * kDeg, ca = std::cos(a), sa = std::sin(a);
  const int n = int(std::lround(2 * half / dx));
  Terrain2D t;
  t.nx = t.ny = n;
  t.dx = t.dy = dx;
  t.x0 = t.y0 = -half + 0.5 * dx;
  t.z.resize(t.cells());
  std::vector<double> h0(t.cells()), s_of(t.cells());
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = t.x0 + i * dx, y = t.y0 + j * dx;
      const double s = x * ca + y * sa, q = -x * sa + y * ca;
      const std::size_t k = std::size_t(j) * n + i;
      t.z[k] = runout_profile(s);
      s_of[k] = s;
      const double r2 = ((s + 150) * (s + 150) + q * q) / (25.0 * 25.0);
      h0[k] = std::max(0.0, 3.0 * (1 - r2));
    }
  Sh2dConfig cfg;
  cfg.material = coulomb(20);
  cfg.limiter = o.limiter;
  cfg.time.t_end = 150;
  cfg.time.stop_fraction = 1e-4;
  cfg.curvature = curvature;
  cfg.track_travel = true;
  const auto init = state_from_normal_depth(t, h0);
  const auto r = run_sh2d(t, cfg, init);
  RunoutFigures f;
  const double thr = 0.1;
  long affected = 0, edge = 0;
  double runout = -1e300;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::size_t k = std::size_t(j) * n + i;
      if (r.hazard.max_depth[k] <= thr) continue;
      ++affected;
      runout = std::max(runout, s_of[k]);
      const bool border = i == 0 || j == 0 || i == n - 1 || j == n - 1 || r.hazard.max_depth[k - 1] <= thr ||
                          r.hazard.max_depth[k + 1] <= thr || r.hazard.max_depth[k - n] <= thr ||
                          r.hazard.max_depth[k + n] <= thr;
      edge += border;
    }
  f.runout = runout;
  f.area = affected * dx * dx;
  f.ring = edge * dx * dx;
  // Energy line: centre of mass before and after.
  double m0 = 0, s0 = 0, z0 = 0, m1 = 0, s1 = 0, z1 = 0;
  for (std::size_t k = 0; k < t.cells(); ++k) {
    m0 += init.H[k];
    s0 += init.H[k] * s_of[k];
    z0 += init.H[k] * t.z[k];
    m1 += r.state.H[k];
    s1 += r.state.H[k] * s_of[k];
    z1 += r.state.H[k] * t.z[k];
  }
  f.tan_alpha = (z0 / m0 - z1 / m1) / (s1 / m1 - s0 / m0);
  f.tan_alpha_path = (z0 / m0 - z1 / m1) / r.diag.mean_travel;
  f.mass_err = r.diag.volume_error();
  f.cells = long(t.cells());
  f.wall = seconds_since(t0);
  return f;
}

std::vector<Row> case_a6(const Options& o) {
  std::vector<Row> rows;
  const double dx = o.resolutions.empty() ? (o.full ? 2.0 : 4.0) : o.resolutions.front();
  RunoutFigures ref;
  for (double ang : {0.0, 30.0, 90.0}) {
    const auto f = runout_run(ang, dx, o);
    if (ang == 0.0) ref = f;
    Row row;
    row.case_id = "A6";
    row.variant = variant("2d", o) + "-rot" + std::to_string(int(ang));
    row.cells = f.cells;
    row.dx = dx;
    row.metrics.push_back({"runout_m", f.runout});
    row.metrics.push_back({"area_m2", f.area});
    row.metrics.push_back({"runout_diff_cells", std::abs(f.runout - ref.runout) / dx, 1.0});
    // One cell: the area may differ by at most the ring of outline cells of the unrotated run.
    row.metrics.push_back({"area_diff_rings", std::abs(f.area - ref.area) / ref.ring, 1.0});
    row.metrics.push_back({"mass_rel_err", f.mass_err, 1e-12});
    row.wall_s = f.wall;
    rows.push_back(row);
  }
  return rows;
}

// Without the centrifugal normal load a Coulomb slider loses exactly mu g per metre of horizontal
// travel, so the alpha angle equals delta (checked); with it, concave terrain adds friction and
// alpha exceeds delta (reported).
std::vector<Row> case_a7(const Options& o) {
  std::vector<Row> rows;
  const double tan_delta = std::tan(20 * kDeg);
  auto add = [&](const std::string& var, long cells, double dx, double ta, double merr, bool checked, double wall) {
    Row row;
    row.case_id = "A7";
    row.variant = var;
    row.cells = cells;
    row.dx = dx;
    row.metrics.push_back({"tan_alpha", ta});
    row.metrics.push_back({"tan_delta", tan_delta});
    row.metrics.push_back({"rel_diff", std::abs(ta / tan_delta - 1), checked ? 0.02 : kNaN});
    row.metrics.push_back({"mass_rel_err", merr, 1e-12});
    row.wall_s = wall;
    rows.push_back(row);
  };
  // 2D: slope to run-out terrain (as A6, unrotated).
  for (const bool curv : {false, true}) {
    const double dx = o.resolutions.empty() ? (o.full ? 2.0 : 4.0) : o.resolutions.front();
    const auto f = runout_run(0.0, dx, o, curv);
    // In 2D the mass spreads sideways, so the path is longer than the displacement of the centre of
    // mass: the check uses the mass-averaged path length, the centre-of-mass angle is reported.
    add(variant("2d", o) + (curv ? "-curvature" : "-no-curvature"), f.cells, dx, f.tan_alpha_path, f.mass_err, !curv,
        f.wall);
    rows.back().metrics.push_back({"tan_alpha_com", f.tan_alpha});
  }
  // 1D: a curved channel (30 degrees easing to 0 over 100 m of arc).
  for (const bool curv : {false, true}) {
    const auto t0 = std::chrono::steady_clock::now();
    const double ds = o.resolutions.empty() ? (o.full ? 0.25 : 1.0) : o.resolutions.front();
    const double xa = -250, xb = 300, th0 = 30 * kDeg;
    auto zeta = [&](double x) { return x < -50 ? th0 : (x > 50 ? 0.0 : th0 * (50 - x) / 100); };
    const int n = int(std::lround((xb - xa) / ds));
    auto ch = Channel1D::from_profile(n, ds, xa, zeta);
    // Map arc length to the vertical section (x_h, z) by integrating cos/sin of the inclination.
    std::vector<double> xh(n), zz(n);
    double X = 0, Z = 0;
    for (int i = 0; i < n; ++i) {
      const double zt = zeta(ch.centre(i));
      X += ds * std::cos(zt);
      Z -= ds * std::sin(zt);
      xh[i] = X;
      zz[i] = Z;
    }
    Sh1dConfig cfg;
    cfg.material = coulomb(20);
    cfg.limiter = o.limiter;
    cfg.time.t_end = 150;
    cfg.time.stop_fraction = 1e-4;
    cfg.left = cfg.right = Boundary1D::wall;
    cfg.curvature = curv;
    Sh1dState s;
    s.h.resize(n);
    s.m.assign(n, 0);
    for (int i = 0; i < n; ++i) {
      const double xi = (ch.centre(i) + 150) / 25.0;
      s.h[i] = std::max(0.0, 3.0 * (1 - xi * xi));
    }
    const auto r = run_sh1d(ch, cfg, s);
    auto com = [&](const std::vector<double>& h, double& cx, double& cz) {
      double m = 0;
      cx = cz = 0;
      for (int i = 0; i < n; ++i) {
        m += h[i];
        cx += h[i] * xh[i];
        cz += h[i] * zz[i];
      }
      cx /= m;
      cz /= m;
    };
    double x0, z0, x1, z1;
    com(s.h, x0, z0);
    com(r.state.h, x1, z1);
    add(variant("1d", o) + (curv ? "-curvature" : "-no-curvature"), n, ds, (z0 - z1) / (x1 - x0),
        std::abs(r.mass_final - r.mass_initial) / r.mass_initial, !curv, seconds_since(t0));
  }
  return rows;
}

// ---------------------------------------------------------------- stress test
std::vector<Row> case_stress(const Options& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const int scenarios = o.full ? 120 : 24;
  std::mt19937_64 rng(20261123);
  auto U = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  long failures = 0, nan_count = 0, negative = 0;
  double worst_mass = 0, min_depth = 0, cell_updates = 0;
  for (int sc = 0; sc < scenarios; ++sc) {
    const int n = 48;
    Terrain2D t;
    t.nx = t.ny = n;
    t.dx = t.dy = U(1.0, 10.0);
    const double slope = std::tan(U(0, 60) * kDeg), aspect = U(0, 2 * M_PI);
    const double rough = U(0, 0.5) * t.dx;
    double kx[3], ky[3], ph[3];
    for (int q = 0; q < 3; ++q) {
      kx[q] = U(-1, 1) * 2 * M_PI / (t.dx * U(3, 20));
      ky[q] = U(-1, 1) * 2 * M_PI / (t.dx * U(3, 20));
      ph[q] = U(0, 2 * M_PI);
    }
    t.z.resize(t.cells());
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double x = i * t.dx, y = j * t.dy;
        double z = -slope * (std::cos(aspect) * x + std::sin(aspect) * y);
        for (int q = 0; q < 3; ++q) z += rough * std::sin(kx[q] * x + ky[q] * y + ph[q]);
        t.z[std::size_t(j) * n + i] = z;
      }
    std::vector<double> h0(t.cells(), 0.0);
    const double depth = U(0.2, 8.0), rad = U(3, 15), ci = U(12, 36), cj = U(12, 36);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double r2 = ((i - ci) * (i - ci) + (j - cj) * (j - cj)) / (rad * rad);
        h0[std::size_t(j) * n + i] = r2 < 1 ? depth * (sc % 3 == 0 ? 1.0 : 1 - r2) : 0.0;  // plateaus too
      }
    Sh2dConfig cfg;
    const double delta = U(5, 40);
    cfg.material = coulomb(delta);
    if (sc % 4 == 1) {
      cfg.material.rheology = Rheology::voellmy;
      cfg.material.mu = U(0.05, 0.6);
      cfg.material.xi = U(300, 5000);
    }
    if (sc % 2 == 0) {
      cfg.material.earth_pressure = EarthPressure::active_passive;
      cfg.material.phi = std::max(delta + U(0, 10), std::atan(cfg.material.coulomb_coefficient()) / kDeg + 1) * kDeg;
    }
    cfg.limiter = static_cast<Limiter>(sc % 3);
    cfg.time.cfl = sc % 5 == 0 ? 0.5 : U(0.2, 0.5);
    cfg.time.t_end = 1e9;
    cfg.time.max_steps = 250;
    const bool closed = sc % 2 == 1;
    cfg.west = cfg.east = cfg.south = cfg.north = closed ? Boundary2D::wall : Boundary2D::outflow;
    cfg.tile = 16;
    bool ok = true;
    try {
      const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, h0));
      for (std::size_t k = 0; k < t.cells(); ++k) {
        const double H = r.state.H[k];
        if (!std::isfinite(H) || !std::isfinite(r.state.HU[k]) || !std::isfinite(r.state.HV[k])) {
          ++nan_count;
          ok = false;
        } else if (H < 0) {
          ++negative;
          min_depth = std::min(min_depth, H);
          ok = false;
        }
      }
      worst_mass = std::max(worst_mass, r.diag.volume_error());
      if (!(r.diag.volume_error() <= 1e-12)) ok = false;
      cell_updates += r.diag.cell_updates;
    } catch (const std::exception&) {
      ok = false;
    }
    failures += !ok;
  }
  Row row;
  row.case_id = "STRESS";
  row.variant = "2d-random";
  row.cells = scenarios;
  row.dx = 0;
  row.metrics.push_back({"scenarios", double(scenarios)});
  row.metrics.push_back({"failed", double(failures), 0.0});
  row.metrics.push_back({"nan_cells", double(nan_count), 0.0});
  row.metrics.push_back({"negative_cells", double(negative), 0.0});
  row.metrics.push_back({"worst_mass_rel_err", worst_mass, 1e-12});
  row.metrics.push_back({"cell_updates", cell_updates});
  row.wall_s = seconds_since(t0);
  return {row};
}

struct CaseEntry {
  const char* id;
  const char* text;
  std::vector<Row> (*run)(const Options&);
};
const CaseEntry kCases[] = {
    {"A1", "dam break on an inclined plane with Coulomb friction (Mangeney et al. 2000), 1D and 2D", case_a1},
    {"A2", "parabolic cap on an inclined plane (Savage & Hutter 1989), 1D", case_a2},
    {"A3", "elliptic cap on an inclined plane (Hutter et al. 1993), 2D", case_a3},
    {"A4", "material at rest stays at rest: pile on a flat plane, layer on a gentle slope, 2D", case_a4},
    {"A5", "steady flow down a uniform chute (Pudasaini 2011), 1D with inflow", case_a5},
    {"A6", "rotation invariance: release on slope-to-run-out terrain rotated by 0, 30, 90 deg, 2D", case_a6},
    {"A7", "energy line: alpha angle equals delta for pure Coulomb friction, 2D and curved 1D", case_a7},
    {"STRESS", "randomised terrain, friction, depths, resolutions and CFL: no NaN, no negative depth, no mass drift",
     case_stress},
    {"V1", "VOF engine: plane Couette flow of a Newtonian fluid, steady linear profile", case_v1},
    {"V2", "VOF engine: plane Poiseuille flow of a Newtonian fluid down an inclined channel, parabolic profile", case_v2},
    {"V3", "VOF engine: granular layer under air at rest in a closed box, hydrostatic pressure, no spurious currents", case_v3},
    {"V4", "VOF engine: start-up of plane Couette flow from rest (series solution)", case_v4},
};

}  // namespace

std::vector<std::string> case_ids() {
  std::vector<std::string> v;
  for (const auto& c : kCases) v.emplace_back(c.id);
  return v;
}

std::string describe(const std::string& id) {
  for (const auto& c : kCases)
    if (id == c.id) return c.text;
  return {};
}

std::vector<Row> run_case(const std::string& id, const Options& opt) {
  for (const auto& c : kCases)
    if (id == c.id) return c.run(opt);
  std::string valid;
  for (const auto& c : kCases) valid += (valid.empty() ? "" : ", ") + std::string(c.id);
  throw std::invalid_argument("unknown verification case '" + id + "' (valid: " + valid + ")");
}

}  // namespace runout::engine::verification
