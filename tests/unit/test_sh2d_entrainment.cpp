// The erodible cover of the depth-averaged engine (engine/sh2d.hpp ErodibleCover): basal erosion
// against its closed form on an inclined plane, the cover running out, front entrainment
// (ploughing), the mass balance, a run continued from a checkpoint, and the cover's checks.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "tests/support/depth_averaged.hpp"

using namespace runout::engine;
using namespace runout::test_support::depth_averaged;

namespace {

constexpr int kN = 24;
constexpr double kDx = 5.0, kSlope = 30.0, kRho = 300.0, kRhoCover = 100.0, kEb = 5000.0;

// A uniform layer of normal depth h0 sliding at u0 down a plane whose Coulomb friction balances
// gravity (tan delta = tan theta), over a uniform cover of normal depth d: with nothing else acting,
// the layer stays uniform (the outflow edges copy the inside) and its momentum constant.
struct BalancedLayer {
  Terrain2D t = inclined_plane(kN, kN, kDx, kSlope);
  Sh2dConfig cfg;
  Sh2dState init;
  BalancedLayer(double h0, double u0, double d, double t_end) {
    cfg.material.delta = kSlope * kDeg;
    cfg.material.density = kRho;
    cfg.time.t_end = t_end;
    cfg.time.stop_fraction = 0;
    init = state_from_normal_depth(t, std::vector<double>(t.cells(), h0));
    // Velocity along the slope at u0: its horizontal part u0 cos(theta).
    for (std::size_t k = 0; k < t.cells(); ++k) init.HU[k] = init.H[k] * u0 * std::cos(kSlope * kDeg);
    cfg.cover.depth.assign(t.cells(), d);
    cfg.cover.density.assign(t.cells(), kRhoCover);
    cfg.cover.erosion_energy = kEb;
  }
  static std::size_t centre() { return std::size_t(kN / 2) * kN + kN / 2; }
};

}  // namespace

// Basal erosion dm/dt = tau_b |u| / e_b with tau_b = mu rho g cos(theta) h (Coulomb): with the
// momentum h |u| = h0 u0 constant, the layer grows linearly, h(t) = h0 + mu g cos(theta) h0 u0 t / e_b,
// and the cover thins by rho / rho_cover times that. The scheme keeps the momentum to round-off, so
// the closed form holds to 1e-9; the volume balance (released + entrained = final) to 1e-12.
TEST(Sh2dEntrainment, ErosionGrowsABalancedLayerAsItsClosedForm) {
  const double h0 = 1.0, u0 = 20.0, d = 2.0, t_end = 10.0;
  BalancedLayer f(h0, u0, d, t_end);
  const auto r = run_sh2d(f.t, f.cfg, f.init);
  ASSERT_NEAR(r.diag.t, t_end, 1e-9);
  const double c = std::cos(kSlope * kDeg), mu = std::tan(kSlope * kDeg);
  const double grown = mu * 9.81 * c * h0 * u0 * r.diag.t / kEb;  // normal depth taken up
  const std::size_t k = BalancedLayer::centre();
  EXPECT_NEAR(r.state.H[k] * c, h0 + grown, 1e-9 * h0);
  EXPECT_NEAR(r.cover[k], d - kRho / kRhoCover * grown, 1e-9);
  EXPECT_NEAR(r.diag.volume_entrained, grown / c * kN * kN * kDx * kDx, 1e-9 * r.diag.volume_entrained);
  EXPECT_LT(r.diag.volume_error(), 1e-12);
  // Uniform: what leaves the lower edge comes in at the upper one.
  EXPECT_LT(std::abs(r.diag.volume_outflow), 1e-12 * r.diag.volume_final);
  // Taken up at rest: the speed drops as h0 u0 / h.
  const double u = std::hypot(r.state.HU[k], r.state.HU[k] * std::tan(kSlope * kDeg)) / r.state.H[k];
  EXPECT_NEAR(u, u0 * h0 / (h0 + grown), 1e-9 * u0);
}

