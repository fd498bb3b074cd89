// The stress test of the depth-averaged engine: randomised terrain, friction, depths, resolutions
// and CFL numbers; no NaN, no negative depth, no mass drift.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>

#include "engine/verification/case_support.hpp"
#include "engine/verification/exact.hpp"

namespace runout::engine::verification::detail {

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
      cfg.material.rheology = &friction::voellmy;
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

}  // namespace runout::engine::verification::detail
