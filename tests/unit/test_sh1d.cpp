#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/sh1d.hpp"

using namespace runout::engine;
constexpr double kDeg = M_PI / 180.0;

namespace {
Sh1dConfig coulomb(double delta_deg, double t_end) {
  Sh1dConfig c;
  c.material.delta = delta_deg * kDeg;
  c.time.t_end = t_end;
  return c;
}
}  // namespace

TEST(Sh1d, LayerOnSlopeFlatterThanDeltaStaysExactlyAtRest) {
  auto ch = Channel1D::uniform(100, 1.0, 0.0, 20 * kDeg);
  auto cfg = coulomb(25, 50.0);
  Sh1dState s{std::vector<double>(100, 2.0), std::vector<double>(100, 0.0)};
  const auto r = run_sh1d(ch, cfg, s);
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(r.state.h[i], 2.0);
    EXPECT_EQ(r.state.m[i], 0.0);
  }
}

TEST(Sh1d, SlidingLayerStopsAtTheCoulombTimeAndNeverReverses) {
  // Uniform layer on flat ground moving at u0: u(t) = u0 - mu g t until rest at t = u0 / (mu g).
  const int n = 50;
  auto ch = Channel1D::uniform(n, 1.0, 0.0, 0.0);
  auto cfg = coulomb(10, 0.5);
  cfg.left = cfg.right = Boundary1D::outflow;
  const double u0 = 4.0, mu = std::tan(10 * kDeg);
  Sh1dState s{std::vector<double>(n, 1.0), std::vector<double>(n, u0)};
  auto r = run_sh1d(ch, cfg, s);
  EXPECT_NEAR(r.state.m[n / 2], u0 - mu * 9.81 * 0.5, 1e-9);
  cfg.time.t_end = 10.0;  // well past the stop time 2.31 s
  r = run_sh1d(ch, cfg, s);
  for (int i = 0; i < n; ++i) EXPECT_EQ(r.state.m[i], 0.0) << i;
}

TEST(Sh1d, WallsConserveMassOnASlope) {
  // A heap released on a 35 degree slope runs into the lower wall and piles up there.
  const int n = 200;
  auto ch = Channel1D::uniform(n, 0.5, 0.0, 35 * kDeg);
  auto cfg = coulomb(20, 20.0);
  cfg.left = cfg.right = Boundary1D::wall;
  Sh1dState s;
  s.h.resize(n);
  s.m.assign(n, 0.0);
  for (int i = 0; i < n; ++i) s.h[i] = std::max(0.0, 2.0 - std::abs(ch.centre(i) - 30.0) / 5.0);
  const auto r = run_sh1d(ch, cfg, s);
  EXPECT_NEAR(r.mass_final, r.mass_initial, 1e-12 * r.mass_initial);
  EXPECT_EQ(r.positivity_clips, 0);
  double mn = 0;
  for (double h : r.state.h) mn = std::min(mn, h);
  EXPECT_GE(mn, 0.0);
  // The material has reached the lower wall.
  EXPECT_GT(r.state.h[n - 1], 0.5);
}

TEST(Sh1d, InflowDeliversTheHydrographDischarge) {
  const int n = 100;
  auto ch = Channel1D::uniform(n, 1.0, 0.0, 35 * kDeg);
  auto cfg = coulomb(25, 30.0);
  cfg.left = Boundary1D::inflow;
  cfg.right = Boundary1D::outflow;
  cfg.inflow = Hydrograph{{0.0, 10.0, 11.0}, {1.0, 1.0, 0.0}, {5.0, 5.0, 5.0}};
  Sh1dState s{std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)};
  const auto r = run_sh1d(ch, cfg, s);
  // About 10.5 s * 5 m^2/s entered (ramp-down included) and most of it has left again.
  EXPECT_GT(r.boundary_exchange, -5.0);
  EXPECT_LT(r.boundary_exchange, 5.0);
  double h, u;
  cfg.inflow.at(10.5, h, u);
  EXPECT_DOUBLE_EQ(h, 0.5);
  cfg.inflow.at(20, h, u);
  EXPECT_DOUBLE_EQ(h, 0.0);
}

// A gauge downstream of a steady inflow (a laboratory nest's face, jobs/drivers/vof_lab/nest.hpp):
// it reads before the front arrives a dry bed, then the inflow's discharge (steady: h u is the same
// all along the channel), in a flow thinner and faster than at the inflow (45 deg against 32 deg
// friction accelerates it). A gauge outside the channel is refused.
TEST(Sh1d, AGaugeRecordsTheSteadyDischargeDownstreamOfAnInflow) {
  const int n = 240;
  auto ch = Channel1D::uniform(n, 0.59 / n, 0.0, 45 * kDeg);
  auto cfg = coulomb(32, 2.0);
  cfg.left = Boundary1D::inflow;
  cfg.right = Boundary1D::outflow;
  cfg.inflow = Hydrograph{{0.0}, {0.015}, {1.0}};
  std::vector<double> t, h, u;
  cfg.gauge.xi = 0.2;
  cfg.gauge.record = [&](double time, double depth, double speed) {
    t.push_back(time);
    h.push_back(depth);
    u.push_back(speed);
  };
  const auto r = run_sh1d(ch, cfg, Sh1dState{std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)});
  ASSERT_EQ(long(t.size()), r.steps + 1);  // the start and every step
  EXPECT_EQ(t.front(), 0.0);
  EXPECT_EQ(h.front(), 0.0);
  EXPECT_DOUBLE_EQ(t.back(), 2.0);
  EXPECT_NEAR(h.back() * u.back(), 0.015, 0.015 * 1e-3);
  EXPECT_LT(h.back(), 0.013);
  EXPECT_GT(u.back(), 1.15);
  std::printf("gauge at 0.2 m after 2 s: h = %.3f mm, u = %.3f m/s, q = %.6f m2/s (inflow 0.015)\n", 1e3 * h.back(), u.back(),
              h.back() * u.back());
  cfg.gauge.xi = 0.6;
  EXPECT_THROW(run_sh1d(ch, cfg, Sh1dState{std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)}), std::invalid_argument);
}

