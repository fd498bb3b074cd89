// Resistance areas of the depth-averaged engine (engine/sh2d.hpp ResistanceAreas): the drag of a
// forest against the closed form of its term, detrainment against its rate and the mass balance,
// material at rest in a forest left on the ground, the areas' checks, and a run continued from a
// checkpoint.
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

// A uniform layer of normal depth h moving at u0 along x on a flat, frictionless plane: nothing but
// the resistance areas changes it (the outflow edges copy the inside, so it stays uniform).
struct UniformFlow {
  Terrain2D t = terrain_of(kN, kN, 5.0, [](double, double) { return 0.0; });
  Sh2dConfig cfg;
  Sh2dState init;
  UniformFlow(double h, double u0, double t_end) {
    cfg.material.delta = 0;
    cfg.material.density = 300;
    cfg.time.t_end = t_end;
    cfg.time.stop_fraction = 0;
    init = state_from_normal_depth(t, std::vector<double>(t.cells(), h));
    for (std::size_t k = 0; k < t.cells(); ++k) init.HU[k] = init.H[k] * u0;
  }
  void forest(double c, double k_det, bool detrainment) {
    cfg.resistance.c.assign(t.cells(), c);
    cfg.resistance.k_det.assign(t.cells(), k_det);
    cfg.resistance.detrainment = detrainment;
  }
  static std::size_t centre() { return std::size_t(kN / 2) * kN + kN / 2; }
};

}  // namespace

// du/dt = -c u^2 / h integrates to 1/u = 1/u0 + c t / h. The engine takes the term implicitly over
// each step (backward Euler: first order in dt): 10 s on 5 m cells within 1.5 % of the closed form,
// and half the CFL number halves the error.
TEST(Sh2dResistance, DragDeceleratesAUniformFlowAsItsTerm) {
  const double h = 1.0, u0 = 20.0, c = 0.01, t_end = 10.0;
  const double exact = 1.0 / (1.0 / u0 + c * t_end / h);
  double err[2];
  for (int k = 0; k < 2; ++k) {
    UniformFlow f(h, u0, t_end);
    f.forest(c, 0, false);
    f.cfg.time.cfl = k == 0 ? 0.45 : 0.225;
    const auto r = run_sh2d(f.t, f.cfg, f.init);
    ASSERT_NEAR(r.diag.t, t_end, 1e-9);
    const std::size_t m = UniformFlow::centre();
    err[k] = r.state.HU[m] / r.state.H[m] / exact - 1.0;
    EXPECT_NEAR(r.state.H[m], h, 1e-12);  // no detrainment
  }
  EXPECT_LT(std::abs(err[0]), 0.015) << err[0];
  EXPECT_GT(err[0], 0.0);  // backward Euler lags the deceleration
  EXPECT_NEAR(err[0] / err[1], 2.0, 0.3) << err[0] << " " << err[1];
  // Without the area the layer keeps its speed.
  UniformFlow free(h, u0, t_end);
  const auto r0 = run_sh2d(free.t, free.cfg, free.init);
  EXPECT_NEAR(r0.state.HU[UniformFlow::centre()] / r0.state.H[UniformFlow::centre()], u0, 1e-9);
}

// With detrainment the drag acts only inside its band: a flow faster than speed_max, or deeper than
// depth_max, keeps its speed.
TEST(Sh2dResistance, DragActsOnlyInsideItsBand) {
  for (const auto& [h, u0] : {std::pair{1.0, 45.0}, std::pair{12.0, 20.0}}) {
    UniformFlow f(h, u0, 2.0);
    f.forest(0.01, 5, true);
    const auto r = run_sh2d(f.t, f.cfg, f.init);
    const std::size_t k = UniformFlow::centre();
    EXPECT_NEAR(r.state.HU[k] / r.state.H[k], u0, 1e-9) << "h " << h << " u " << u0;
    EXPECT_EQ(r.diag.volume_detrained, 0.0);
  }
}