// With Voellmy's drag the basal shear stress is mu rho g cos(theta) h + rho g |u|^2 / xi: at the start
// the layer erodes 1 + u0^2 / (xi mu cos(theta) h0) times as fast as with Coulomb alone (in 0.1 s the
// drag slows it by 1 %), and the balance still holds to round-off.
TEST(Sh2dEntrainment, VoellmysDragErodesToo) {
  const double h0 = 1.0, u0 = 20.0, xi = 2000, t_end = 0.1;
  BalancedLayer coulomb(h0, u0, 2.0, t_end), voellmy(h0, u0, 2.0, t_end);
  voellmy.cfg.material.rheology = &friction::voellmy;
  voellmy.cfg.material.mu = std::tan(kSlope * kDeg);
  voellmy.cfg.material.xi = xi;
  const auto a = run_sh2d(coulomb.t, coulomb.cfg, coulomb.init), b = run_sh2d(voellmy.t, voellmy.cfg, voellmy.init);
  const double ratio = 1 + u0 * u0 / (xi * std::tan(kSlope * kDeg) * std::cos(kSlope * kDeg) * h0);
  EXPECT_NEAR(b.diag.volume_entrained / a.diag.volume_entrained, ratio, 0.02 * ratio);
  EXPECT_LT(b.diag.volume_error(), 1e-12);
}

// A thin cover runs out: the layer has taken up exactly the cover (as flow volume rho_c d / rho),
// nothing is left of it, and it erodes no further.
TEST(Sh2dEntrainment, ACoverRunsOut) {
  const double h0 = 1.0, d = 0.01;
  BalancedLayer f(h0, 20.0, d, 10.0);
  const auto r = run_sh2d(f.t, f.cfg, f.init);
  const std::size_t k = BalancedLayer::centre();
  const double c = std::cos(kSlope * kDeg);
  EXPECT_NEAR(r.state.H[k] * c, h0 + kRhoCover / kRho * d, 1e-12);
  EXPECT_EQ(r.cover[k], 0.0);
  EXPECT_NEAR(r.diag.volume_entrained, kRhoCover / kRho * d / c * kN * kN * kDx * kDx, 1e-9);
  EXPECT_LT(r.diag.volume_error(), 1e-12);
}

// Ploughing (front entrainment): a release slides down over a cover; every cell it flowed over (an
// arrival time) has given its whole cover, the others keep theirs, and the volume taken up is the
// cover under the path, to round-off.
TEST(Sh2dEntrainment, PloughingTakesTheWholeCoverUnderThePath) {
  const auto t = hillside(60, 30, 5.0, 32, 0.0);
  Sh2dConfig cfg;
  cfg.material.delta = 24 * kDeg;
  cfg.material.density = kRho;
  cfg.time.t_end = 30;
  cfg.tile = 16;
  cfg.cover.depth.assign(t.cells(), 0.0);
  cfg.cover.density.assign(t.cells(), kRhoCover);
  cfg.cover.ploughing = true;
  for (int j = 0; j < t.ny; ++j)
    for (int i = 20; i < 45; ++i) cfg.cover.depth[std::size_t(j) * t.nx + i] = 0.5;
  const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, blob(t, 10, 15, 6, 3.0)));
  const auto geo = SurfaceGeometry::from(t);
  double under = 0;
  long reached = 0;
  for (std::size_t k = 0; k < t.cells(); ++k) {
    const double d0 = cfg.cover.depth[k];
    if (std::isnan(r.hazard.arrival_time[k])) {
      ASSERT_EQ(r.cover[k], d0) << k;
    } else {
      ASSERT_EQ(r.cover[k], 0.0) << k;
      under += kRhoCover * d0 / (kRho * geo.c[k]) * t.dx * t.dy;
      reached += d0 > 0;
    }
  }
  EXPECT_GT(reached, 50);
  EXPECT_NEAR(r.diag.volume_entrained, under, 1e-9 * under);
  EXPECT_LT(r.diag.volume_error(), 1e-12);
}

