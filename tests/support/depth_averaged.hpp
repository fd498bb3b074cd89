#pragma once
// Test support for the depth-averaged engines' unit tests: synthetic terrains, releases, and the
// flow-dependent friction laws with the published parameters of glass beads.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"

namespace runout::test_support::depth_averaged {

using namespace runout::engine;
inline constexpr double kDeg = M_PI / 180.0;

// Slope falling in direction `aspect` (radians from +x) at `slope_deg`, plus a run-out bowl.
inline Terrain2D hillside(int nx, int ny, double dx, double slope_deg, double aspect) {
  Terrain2D t;
  t.nx = nx;
  t.ny = ny;
  t.dx = t.dy = dx;
  t.z.resize(t.cells());
  const double s = std::tan(slope_deg * kDeg);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = i * dx, y = j * dx;
      const double along = std::cos(aspect) * x + std::sin(aspect) * y;
      t.z[std::size_t(j) * nx + i] = -s * along + 0.0005 * along * along + 0.3 * std::sin(0.05 * x) * std::cos(0.07 * y);
    }
  return t;
}

// A grid of nx x ny cells of size dx with the elevation z(x, y) at the cells' centres.
template <class F>
Terrain2D terrain_of(int nx, int ny, double dx, F z) {
  Terrain2D t;
  t.nx = nx;
  t.ny = ny;
  t.dx = t.dy = dx;
  t.z.resize(t.cells());
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) t.z[std::size_t(j) * nx + i] = z(i * dx, j * dx);
  return t;
}

// A plane falling in +x at `slope_deg`.
inline Terrain2D inclined_plane(int nx, int ny, double dx, double slope_deg) {
  return terrain_of(nx, ny, dx, [&](double x, double) { return -std::tan(slope_deg * kDeg) * x; });
}

// A paraboloid of normal depth h and radius r cells centred on cell (ci, cj).
inline std::vector<double> blob(const Terrain2D& t, double ci, double cj, double r, double h) {
  std::vector<double> v(t.cells(), 0.0);
  for (int j = 0; j < t.ny; ++j)
    for (int i = 0; i < t.nx; ++i) {
      const double q = ((i - ci) * (i - ci) + (j - cj) * (j - cj)) / (r * r);
      v[std::size_t(j) * t.nx + i] = q < 1 ? h * (1 - q) : 0.0;
    }
  return v;
}

// Pouliquen-Forterre for glass beads (Forterre & Pouliquen 2003, as tabulated by Gray & Edwards
// 2014): delta_1 = 20.9, delta_2 = 32.76 deg, beta = 0.136, L = 0.825 mm; delta_3 and gamma given.
inline Material glass_beads_pf(double delta3_deg, double gamma) {
  return pouliquen_forterre_material(20.9 * kDeg, 32.76 * kDeg, delta3_deg * kDeg, 0.136, 0.825e-3, gamma);
}

// mu(I) for glass beads (Jop, Forterre & Pouliquen 2006): mu_s = tan 20.9, mu_2 = tan 32.76 deg,
// I_0 = 0.279, d = 0.5 mm, rho_s = 2450 kg/m^3, solid fraction 0.6.
inline Material glass_beads_mu_i() {
  return mu_i_material(std::tan(20.9 * kDeg), std::tan(32.76 * kDeg), 0.279, 0.5e-3, 2450, 0.6 * 2450);
}

// Every figure of two runs the same, bit for bit (NaN arrival times where both never arrived).
inline void expect_same(const Sh2dResult& a, const Sh2dResult& b) {
  EXPECT_EQ(a.diag.steps, b.diag.steps);
  EXPECT_EQ(a.diag.t, b.diag.t);
  EXPECT_EQ(a.diag.stop, b.diag.stop);
  EXPECT_EQ(a.state.H, b.state.H);
  EXPECT_EQ(a.state.HU, b.state.HU);
  EXPECT_EQ(a.state.HV, b.state.HV);
  EXPECT_EQ(a.hazard.max_depth, b.hazard.max_depth);
  EXPECT_EQ(a.hazard.max_speed, b.hazard.max_speed);
  EXPECT_EQ(a.hazard.max_pressure, b.hazard.max_pressure);
  EXPECT_EQ(a.hazard.final_depth, b.hazard.final_depth);
  ASSERT_EQ(a.hazard.arrival_time.size(), b.hazard.arrival_time.size());
  for (std::size_t k = 0; k < a.hazard.arrival_time.size(); ++k)
    ASSERT_TRUE(a.hazard.arrival_time[k] == b.hazard.arrival_time[k] ||
                (std::isnan(a.hazard.arrival_time[k]) && std::isnan(b.hazard.arrival_time[k])))
        << k;
  EXPECT_EQ(a.diag.volume_initial, b.diag.volume_initial);
  EXPECT_EQ(a.diag.volume_final, b.diag.volume_final);
  EXPECT_EQ(a.diag.volume_outflow, b.diag.volume_outflow);
  EXPECT_EQ(a.diag.kinetic_energy_peak, b.diag.kinetic_energy_peak);
  EXPECT_EQ(a.diag.max_speed, b.diag.max_speed);
  EXPECT_EQ(a.diag.positivity_limited, b.diag.positivity_limited);
  EXPECT_EQ(a.diag.cell_updates, b.diag.cell_updates);
  EXPECT_EQ(a.diag.mean_active_fraction, b.diag.mean_active_fraction);
  EXPECT_EQ(a.diag.max_active_fraction, b.diag.max_active_fraction);
  EXPECT_EQ(a.diag.mean_travel, b.diag.mean_travel);
  EXPECT_EQ(a.diag.volume_detrained, b.diag.volume_detrained);
  EXPECT_EQ(a.detrained, b.detrained);
  EXPECT_EQ(a.diag.volume_entrained, b.diag.volume_entrained);
  EXPECT_EQ(a.cover, b.cover);
  EXPECT_EQ(a.gauge_right, b.gauge_right);
  EXPECT_EQ(a.gauge_left, b.gauge_left);
}

// The engine refuses `cfg` with std::invalid_argument whose message holds `needle`.
inline void expect_refused(const Terrain2D& t, const Sh2dConfig& cfg, const Sh2dState& init, const std::string& needle) {
  try {
    run_sh2d(t, cfg, init);
    ADD_FAILURE() << "accepted: " << needle;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

// A run with checkpoints, cancelled at about half of `plain`'s steps, continues from its last
// checkpoint to `plain`'s bits; and a checkpoint of the run without the feature under test (`strip`
// removes it from a configuration) does not continue the run with it.
template <class Strip>
void expect_continuation(const Terrain2D& t, const Sh2dConfig& cfg, const Sh2dState& init, const Sh2dResult& plain, Strip strip) {
  auto cut = cfg;
  Sh2dCheckpoint taken;
  const long at = plain.diag.steps / 2 + 1;
  cut.time.progress_every = 1;
  cut.time.progress = [&](const Progress& p) { return p.step < at; };
  cut.checkpoint = [&](const Sh2dCheckpoint& cp) { taken = cp; };
  ASSERT_EQ(run_sh2d(t, cut, init).diag.stop, StopReason::cancelled);
  expect_same(plain, run_sh2d(t, cfg, taken));
  auto bare = cut;
  strip(bare);
  Sh2dCheckpoint other;
  bare.checkpoint = [&](const Sh2dCheckpoint& cp) { other = cp; };
  run_sh2d(t, bare, init);
  EXPECT_THROW(run_sh2d(t, cfg, other), std::invalid_argument);
}

}  // namespace runout::test_support::depth_averaged
