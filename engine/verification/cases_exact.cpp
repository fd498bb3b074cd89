// Verification against exact solutions of the depth-averaged equations: A1 dam break, A2 parabolic
// cap, A3 elliptic cap.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>

#include "engine/verification/case_support.hpp"
#include "engine/verification/exact.hpp"

namespace runout::engine::verification::detail {

// ---------------------------------------------------------------- A1 dam break
std::vector<Row> case_a1(const Options& o) {
  const exact::DamBreak ex{22 * kDeg, 21 * kDeg, 1.0};
  const double t_end = 5.0, xa = -40, xb = 50;
  // The front is where the depth falls to a threshold, in the exact solution and in the run alike:
  // 0.1 m (10 % of h0, the depth hazard maps outline) is checked; 1 mm is reported. The exact tail
  // ahead of it is a degenerate rarefaction (h ~ (x_f - x)^2) that central schemes under-resolve,
  // so the 1 mm position lags (docs/validation/verification.md).
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
// by t = 10 s, every limiter) and the observed order becomes erratic (docs/validation/verification.md).
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

}  // namespace runout::engine::verification::detail
