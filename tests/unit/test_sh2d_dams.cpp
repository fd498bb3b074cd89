// Dams and walls in the depth-averaged engine (engine/sh2d.hpp Sh2dConfig::dam_height): a lake at rest
// against a dam stays at rest to the bit, a flow over a low dam is counted by the crest's flux gauge
// exactly as the volume balance moves it, a run continued from a checkpoint is the uninterrupted run,
// and bad dam heights are refused.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "tests/support/depth_averaged.hpp"

using namespace runout::engine;
using namespace runout::test_support::depth_averaged;

namespace {

constexpr int kNx = 60, kNy = 24, kDam = 30;  // the dam: the column of cells i = kDam
constexpr double kDx = 5.0;

// Flat ground walled on every edge, a dam of height `height` across it at i = kDam, with a flux
// gauge over its cells (west faces lead left, east faces right).
struct DammedFlat {
  Terrain2D t = terrain_of(kNx, kNy, kDx, [](double, double) { return 0.0; });
  Sh2dConfig cfg;
  explicit DammedFlat(double height) {
    cfg.west = cfg.east = cfg.south = cfg.north = Boundary2D::wall;
    cfg.tile = 16;
    cfg.dam_height.assign(t.cells(), 0.0);
    FluxGauge g{"dam", {}, {}};
    for (int j = 0; j < kNy; ++j) {
      const std::size_t k = std::size_t(j) * kNx + kDam;
      cfg.dam_height[k] = height;
      g.cells.push_back(k);
      g.sides.push_back({-1, 1, 0, 0});
    }
    cfg.gauges.push_back(g);
  }
  // The volume east of the dam in a state.
  double east_of_dam(const std::vector<double>& H) const {
    double v = 0;
    for (int j = 0; j < kNy; ++j)
      for (int i = kDam + 1; i < kNx; ++i) v += H[std::size_t(j) * kNx + i];
    return v * kDx * kDx;
  }
};

}  // namespace

// Lakes 2 m deep west of a 3 m dam and 1 m deep east of it, frictionless: the dam's faces push back
// exactly what the lake's pressure pushes (a wall's mirror flux), so nothing moves, to the bit.
TEST(Sh2dDams, ALakeAtRestAgainstADamStaysAtRest) {
  DammedFlat f(3.0);
  f.cfg.material.delta = 0;
  f.cfg.time.t_end = 60;
  f.cfg.time.stop_fraction = 0;
  std::vector<double> h(f.t.cells(), 0.0);
  for (int j = 0; j < kNy; ++j)
    for (int i = 0; i < kNx; ++i) h[std::size_t(j) * kNx + i] = i < kDam ? 2.0 : i > kDam ? 1.0 : 0.0;
  const auto init = state_from_normal_depth(f.t, h);
  const auto r = run_sh2d(f.t, f.cfg, init);
  ASSERT_GT(r.diag.steps, 10);
  EXPECT_EQ(r.state.H, init.H);
  for (std::size_t k = 0; k < f.t.cells(); ++k) {
    ASSERT_EQ(r.state.HU[k], 0.0) << k;
    ASSERT_EQ(r.state.HV[k], 0.0) << k;
  }
  EXPECT_EQ(r.gauge_right[0], 0.0);
  EXPECT_EQ(r.gauge_left[0], 0.0);
}

