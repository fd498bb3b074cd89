// Verification of invariants of the depth-averaged engine: A4 rest stays at rest, A5 steady chute,
// A6 rotation invariance, A7 the energy line.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>

#include "engine/verification/case_support.hpp"
#include "engine/verification/exact.hpp"

namespace runout::engine::verification::detail {

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
static double runout_profile(double s) {
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

static RunoutFigures runout_run(double angle_deg, double dx, const Options& o, bool curvature = true) {
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

}  // namespace runout::engine::verification::detail