// Below speed_min the area detrains dh/dt = -K / (rho u) and the drag stops: on the flat plane the
// layer keeps its speed and thins linearly; the volume balance (initial + inflow = final + outflow +
// detrained) holds to round-off, and the detrained thickness is what the layer lost.
TEST(Sh2dResistance, DetrainmentThinsASlowFlowAtItsRate) {
  const double h = 1.0, u0 = 2.0, K = 5.0, rho = 300, t_end = 10.0;
  UniformFlow f(h, u0, t_end);
  f.forest(0.01, K, true);
  const auto r = run_sh2d(f.t, f.cfg, f.init);
  const std::size_t k = UniformFlow::centre();
  const double lost = K / (rho * u0) * r.diag.t;
  EXPECT_NEAR(r.state.H[k], h - lost, 1e-9);
  EXPECT_NEAR(r.state.HU[k] / r.state.H[k], u0, 1e-9);
  EXPECT_NEAR(r.detrained[k], lost, 1e-9);
  EXPECT_LT(r.diag.volume_error(), 1e-12);
  EXPECT_GT(r.diag.volume_detrained, 0.5 * lost * kN * kN * 25.0);
}

// Material at rest in a detraining area (Coulomb friction holds it) is left on the ground in the
// first step: the flow is empty, the detrained thickness is the release's, the volume balance exact.
TEST(Sh2dResistance, MaterialAtRestInAForestIsLeftOnTheGround) {
  const auto t = inclined_plane(kN, kN, 5.0, 10);
  Sh2dConfig cfg;
  cfg.material.delta = 30 * kDeg;
  cfg.time.t_end = 5;
  const auto h = blob(t, 12, 12, 6, 2.0);
  cfg.resistance.c.assign(t.cells(), 0.01);
  cfg.resistance.k_det.assign(t.cells(), 5.0);
  const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, h));
  EXPECT_EQ(r.diag.volume_final, 0.0);
  EXPECT_LT(r.diag.volume_error(), 1e-12);
  for (std::size_t k = 0; k < t.cells(); ++k) ASSERT_NEAR(r.detrained[k], h[k], 1e-12) << k;
}

// An avalanche down a slope into a forest band, with checkpoints and cancelled at an arbitrary step:
// continued, it computes the bits of the uninterrupted run, the detrained thickness included.
TEST(Sh2dResistance, ContinuedRunIsTheUninterruptedRun) {
  auto t = hillside(100, 40, 5.0, 30, 0.0);
  Sh2dConfig cfg;
  cfg.material.rheology = &friction::voellmy;
  cfg.material.mu = 0.3;
  cfg.material.xi = 1000;
  cfg.time.t_end = 40;
  cfg.tile = 16;
  cfg.resistance.c.assign(t.cells(), 0.0);
  cfg.resistance.k_det.assign(t.cells(), 0.0);
  for (int j = 0; j < t.ny; ++j)
    for (int i = 45; i < 70; ++i) {
      cfg.resistance.c[std::size_t(j) * t.nx + i] = 0.02;
      cfg.resistance.k_det[std::size_t(j) * t.nx + i] = 5;
    }
  const auto init = state_from_normal_depth(t, blob(t, 15, 20, 8, 3.0));
  const auto plain = run_sh2d(t, cfg, init);
  ASSERT_GT(plain.diag.volume_detrained, 0);
  EXPECT_LT(plain.diag.volume_error(), 1e-12);
  expect_continuation(t, cfg, init, plain, [](Sh2dConfig& c) { c.resistance = {}; });
}

// Bad areas are refused by name: sizes, negative coefficients, an inverted band, a flow-dependent law.
TEST(Sh2dResistance, BadAreasAreRefused) {
  UniformFlow f(1.0, 5.0, 1.0);
  auto expect_bad = [&](const Sh2dConfig& cfg, const std::string& needle) { expect_refused(f.t, cfg, f.init, needle); };
  auto c = f.cfg;
  c.resistance.c.assign(3, 0.01);
  expect_bad(c, "resistance areas: field sizes");
  c.resistance.c.assign(f.t.cells(), -0.01);
  expect_bad(c, "finite and >= 0");
  c.resistance.c.assign(f.t.cells(), 0.01);
  c.resistance.speed_min = 50;
  expect_bad(c, "speed_min <= speed_max");
  c.resistance.speed_min = 6;
  c.material = glass_beads_mu_i();
  expect_bad(c, "constant mu");
}