TEST(Sh1d, KineticEnergyStopRule) {
  const int n = 300;
  auto ch = Channel1D::from_profile(n, 1.0, 0.0, [](double x) { return x < 100 ? 35 * kDeg : 0.0; });
  auto cfg = coulomb(25, 500.0);
  cfg.time.stop_fraction = 0.01;
  cfg.left = cfg.right = Boundary1D::wall;
  Sh1dState s;
  s.h.resize(n);
  s.m.assign(n, 0.0);
  for (int i = 0; i < n; ++i) s.h[i] = std::abs(ch.centre(i) - 30) < 10 ? 2.0 : 0.0;
  const auto r = run_sh1d(ch, cfg, s);
  EXPECT_EQ(r.stop, StopReason::kinetic_energy) << "t = " << r.t << ", exchange " << r.boundary_exchange;
  EXPECT_LT(r.t, 100.0);
  EXPECT_NEAR(r.mass_final, r.mass_initial, 1e-12 * r.mass_initial);
}

TEST(Sh1d, VoellmyLayerReachesItsTerminalSpeed) {
  // Uniform 0.5 m layer on a 35 degree chute: u = sqrt(xi h (sin - mu cos)).
  const int n = 40;
  auto ch = Channel1D::uniform(n, 2.0, 0.0, 35 * kDeg);
  Sh1dConfig cfg;
  cfg.material.rheology = &friction::voellmy;
  cfg.material.mu = 0.25;
  cfg.material.xi = 2000;
  cfg.time.t_end = 200.0;
  Sh1dState s{std::vector<double>(n, 0.5), std::vector<double>(n, 0.0)};
  const auto r = run_sh1d(ch, cfg, s);
  const double expect = std::sqrt(2000 * 0.5 * (std::sin(35 * kDeg) - 0.25 * std::cos(35 * kDeg)));
  EXPECT_NEAR(r.state.m[n / 2] / r.state.h[n / 2], expect, 0.002 * expect);
}

TEST(Sh1d, ProgressHookCanCancel) {
  auto ch = Channel1D::uniform(50, 1.0, 0.0, 30 * kDeg);
  auto cfg = coulomb(20, 100.0);
  int calls = 0;
  cfg.time.progress_every = 5;
  cfg.time.progress = [&](const Progress& p) {
    ++calls;
    EXPECT_GT(p.dt, 0.0);
    return calls < 3;
  };
  Sh1dState s{std::vector<double>(50, 1.0), std::vector<double>(50, 0.0)};
  const auto r = run_sh1d(ch, cfg, s);
  EXPECT_EQ(r.stop, StopReason::cancelled);
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(r.steps, 15);
}

TEST(Sh1d, BadInputIsRejectedWithAMessage) {
  auto ch = Channel1D::uniform(50, 1.0, 0.0, 30 * kDeg);
  auto cfg = coulomb(20, 1.0);
  Sh1dState s{std::vector<double>(50, 1.0), std::vector<double>(50, 0.0)};
  cfg.time.cfl = 0.8;
  EXPECT_THROW(run_sh1d(ch, cfg, s), std::invalid_argument);
  cfg.time.cfl = 0.4;
  s.h[3] = -1;
  EXPECT_THROW(run_sh1d(ch, cfg, s), std::invalid_argument);
  s.h[3] = 1;
  s.m.pop_back();
  EXPECT_THROW(run_sh1d(ch, cfg, s), std::invalid_argument);
  s.m.push_back(0);
  cfg.left = Boundary1D::inflow;
  try {
    run_sh1d(ch, cfg, s);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("hydrograph"), std::string::npos);
  }
}

TEST(Sh1d, CurvatureRaisesFrictionInConcaveBends) {
  const int n = 600;
  auto prof = [](double x) { return x < 100 ? 35 * kDeg : (x > 200 ? 0.0 : 35 * kDeg * (200 - x) / 100); };
  auto ch = Channel1D::from_profile(n, 1.0, 0.0, prof);
  EXPECT_GT(ch.kappa[150], 0.0);
  auto cfg = coulomb(20, 200.0);
  cfg.time.stop_fraction = 1e-4;
  Sh1dState s;
  s.h.resize(n);
  s.m.assign(n, 0.0);
  for (int i = 0; i < n; ++i) s.h[i] = std::abs(ch.centre(i) - 40) < 10 ? 2.0 : 0.0;
  auto front = [&](const Sh1dResult& r) {
    for (int i = n - 1; i >= 0; --i)
      if (r.state.h[i] > 0.01) return ch.centre(i);
    return 0.0;
  };
  const double with = front(run_sh1d(ch, cfg, s));
  cfg.curvature = false;
  const double without = front(run_sh1d(ch, cfg, s));
  EXPECT_LT(with, without - 5.0);
}
