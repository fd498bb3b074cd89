// The flow-dependent friction laws (Pouliquen-Forterre, mu(I)) in the depth-averaged engines: steady
// uniform flow on an inclined plane against Pouliquen's flow rule and the Bagnold speed, the start/stop
// hysteresis, the Coulomb limit bit for bit, thread-count independence, the row kernels against the
// per-cell functions, and the 1D and 2D engines against each other.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "engine/sh1d.hpp"
#include "engine/sh2d.hpp"
#include "tests/support/depth_averaged.hpp"

using namespace runout::engine;
using namespace runout::test_support::depth_averaged;

namespace {

constexpr double g = 9.81;

// A uniform layer of depth h at rest on an infinite chute at theta (outflow ends: it stays uniform).
Sh1dResult chute_1d(const Material& m, double theta_deg, double h, double t_end) {
  const int n = 16;
  Sh1dConfig cfg;
  cfg.material = m;
  cfg.time.t_end = t_end;
  cfg.time.stop_fraction = 0;
  return run_sh1d(Channel1D::uniform(n, 0.01, 0.0, theta_deg * kDeg), cfg,
                  Sh1dState{std::vector<double>(n, h), std::vector<double>(n, 0.0)});
}

// h_stop(theta) of Pouliquen-Forterre: the depth a steady flow leaves behind.
double h_stop(const Material& m, double theta) {
  const double t1 = std::tan(m.delta1), t2 = std::tan(m.delta2), t = std::tan(theta);
  return m.pf_length * (t2 - t) / (t - t1);
}

// Materials on the scale of the 5 m terrains of the 2D tests.
Material pf_coarse() { return pouliquen_forterre_material(15 * kDeg, 30 * kDeg, 18 * kDeg, 0.136, 0.1, 0.04); }
Material mu_i_coarse() { return mu_i_material(0.3, 0.6, 0.279, 0.05, 2500, 1500); }

}  // namespace

// Glass beads, 3 mm on 29 degrees: the layer accelerates from rest to Pouliquen's flow rule
// Fr = beta h / h_stop(theta) - gamma (here Fr = 0.90). The discrete steady state is the exact one:
// mu is evaluated where the friction's load is, and there u is the steady speed.
TEST(FlowFriction1d, PouliquenForterreLayerReachesTheFlowRule) {
  const double th = 29 * kDeg, h = 3e-3;
  for (double gamma : {0.0, 0.05}) {
    const auto m = glass_beads_pf(22.0, gamma);
    const auto r = chute_1d(m, 29.0, h, 10.0);
    const double fr = r.state.m[8] / r.state.h[8] / std::sqrt(g * std::cos(th) * r.state.h[8]);
    const double expect = m.pf_beta * h / h_stop(m, th) - gamma;
    EXPECT_NEAR(r.state.h[8], h, 1e-15);
    EXPECT_NEAR(fr, expect, 1e-9 * expect) << "gamma " << gamma;
  }
}

// mu(I) for glass beads, 5 mm on 25 degrees: the Bagnold profile's depth-averaged speed
// u = (2/5) I sqrt(phi g cos(theta)) h^(3/2) / d with I = I_0 (tan(theta) - mu_s) / (mu_2 - tan(theta)).
TEST(FlowFriction1d, MuILayerReachesTheBagnoldSpeed) {
  const auto m = glass_beads_mu_i();
  const double th = 25 * kDeg, h = 5e-3, phi = m.density / m.grain_density;
  const double I = m.mu_i0 * (std::tan(th) - m.mu_s) / (m.mu_2 - std::tan(th));
  const double expect = 0.4 * I * std::sqrt(phi * g * std::cos(th)) * std::pow(h, 1.5) / m.grain_diameter;
  const auto r = chute_1d(m, 25.0, h, 10.0);
  EXPECT_NEAR(r.state.m[8] / r.state.h[8], expect, 1e-9 * expect);
}