// Without a cover (or with a cover of depth 0 everywhere) the run is the plain run's, bit for bit.
TEST(Sh2dEntrainment, AnEmptyCoverChangesNothing) {
  const auto t = hillside(60, 30, 5.0, 32, 0.0);
  Sh2dConfig cfg;
  cfg.material.delta = 24 * kDeg;
  cfg.time.t_end = 20;
  cfg.tile = 16;
  const auto init = state_from_normal_depth(t, blob(t, 10, 15, 6, 3.0));
  const auto plain = run_sh2d(t, cfg, init);
  cfg.cover.depth.assign(t.cells(), 0.0);
  cfg.cover.density.assign(t.cells(), kRhoCover);
  auto empty = run_sh2d(t, cfg, init);
  EXPECT_EQ(empty.diag.volume_entrained, 0.0);
  empty.cover.clear();
  expect_same(plain, empty);
}

// A Voellmy avalanche over a cover, with checkpoints and cancelled at an arbitrary step: continued, it
// computes the bits of the uninterrupted run, the cover left included; a checkpoint without the cover
// (or without the forest, where there is one) does not continue it.
TEST(Sh2dEntrainment, ContinuedRunIsTheUninterruptedRun) {
  auto t = hillside(100, 40, 5.0, 30, 0.0);
  Sh2dConfig cfg;
  cfg.material.rheology = &friction::voellmy;
  cfg.material.mu = 0.3;
  cfg.material.xi = 1000;
  cfg.time.t_end = 40;
  cfg.tile = 16;
  cfg.cover.depth.assign(t.cells(), 0.0);
  cfg.cover.density.assign(t.cells(), kRhoCover);
  for (int j = 0; j < t.ny; ++j)
    for (int i = 25; i < 70; ++i) cfg.cover.depth[std::size_t(j) * t.nx + i] = 0.4;
  const auto init = state_from_normal_depth(t, blob(t, 15, 20, 8, 3.0));
  const auto plain = run_sh2d(t, cfg, init);
  ASSERT_GT(plain.diag.volume_entrained, 0);
  EXPECT_LT(plain.diag.volume_error(), 1e-12);
  expect_continuation(t, cfg, init, plain, [](Sh2dConfig& c) { c.cover = {}; });
  // With a forest too, the same; and a checkpoint of the run with the cover alone does not continue it.
  auto forest = cfg;
  forest.resistance.c.assign(t.cells(), 0.01);
  expect_continuation(t, forest, init, run_sh2d(t, forest, init), [](Sh2dConfig& c) { c.resistance = {}; });
}

// A bad cover is refused by name: sizes, a negative depth, a zero density, no erosion energy, a
// flow-dependent law.
TEST(Sh2dEntrainment, BadCoverIsRefused) {
  BalancedLayer f(1.0, 5.0, 0.5, 1.0);
  auto expect_bad = [&](const Sh2dConfig& cfg, const std::string& needle) { expect_refused(f.t, cfg, f.init, needle); };
  auto c = f.cfg;
  c.cover.depth.assign(3, 0.5);
  expect_bad(c, "erodible cover: field sizes");
  c.cover.depth.assign(f.t.cells(), -0.5);
  expect_bad(c, "depth must be finite and >= 0");
  c.cover.depth.assign(f.t.cells(), 0.5);
  c.cover.density.assign(f.t.cells(), 0.0);
  expect_bad(c, "density finite and > 0");
  c.cover.density.assign(f.t.cells(), 100.0);
  c.cover.erosion_energy = 0;
  expect_bad(c, "erosion energy");
  c.cover.erosion_energy = 5000;
  c.material = glass_beads_mu_i();
  expect_bad(c, "constant mu");
}