// The same lakes on several tiles, where the dam and the lakes meet cells outside the domain (the
// top row, dams standing on some of them) and across tile borders, on one and on two threads: at
// rest to the bit (a face whose flux does not take the step's, towards the outside, puts no wall
// reaction on its cells).
TEST(Sh2dDams, ALakeAtRestStaysAtRestWhereTheDamMeetsTheOutside) {
  DammedFlat f(3.0);
  f.cfg.material.delta = 0;
  f.cfg.time.t_end = 30;
  f.cfg.time.stop_fraction = 0;
  f.cfg.tile = 8;
  f.t.outside.assign(f.t.cells(), 0);
  for (int i = 0; i < kNx; ++i) {
    const std::size_t k = std::size_t(kNy - 1) * kNx + i;
    f.t.outside[k] = 1;
    f.cfg.dam_height[k] = i % 3 == 0 ? 2.5 : 0.0;  // dams on outside cells too: steps towards the outside
  }
  f.cfg.gauges.clear();
  std::vector<double> h(f.t.cells(), 0.0);
  for (int j = 0; j < kNy - 1; ++j)
    for (int i = 0; i < kNx; ++i) h[std::size_t(j) * kNx + i] = i < kDam ? 2.0 : i > kDam ? 1.0 : 0.0;
  const auto init = state_from_normal_depth(f.t, h);
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    const auto r = run_sh2d(f.t, f.cfg, init);
    EXPECT_EQ(r.state.H, init.H) << threads << " thread(s)";
    for (std::size_t k = 0; k < f.t.cells(); ++k) {
      ASSERT_EQ(r.state.HU[k], 0.0) << k << ", " << threads << " thread(s)";
      ASSERT_EQ(r.state.HV[k], 0.0) << k << ", " << threads << " thread(s)";
    }
  }
}

// A pile 8 m high collapses against a dam 1 m high (Coulomb, 2 deg): part of it passes. What the
// crest's gauge counted to its right is the volume found east of the dam, to round-off (walls all
// round: nothing leaves), and the volume balance holds.
TEST(Sh2dDams, TheCrestsGaugeCountsWhatPassed) {
  DammedFlat f(1.0);
  f.cfg.material.delta = 2 * kDeg;
  f.cfg.time.t_end = 60;
  const auto r = run_sh2d(f.t, f.cfg, state_from_normal_depth(f.t, blob(f.t, 20, 12, 8, 8.0)));
  const double east = f.east_of_dam(r.state.H);
  EXPECT_GT(east, 0.02 * r.diag.volume_initial);
  EXPECT_LT(east, 0.5 * r.diag.volume_initial);
  EXPECT_NEAR(r.gauge_right[0], east, 1e-11 * r.diag.volume_initial);
  EXPECT_LT(r.gauge_left[0], 0.0);  // what passed came in from the west
  EXPECT_LT(r.diag.volume_error(), 1e-12);
  // A dam higher than the pile's run-up lets nothing pass.
  DammedFlat high(20.0);
  high.cfg.material = f.cfg.material;
  high.cfg.time = f.cfg.time;
  const auto h = run_sh2d(high.t, high.cfg, state_from_normal_depth(high.t, blob(high.t, 20, 12, 8, 8.0)));
  EXPECT_EQ(high.east_of_dam(h.state.H), 0.0);
  EXPECT_EQ(h.gauge_right[0], 0.0);
}

// The run over the low dam, with checkpoints and cancelled at about half its steps: continued, it
// computes the bits of the uninterrupted run, the gauges included; a checkpoint of the run without
// the dam does not continue it.
TEST(Sh2dDams, ContinuedRunIsTheUninterruptedRun) {
  DammedFlat f(1.0);
  f.cfg.material.delta = 2 * kDeg;
  f.cfg.time.t_end = 40;
  const auto init = state_from_normal_depth(f.t, blob(f.t, 20, 12, 8, 8.0));
  const auto plain = run_sh2d(f.t, f.cfg, init);
  ASSERT_GT(plain.gauge_right[0], 0.0);
  expect_continuation(f.t, f.cfg, init, plain, [](Sh2dConfig& c) {
    c.dam_height.clear();
    c.gauges.clear();
  });
}

// Dam heights of the wrong size, negative or not a number are refused by name.
TEST(Sh2dDams, BadDamHeightsAreRefused) {
  DammedFlat f(1.0);
  f.cfg.time.t_end = 1;
  const auto init = state_from_normal_depth(f.t, blob(f.t, 20, 12, 8, 8.0));
  auto c = f.cfg;
  c.dam_height.pop_back();
  expect_refused(f.t, c, init, "dams: the dam heights' size");
  c = f.cfg;
  c.dam_height[5] = -1;
  expect_refused(f.t, c, init, "dams: a dam height must lie in [0, 1000] m (cell 5)");
  c = f.cfg;
  c.dam_height[7] = std::numeric_limits<double>::quiet_NaN();
  expect_refused(f.t, c, init, "(cell 7)");
}