// On 24 degrees h_stop = 2.6 mm and h_start = 9.6 mm (delta_3 = 23 deg): a 5 mm layer at rest stays
// exactly at rest in both engines (Coulomb friction at delta_1 would let it slide), a 12 mm layer starts.
TEST(FlowFriction1d, LayersBelowHStartStayAtRest) {
  const auto m = glass_beads_pf(23.0, 0.0);
  const double t1 = std::tan(m.delta1), dt = std::tan(m.delta2) - t1, t3 = std::tan(m.delta3), t = std::tan(24 * kDeg);
  const double h_start = m.pf_length * (dt - (t - t3)) / (t - t3);
  ASSERT_LT(h_stop(m, 24 * kDeg), 5e-3);
  ASSERT_GT(h_start, 5e-3);
  ASSERT_LT(h_start, 12e-3);
  const auto rest = chute_1d(m, 24.0, 5e-3, 2.0);
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(rest.state.m[i], 0.0);
    EXPECT_EQ(rest.state.h[i], 5e-3);
  }
  const auto flows = chute_1d(m, 24.0, 12e-3, 2.0);
  EXPECT_GT(flows.state.m[8], 0.0);
  const auto plane = inclined_plane(12, 6, 0.01, 24.0);
  Sh2dConfig cfg;
  cfg.material = m;
  cfg.time.t_end = 2.0;
  cfg.south = cfg.north = Boundary2D::wall;
  const auto init = state_from_normal_depth(plane, std::vector<double>(plane.cells(), 5e-3));
  const auto r = run_sh2d(plane, cfg, init);
  EXPECT_EQ(r.state.H, init.H);
  for (double M : r.state.HU) ASSERT_EQ(M, 0.0);
}

// mu(I) with mu_2 = mu_s is Coulomb friction with tan(delta) = mu_s: the same bits in every cell,
// through the vector kernels and the per-cell functions alike.
TEST(FlowFriction2d, MuIWithEqualCoefficientsIsCoulombBitForBit) {
  const auto t = hillside(150, 120, 5.0, 32, 0.4);
  Sh2dConfig cfg;
  cfg.material.delta = 22 * kDeg;
  cfg.time.t_end = 30.0;
  cfg.tile = 16;
  cfg.south = Boundary2D::wall;
  const auto init = state_from_normal_depth(t, blob(t, 30, 30, 10, 3.0));
  const auto coulomb = run_sh2d(t, cfg, init);
  cfg.material = mu_i_coarse();
  cfg.material.mu_s = cfg.material.mu_2 = std::tan(22 * kDeg);
  cfg.material.density = Material{}.density;  // the pressure map's
  const auto mu_i = run_sh2d(t, cfg, init);
  expect_same(coulomb, mu_i);
  EXPECT_GT(coulomb.diag.max_speed, 5.0);  // it did flow
}

TEST(FlowFriction2d, ResultsAreIdenticalForAnyThreadCount) {
  const auto t = hillside(150, 120, 5.0, 32, 0.4);
  const auto init = state_from_normal_depth(t, blob(t, 30, 30, 10, 3.0));
  for (const Material& m : {pf_coarse(), mu_i_coarse()}) {
    Sh2dConfig cfg;
    cfg.material = m;
    cfg.time.t_end = 30.0;
    cfg.tile = 16;
    omp_set_num_threads(1);
    const auto a = run_sh2d(t, cfg, init);
    omp_set_num_threads(2);
    const auto b = run_sh2d(t, cfg, init);
    expect_same(a, b);
    EXPECT_GT(a.diag.max_speed, 5.0) << m.rheology->name;
  }
}

// A flow uniform across a curved chute between two walls: the edge rows take the per-cell functions
// (general predictor, update_cell), the rows between them the row kernels. Both give the same bits.
TEST(FlowFriction2d, CellFunctionsGiveTheRowKernelsBits) {
  const auto t = terrain_of(120, 6, 5.0, [](double x, double) { return 300.0 * std::exp(-x / 200.0); });
  std::vector<double> h(t.cells(), 0.0);
  for (int j = 0; j < t.ny; ++j)
    for (int i = 5; i < 25; ++i) h[std::size_t(j) * t.nx + i] = 3.0 * (1 - std::pow((i - 15) / 10.0, 2));
  for (const Material& m : {Material{}, pf_coarse(), mu_i_coarse()}) {
    Sh2dConfig cfg;
    cfg.material = m;
    if (m.rheology == &friction::coulomb) cfg.material.delta = 20 * kDeg;
    cfg.time.t_end = 40.0;
    cfg.south = cfg.north = Boundary2D::wall;
    const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, h));
    EXPECT_GT(r.diag.max_speed, 5.0) << m.rheology->name;
    for (int j : {0, t.ny - 1})
      for (int i = 0; i < t.nx; ++i) {
        const std::size_t edge = std::size_t(j) * t.nx + i, inner = std::size_t(2) * t.nx + i;
        ASSERT_EQ(r.state.H[edge], r.state.H[inner]) << m.rheology->name << " " << i << " " << j;
        ASSERT_EQ(r.state.HU[edge], r.state.HU[inner]) << m.rheology->name << " " << i << " " << j;
        ASSERT_EQ(r.hazard.max_speed[edge], r.hazard.max_speed[inner]) << m.rheology->name << " " << i << " " << j;
      }
  }
}

// The same uniform layer on a plane in both engines, at the same fixed step: the same accelerating
// flow (to round-off), up to the flow rule.
TEST(FlowFriction2d, AgreesWithThe1dEngineOnAPlane) {
  const double th = 29 * kDeg, h = 3e-3;
  for (const Material& m : {glass_beads_pf(22.0, 0.05), glass_beads_mu_i()}) {
    Sh1dConfig c1;
    c1.material = m;
    c1.time.dt_max = 2e-3;
    c1.time.stop_fraction = 0;
    Sh2dConfig c2;
    c2.material = m;
    c2.time.dt_max = 2e-3;
    c2.time.stop_fraction = 0;
    c2.south = c2.north = Boundary2D::wall;
    const auto plane = inclined_plane(12, 6, 0.01, 29.0);
    for (double t_end : {0.1, 0.4, 6.0}) {
      c1.time.t_end = c2.time.t_end = t_end;
      const auto a = run_sh1d(Channel1D::uniform(12, 0.01, 0.0, th), c1, Sh1dState{std::vector<double>(12, h), std::vector<double>(12, 0.0)});
      const auto b = run_sh2d(plane, c2, state_from_normal_depth(plane, std::vector<double>(plane.cells(), h)));
      const std::size_t k = std::size_t(3) * plane.nx + 6;
      const double u1 = a.state.m[6] / a.state.h[6], u2 = std::hypot(b.state.HU[k], std::tan(th) * b.state.HU[k]) / b.state.H[k];
      EXPECT_NEAR(u2, u1, 1e-10 * u1) << m.rheology->name << ", t = " << t_end;
      EXPECT_NEAR(b.state.H[k] * std::cos(th), h, 1e-15);
    }
  }
}

// A new friction law is one header (a FrictionLaw: name, caption, equation, parameter rows, the
// coefficients of law.hpp's family and the checks) plus its line in registry.hpp's table; the kernels
// need nothing else. This example law, a Coulomb angle with Voellmy's drag, is defined here and
// given to both engines directly: it computes Voellmy's bits, and its check names its parameter.
namespace {

constexpr FrictionLaw kExampleLaw{
    "example_coulomb_drag",
    "Coulomb with drag",
    "tau_b = tan(delta) N + rho g |u|^2 / xi (an example law of the unit tests)",
    {{{"bed_friction_deg", "delta", "δ", "°", "bed friction angle"}, {"voellmy_xi", "xi", "ξ", "m/s²", "turbulent-friction coefficient"}}},
    [](const FrictionParams& p) { return BasalFriction{std::tan(p.delta), 1.0 / p.xi}; },
    [](const FrictionParams& p) -> const char* { return p.xi > 0 ? "" : "example law: xi must be > 0 m/s^2"; }};

}  // namespace

TEST(FrictionLaws, AnExampleLawRunsInBothEnginesWithoutChangesToTheKernels) {
  Material example;
  example.rheology = &kExampleLaw;
  example.delta = 20 * kDeg;
  example.xi = 500;
  Material voellmy;
  voellmy.rheology = &friction::voellmy;
  voellmy.mu = std::tan(20 * kDeg);
  voellmy.xi = 500;
  // 2D: a blob down a hillside.
  const auto t = hillside(60, 40, 5.0, 30, 0.3);
  Sh2dConfig c2;
  c2.time.t_end = 8;
  c2.tile = 16;
  c2.material = example;
  const auto a = run_sh2d(t, c2, state_from_normal_depth(t, blob(t, 12, 20, 6, 2.0)));
  c2.material = voellmy;
  const auto b = run_sh2d(t, c2, state_from_normal_depth(t, blob(t, 12, 20, 6, 2.0)));
  ASSERT_GT(a.diag.steps, 10);
  EXPECT_EQ(a.diag.steps, b.diag.steps);
  EXPECT_EQ(a.state.H, b.state.H);
  EXPECT_EQ(a.hazard.max_speed, b.hazard.max_speed);
  // 1D: the uniform chute.
  const auto a1 = chute_1d(example, 35, 0.5, 2.0), b1 = chute_1d(voellmy, 35, 0.5, 2.0);
  EXPECT_EQ(a1.state.m, b1.state.m);
  // Its check runs with every material's.
  example.xi = 0;
  try {
    example.validate();
    FAIL() << "xi = 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("example law: xi"), std::string::npos) << e.what();
  }
}
