#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <limits>

#include "engine/sh2d.hpp"
#include "tests/support/depth_averaged.hpp"

using namespace runout::engine;
using namespace runout::test_support::depth_averaged;

namespace {

Sh2dConfig coulomb(double delta_deg, double t_end) {
  Sh2dConfig c;
  c.material.delta = delta_deg * kDeg;
  c.time.t_end = t_end;
  return c;
}

}  // namespace

TEST(Sh2d, ResultsAreIdenticalForAnyThreadCount) {
  const auto t = hillside(150, 120, 5.0, 32, 0.4);
  auto cfg = coulomb(22, 30.0);
  cfg.tile = 16;
  const auto init = state_from_normal_depth(t, blob(t, 30, 30, 10, 3.0));
  omp_set_num_threads(1);
  const auto a = run_sh2d(t, cfg, init);
  omp_set_num_threads(2);
  const auto b = run_sh2d(t, cfg, init);
  ASSERT_EQ(a.diag.steps, b.diag.steps);
  EXPECT_EQ(a.state.H, b.state.H);
  EXPECT_EQ(a.state.HU, b.state.HU);
  EXPECT_EQ(a.hazard.max_speed, b.hazard.max_speed);
  EXPECT_EQ(a.diag.volume_final, b.diag.volume_final);
  EXPECT_GT(a.diag.max_speed, 5.0);  // it did flow
}

TEST(Sh2d, SkippingDryTilesChangesNothingButTheCost) {
  const auto t = hillside(256, 256, 4.0, 30, 0.0);
  auto cfg = coulomb(24, 20.0);
  const auto init = state_from_normal_depth(t, blob(t, 40, 128, 8, 3.0));
  const auto fast = run_sh2d(t, cfg, init);
  cfg.skip_inactive = false;
  const auto full = run_sh2d(t, cfg, init);
  ASSERT_EQ(fast.diag.steps, full.diag.steps);
  double dmax = 0;
  for (std::size_t k = 0; k < t.cells(); ++k) dmax = std::max(dmax, std::abs(fast.hazard.max_depth[k] - full.hazard.max_depth[k]));
  EXPECT_LT(dmax, 1e-9);
  EXPECT_LT(fast.diag.cell_updates, 0.25 * full.diag.cell_updates);
  EXPECT_LT(fast.diag.mean_active_fraction, 0.25);
  EXPECT_NEAR(full.diag.mean_active_fraction, 1.0, 1e-12);
}

// Inside an active tile only the cells within two cells of material are computed (the scheme's
// stencil): the others would come out empty anyway, bit for bit.
TEST(Sh2d, ComputingOnlyTheCellsWithinReachOfMaterialChangesNoBit) {
  const auto t = hillside(200, 160, 4.0, 32, 0.3);
  auto cfg = coulomb(20, 40.0);
  const auto init = state_from_normal_depth(t, blob(t, 40, 60, 9, 3.0));
  const auto fast = run_sh2d(t, cfg, init);
  cfg.skip_empty = false;
  const auto whole = run_sh2d(t, cfg, init);
  ASSERT_EQ(fast.diag.steps, whole.diag.steps);
  EXPECT_EQ(fast.state.H, whole.state.H);
  EXPECT_EQ(fast.state.HU, whole.state.HU);
  EXPECT_EQ(fast.state.HV, whole.state.HV);
  EXPECT_EQ(fast.hazard.max_depth, whole.hazard.max_depth);
  EXPECT_EQ(fast.hazard.max_speed, whole.hazard.max_speed);
  EXPECT_EQ(fast.hazard.max_pressure, whole.hazard.max_pressure);
  for (std::size_t k = 0; k < t.cells(); ++k)  // NaN where never reached: compare the bits
    ASSERT_EQ(std::isnan(fast.hazard.arrival_time[k]) ? -1.0 : fast.hazard.arrival_time[k],
              std::isnan(whole.hazard.arrival_time[k]) ? -1.0 : whole.hazard.arrival_time[k]);
  EXPECT_EQ(fast.diag.volume_final, whole.diag.volume_final);
  EXPECT_EQ(fast.diag.kinetic_energy_peak, whole.diag.kinetic_energy_peak);
  EXPECT_GT(fast.diag.max_speed, 5.0);  // it did flow
  EXPECT_LT(fast.diag.cell_updates, 0.8 * whole.diag.cell_updates);
}

TEST(Sh2d, TransposedTerrainGivesTheTransposedResult) {
  const int n = 96;
  const auto tx = hillside(n, n, 3.0, 30, 0.0);
  auto ty = tx;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) ty.z[std::size_t(j) * n + i] = tx.z[std::size_t(i) * n + j];
  auto cfg = coulomb(20, 15.0);
  const auto hx = blob(tx, 20, 48, 8, 2.0);
  std::vector<double> hy(hx.size());
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) hy[std::size_t(j) * n + i] = hx[std::size_t(i) * n + j];
  const auto a = run_sh2d(tx, cfg, state_from_normal_depth(tx, hx));
  const auto b = run_sh2d(ty, cfg, state_from_normal_depth(ty, hy));
  double d = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      d = std::max(d, std::abs(a.hazard.max_depth[std::size_t(j) * n + i] - b.hazard.max_depth[std::size_t(i) * n + j]));
  EXPECT_LT(d, 1e-10);
}

TEST(Sh2d, ClosedBoxConservesVolumeToRoundOff) {
  const auto t = hillside(80, 60, 5.0, 40, 0.7);
  auto cfg = coulomb(15, 60.0);
  cfg.west = cfg.east = cfg.south = cfg.north = Boundary2D::wall;
  const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, blob(t, 30, 20, 12, 5.0)));
  EXPECT_EQ(r.diag.volume_outflow, 0.0);
  EXPECT_LT(r.diag.volume_error(), 1e-13);
  for (double H : r.state.H) EXPECT_GE(H, 0.0);
}

TEST(Sh2d, OutflowIsAccountedFor) {
  const auto t = hillside(60, 40, 5.0, 35, 0.0);
  auto cfg = coulomb(10, 40.0);
  const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, blob(t, 20, 20, 8, 3.0)));
  EXPECT_GT(r.diag.volume_outflow, 0.5 * r.diag.volume_initial);
  EXPECT_LT(r.diag.volume_error(), 1e-12);
}

TEST(Sh2d, VoellmyLayerReachesItsTerminalSpeed) {
  // Uniform 2 m layer on an infinite 30 degree slope: g sin - mu g cos - g u^2 / (xi h) = 0.
  const auto t = inclined_plane(12, 12, 5.0, 30);
  const double th = 30 * kDeg;
  Sh2dConfig cfg;
  cfg.material.rheology = &friction::voellmy;
  cfg.material.mu = 0.2;
  cfg.material.xi = 1000.0;
  cfg.time.t_end = 120.0;
  cfg.south = cfg.north = Boundary2D::wall;
  // An infinite slope: the outflow ghosts copy the state, so the uniform layer stays uniform.
  const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, std::vector<double>(t.cells(), 2.0)));
  const double expect = std::sqrt(1000.0 * 2.0 * (std::sin(th) - 0.2 * std::cos(th)));
  const std::size_t k = std::size_t(6) * t.nx + 6;
  EXPECT_NEAR(r.hazard.max_speed[k], expect, 0.005 * expect);
  EXPECT_NEAR(r.hazard.final_depth[k], 2.0, 1e-9);
}

TEST(Sh2d, HazardMapsAreConsistent) {
  const auto t = hillside(120, 80, 5.0, 30, 0.0);
  auto cfg = coulomb(22, 40.0);
  cfg.material.density = 300;
  cfg.flow_threshold = 0.05;
  const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, blob(t, 20, 40, 8, 3.0)));
  const auto& hz = r.hazard;
  int reached = 0, never = 0;
  for (std::size_t k = 0; k < t.cells(); ++k) {
    EXPECT_GE(hz.max_depth[k] + 1e-15, hz.final_depth[k]);
    EXPECT_NEAR(hz.max_pressure[k], 300 * hz.max_speed[k] * hz.max_speed[k], 1e-9 * (1 + hz.max_pressure[k]));
    if (std::isnan(hz.arrival_time[k])) {
      EXPECT_LE(hz.max_depth[k], 0.05);
      EXPECT_EQ(hz.max_speed[k], 0.0);  // thin films do not enter the speed and pressure maps
      EXPECT_EQ(hz.max_pressure[k], 0.0);
      ++never;
    } else {
      EXPECT_GT(hz.max_depth[k], 0.05);
      EXPECT_LE(hz.arrival_time[k], r.diag.t);
      ++reached;
    }
  }
  EXPECT_GT(reached, 100);
  EXPECT_GT(never, 100);
  // Release cells have arrival time 0; cells further down arrive later.
  EXPECT_EQ(hz.arrival_time[std::size_t(40) * t.nx + 20], 0.0);
  EXPECT_GT(hz.arrival_time[std::size_t(40) * t.nx + 35], hz.arrival_time[std::size_t(40) * t.nx + 30]);
  EXPECT_GT(hz.arrival_time[std::size_t(40) * t.nx + 30], 0.0);
}

TEST(Sh2d, StopsWhenKineticEnergyHasDecayed) {
  auto t = hillside(150, 60, 4.0, 30, 0.0);
  for (int j = 0; j < t.ny; ++j)  // flat run-out beyond x = 300 m
    for (int i = 0; i < t.nx; ++i) {
      auto& z = t.z[std::size_t(j) * t.nx + i];
      z = std::max(z, t.z[std::size_t(j) * t.nx + 75]);
    }
  auto cfg = coulomb(25, 1000.0);
  cfg.time.stop_fraction = 0.01;
  const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, blob(t, 20, 30, 8, 3.0)));
  EXPECT_EQ(r.diag.stop, StopReason::kinetic_energy);
  EXPECT_LT(r.diag.t, 200.0);
}

TEST(Sh2d, EarthPressureActivePassiveRunsAndConserves) {
  const auto t = hillside(100, 80, 4.0, 35, 0.3);
  auto cfg = coulomb(20, 30.0);
  cfg.material.earth_pressure = EarthPressure::active_passive;
  cfg.material.phi = 32 * kDeg;
  cfg.west = cfg.east = cfg.south = cfg.north = Boundary2D::wall;
  const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, blob(t, 25, 40, 10, 4.0)));
  EXPECT_LT(r.diag.volume_error(), 1e-13);
  EXPECT_GT(r.diag.max_speed, 3.0);
}

TEST(Sh2d, ProgressIsReportedAndCancellationStopsTheRun) {
  const auto t = hillside(60, 60, 5.0, 30, 0.0);
  auto cfg = coulomb(20, 100.0);
  cfg.time.progress_every = 10;
  int calls = 0;
  double last_t = 0;
  cfg.time.progress = [&](const Progress& p) {
    ++calls;
    EXPECT_GT(p.t, last_t);
    last_t = p.t;
    EXPECT_GT(p.mass, 0.0);
    EXPECT_GT(p.active_fraction, 0.0);
    return calls < 4;
  };
  const auto r = run_sh2d(t, cfg, state_from_normal_depth(t, blob(t, 20, 30, 8, 2.0)));
  EXPECT_EQ(r.diag.stop, StopReason::cancelled);
  EXPECT_EQ(r.diag.steps, 40);
}

TEST(Sh2d, BadInputIsRejectedWithAMessage) {
  auto t = hillside(20, 20, 5.0, 30, 0.0);
  auto cfg = coulomb(20, 1.0);
  auto s = state_from_normal_depth(t, std::vector<double>(t.cells(), 1.0));
  t.z[5] = std::nan("");
  try {
    run_sh2d(t, cfg, s);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("finite"), std::string::npos);
  }
  t.z[5] = 0;
  cfg.time.cfl = 0.6;
  EXPECT_THROW(run_sh2d(t, cfg, s), std::invalid_argument);
  cfg.time.cfl = 0.4;
  s.H[3] = -0.1;
  EXPECT_THROW(run_sh2d(t, cfg, s), std::invalid_argument);
  s.H[3] = 1;
  cfg.material.delta = 95 * kDeg;
  EXPECT_THROW(run_sh2d(t, cfg, s), std::invalid_argument);
  EXPECT_THROW(state_from_normal_depth(t, std::vector<double>(3, 1.0)), std::invalid_argument);
}

TEST(Sh2d, SnapshotsComeAtTheIntervalAndChangeNothing) {
  const auto t = hillside(80, 60, 5.0, 30, 0.0);
  auto cfg = coulomb(22, 20.0);
  cfg.west = cfg.east = cfg.south = cfg.north = Boundary2D::wall;
  const auto init = state_from_normal_depth(t, blob(t, 20, 30, 8, 3.0));
  const auto plain = run_sh2d(t, cfg, init);
  std::vector<double> times;
  double volume0 = 0;
  cfg.snapshot_interval = 5.0;
  cfg.snapshot = [&](double time, const Sh2dStateView& s) {
    times.push_back(time);
    double v = 0;
    for (double H : s.H) v += H;
    if (times.size() == 1) volume0 = v;
    EXPECT_NEAR(v, volume0, 1e-12 * volume0);
  };
  const auto with = run_sh2d(t, cfg, init);
  EXPECT_EQ(plain.state.H, with.state.H);  // snapshots do not change the steps
  ASSERT_EQ(times.size(), 5u);             // 0, >= 5, >= 10, >= 15, end (20)
  EXPECT_EQ(times[0], 0.0);
  for (int k = 1; k < 4; ++k) {
    EXPECT_GE(times[k], 5.0 * k);
    EXPECT_LT(times[k], 5.0 * k + 0.5);
  }
  EXPECT_EQ(times.back(), with.diag.t);
}

TEST(Sh2d, CellsOutsideTheDomainSwallowWhatReachesThem) {
  // A closed box on a slope with a block of cells outside the domain in the flow's path.
  auto t = hillside(120, 80, 5.0, 30, 0.0);
  t.outside.assign(t.cells(), 0);
  for (int j = 30; j < 50; ++j)
    for (int i = 60; i < 75; ++i) t.outside[std::size_t(j) * t.nx + i] = 1;
  auto cfg = coulomb(20, 40.0);
  cfg.west = cfg.east = cfg.south = cfg.north = Boundary2D::wall;
  cfg.tile = 16;
  const auto init = state_from_normal_depth(t, blob(t, 25, 40, 10, 3.0));
  omp_set_num_threads(1);
  const auto a = run_sh2d(t, cfg, init);
  omp_set_num_threads(2);
  const auto b = run_sh2d(t, cfg, init);
  EXPECT_EQ(a.state.H, b.state.H);  // deterministic with the mask too
  EXPECT_GT(a.diag.volume_outflow, 0.05 * a.diag.volume_initial);  // material ran into the hole
  EXPECT_LT(a.diag.volume_error(), 1e-12);
  for (std::size_t k = 0; k < t.cells(); ++k) {
    if (t.outside[k]) {
      ASSERT_EQ(a.state.H[k], 0.0);
    }
  }
  for (double H : a.state.H) EXPECT_GE(H, 0.0);
}

TEST(Sh2d, AnUntouchedOutsideRegionChangesNothing) {
  // Outside cells far from the flow: every cell takes the same arithmetic as without them.
  auto t = hillside(128, 96, 5.0, 30, 0.0);
  auto cfg = coulomb(22, 15.0);
  cfg.tile = 16;
  const auto init = state_from_normal_depth(t, blob(t, 20, 48, 8, 3.0));
  const auto plain = run_sh2d(t, cfg, init);
  t.outside.assign(t.cells(), 0);
  for (int j = 0; j < 6; ++j)
    for (int i = 100; i < 128; ++i) t.outside[std::size_t(j) * t.nx + i] = 1;
  const auto masked = run_sh2d(t, cfg, init);
  EXPECT_EQ(plain.state.H, masked.state.H);
  EXPECT_EQ(plain.hazard.max_speed, masked.hazard.max_speed);
}

TEST(Sh2d, OutsideMaskIsChecked) {
  auto t = hillside(20, 20, 5.0, 30, 0.0);
  auto s = state_from_normal_depth(t, std::vector<double>(t.cells(), 1.0));
  t.outside.assign(t.cells(), 0);
  t.outside[7] = 1;
  EXPECT_THROW(run_sh2d(t, coulomb(20, 1.0), s), std::invalid_argument);  // material in an outside cell
  t.outside.resize(3);
  s.H.assign(t.cells(), 0.0);
  EXPECT_THROW(run_sh2d(t, coulomb(20, 1.0), s), std::invalid_argument);
}

TEST(Sh2d, CurvatureBoundKeepsFlowsOnRoughTerrainWithinTheirEnergy) {
  // A 35 degree slope corrugated at the grid scale (wavelength 3 cells, amplitude 1.5 m). Without
  // friction a flow can never be faster than free fall from its highest point allows.
  const auto t = terrain_of(160, 40, 5.0, [](double x, double y) {
    return -std::tan(35 * kDeg) * x + 1.5 * std::sin(2 * M_PI * x / 15.0) * std::cos(2 * M_PI * y / 15.0);
  });
  const auto h0 = blob(t, 20, 20, 8, 2.0);
  double zmax = -1e9, zmin = 1e9;
  for (std::size_t k = 0; k < t.cells(); ++k) {
    if (h0[k] > 0) zmax = std::max(zmax, t.z[k] + h0[k]);
    zmin = std::min(zmin, t.z[k]);
  }
  const double bound = std::sqrt(2 * 9.81 * (zmax - zmin));
  auto cfg = coulomb(0, 10.0);
  cfg.south = cfg.north = Boundary2D::wall;
  cfg.flow_threshold = 0.05;
  cfg.time.max_steps = 3000;
  const auto capped = run_sh2d(t, cfg, state_from_normal_depth(t, h0));
  double vmax = 0;
  for (double v : capped.hazard.max_speed) vmax = std::max(vmax, v);
  // The bound leaves a few per cent of energy gain on this extreme corrugation (bumps of 3 m every 15 m).
  EXPECT_LT(vmax, 1.10 * bound) << "bound " << bound;
  cfg.curvature_cap = 1e9;  // unbounded: the explicit turns pump energy into the flow
  const auto free = run_sh2d(t, cfg, state_from_normal_depth(t, h0));
  double vfree = 0;
  for (double v : free.hazard.max_speed) vfree = std::max(vfree, v);
  EXPECT_GT(vfree, 1.5 * vmax) << "bound " << bound;
}

TEST(Sh2d, NormalDepthConventionOnASlope) {
  const auto t = inclined_plane(5, 5, 1.0, 30);
  const auto s = state_from_normal_depth(t, std::vector<double>(25, 2.0));
  EXPECT_NEAR(s.H[12], 2.0 / std::cos(30 * kDeg), 1e-12);  // volume per horizontal area
  EXPECT_NEAR(normal_depth(t, s)[12], 2.0, 1e-12);
}

// Every reported speed takes the maps' flow threshold: the run's maximum is the maximum of the
// maximum-speed map, and no progress report exceeds it, although thin films slide on faster.
TEST(Sh2d, ReportedSpeedsAreThoseOfTheFlowingCells) {
  const auto t = hillside(120, 60, 5.0, 35, 0.0);
  auto cfg = coulomb(20, 40.0);
  cfg.flow_threshold = 0.05;
  const auto init = state_from_normal_depth(t, blob(t, 20, 30, 8, 2.0));
  double progress_max = 0;
  cfg.time.progress_every = 1;
  cfg.time.progress = [&](const Progress& p) {
    progress_max = std::max(progress_max, p.max_speed);
    return true;
  };
  const auto r = run_sh2d(t, cfg, init);
  double map_max = 0;
  for (double v : r.hazard.max_speed) map_max = std::max(map_max, v);
  EXPECT_GT(map_max, 5.0);
  EXPECT_EQ(r.diag.max_speed, map_max);
  EXPECT_LE(progress_max, map_max);
  EXPECT_GT(progress_max, 0.5 * map_max);
  // A threshold above every depth: nothing counts as flowing, nothing is reported.
  cfg.flow_threshold = 100.0;
  progress_max = 0;
  const auto deep = run_sh2d(t, cfg, init);
  EXPECT_EQ(deep.diag.max_speed, 0.0);
  EXPECT_EQ(progress_max, 0.0);
  EXPECT_EQ(deep.state.H, r.state.H);  // the flow itself is the same
}

// A state that becomes non-finite stops the run with an error instead of ending with infinities.
TEST(Sh2d, NonFiniteStateFailsTheRun) {
  const auto t = hillside(60, 40, 5.0, 30, 0.0);
  auto cfg = coulomb(20, 20.0);
  try {
    run_sh2d(t, cfg, state_from_normal_depth(t, blob(t, 15, 20, 5, 1e300)));
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
  }
  // An infinite initial depth is bad input.
  auto init = state_from_normal_depth(t, blob(t, 15, 20, 5, 1.0));
  init.H[20 * 60 + 15] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(run_sh2d(t, cfg, init), std::invalid_argument);
}


// Checkpoints change nothing, and a run continued from any of them (periodic, or taken when the run
// was cancelled) computes the bits of the uninterrupted run, snapshots included.
TEST(Sh2d, ContinuedRunIsTheUninterruptedRun) {
  auto t = hillside(150, 60, 4.0, 30, 0.0);
  for (int j = 0; j < t.ny; ++j)  // flat run-out beyond x = 300 m
    for (int i = 0; i < t.nx; ++i) {
      auto& z = t.z[std::size_t(j) * t.nx + i];
      z = std::max(z, t.z[std::size_t(j) * t.nx + 75]);
    }
  auto cfg = coulomb(25, 1000.0);
  cfg.tile = 16;
  cfg.time.stop_fraction = 0.01;
  cfg.track_travel = true;
  cfg.snapshot_interval = 5.0;
  const auto init = state_from_normal_depth(t, blob(t, 20, 30, 8, 3.0));
  std::vector<double> frames;
  cfg.snapshot = [&](double time, const Sh2dStateView&) { frames.push_back(time); };
  const auto plain = run_sh2d(t, cfg, init);
  const auto plain_frames = frames;
  ASSERT_EQ(plain.diag.stop, StopReason::kinetic_energy) << plain.diag.t;
  ASSERT_GT(plain.diag.t, 20.0);
  // With checkpoints every 4 s: the same bits.
  // A continued run appends its frames to those written before the checkpoint was taken.
  std::vector<Sh2dCheckpoint> cps;
  std::vector<std::vector<double>> frames_at;
  auto with = cfg;
  with.checkpoint_interval = 4.0;
  with.checkpoint = [&](const Sh2dCheckpoint& cp) {
    cps.push_back(cp);
    frames_at.push_back(frames);
  };
  frames.clear();
  const auto checked = run_sh2d(t, with, init);
  expect_same(plain, checked);
  EXPECT_EQ(frames, plain_frames);
  ASSERT_GE(cps.size(), 3u);
  for (std::size_t k = 1; k < cps.size(); ++k) EXPECT_GE(cps[k].t, 4.0 * double(k + 1));
  // Continued from a periodic one.
  for (std::size_t c : {std::size_t(0), cps.size() / 2}) {
    frames = frames_at[c];
    const auto cont = run_sh2d(t, cfg, cps[c]);
    expect_same(plain, cont);
    EXPECT_EQ(frames, plain_frames) << "from t = " << cps[c].t;
  }
  // Cancelled at an arbitrary step (also one where the stopping rule ends the run), then continued.
  for (long at : {37L, plain.diag.steps / 2 + 3, plain.diag.steps}) {
    auto cut = cfg;
    Sh2dCheckpoint taken;
    cut.time.progress_every = 1;
    cut.time.progress = [&](const Progress& p) { return p.step < at; };
    std::vector<double> before;
    cut.checkpoint = [&](const Sh2dCheckpoint& cp) {
      taken = cp;
      before = frames;
    };
    frames.clear();
    const auto part = run_sh2d(t, cut, init);
    ASSERT_EQ(part.diag.stop, StopReason::cancelled);
    ASSERT_EQ(taken.steps, at);
    frames = before;  // the cancelled run's own final frame came after the checkpoint
    omp_set_num_threads(1);  // any thread count
    const auto cont = run_sh2d(t, cfg, taken);
    omp_set_num_threads(2);
    expect_same(plain, cont);
    EXPECT_EQ(frames, plain_frames) << "cancelled at step " << at;
  }
}

TEST(Sh2d, CheckpointOfAnotherGridIsRefused) {
  const auto t = hillside(60, 40, 5.0, 30, 0.0);
  auto cfg = coulomb(20, 10.0);
  Sh2dCheckpoint cp;
  cfg.checkpoint_interval = 1.0;
  cfg.checkpoint = [&](const Sh2dCheckpoint& c) { cp = c; };
  run_sh2d(t, cfg, state_from_normal_depth(t, blob(t, 15, 20, 5, 2.0)));
  ASSERT_GT(cp.steps, 0);
  const auto other = hillside(61, 40, 5.0, 30, 0.0);
  EXPECT_THROW(run_sh2d(other, coulomb(20, 10.0), cp), std::invalid_argument);
  auto tiles = coulomb(20, 10.0);
  tiles.tile = 16;
  EXPECT_THROW(run_sh2d(t, tiles, cp), std::invalid_argument);
}

// The 3D engine's rest case (validation.md D1) in the depth-averaged engine: a block 2 m deep (normal
// to the slope), 60 m square on a 15 deg plane, Coulomb delta 20 (earth pressure 1). On 10 m cells
// the bed holds the whole block, its vertical edges included: it does not move at all (0 m/s at 2, 4
// and 10 s, no cell added to its footprint). That is the coarse cells' doing: one cell's step hides
// the edge's gradient. On 5 m cells the downslope edge slumps out 20 m (measured: 7.8e-2 m/s at 2 s,
// 15 m out; 1.8e-5 m/s at 8 s, 20 m out; on 2.5 m cells the same 20 m), as the 3D engine's edges do
// (TerrainVof.RefinedBlockSlumpsAsTheDepthAveragedOneOnTheSameCells).
TEST(Sh2d, BlockFlatterThanItsBedFrictionSpreadsAtItsEdges) {
  const auto t = inclined_plane(40, 32, 10.0, 15);
  std::vector<double> h(t.cells(), 0.0);
  for (int j = 13; j < 19; ++j)
    for (int i = 7; i < 13; ++i) h[std::size_t(j) * t.nx + i] = 2.0;
  const auto init = state_from_normal_depth(t, h);
  for (double t_end : {2.0, 4.0, 10.0}) {
    auto cfg = coulomb(20, t_end);
    cfg.time.stop_fraction = 0;
    const auto r = run_sh2d(t, cfg, init);
    double H = 0, HU = 0, HV = 0;
    int grown = 0, reach = 0;
    for (int j = 0; j < t.ny; ++j)
      for (int i = 0; i < t.nx; ++i) {
        const std::size_t k = std::size_t(j) * t.nx + i;
        H += r.state.H[k];
        HU += r.state.HU[k];
        HV += r.state.HV[k];
        if (r.state.H[k] > 0.01 && h[k] == 0) {
          ++grown;
          reach = std::max(reach, std::max(std::max(7 - i, i - 12), std::max(13 - j, j - 18)));
        }
      }
    std::printf("depth-averaged, 15 deg, delta 20, block with vertical edges: mean speed %.2e m/s at %.0f s; footprint grown by %d cells, "
                "the farthest %d cells out\n",
                std::hypot(HU, HV) / H, t_end, grown, reach);
    EXPECT_LT(std::hypot(HU, HV) / H, 1e-3);
    EXPECT_LE(reach, 1);
  }
  // On 5 m cells: the same block slumps and comes to rest.
  const auto fine = inclined_plane(80, 64, 5.0, 15);
  std::vector<double> hf(fine.cells(), 0.0);
  for (int j = 26; j < 38; ++j)
    for (int i = 14; i < 26; ++i) hf[std::size_t(j) * fine.nx + i] = 2.0;
  auto cfg = coulomb(20, 8.0);
  cfg.time.stop_fraction = 0;
  const auto r = run_sh2d(fine, cfg, state_from_normal_depth(fine, hf));
  double H = 0, HU = 0, HV = 0;
  int reach = 0;
  for (int j = 0; j < fine.ny; ++j)
    for (int i = 0; i < fine.nx; ++i) {
      const std::size_t k = std::size_t(j) * fine.nx + i;
      H += r.state.H[k];
      HU += r.state.HU[k];
      HV += r.state.HV[k];
      if (r.state.H[k] > 0.01 && hf[k] == 0) reach = std::max(reach, std::max(std::max(14 - i, i - 25), std::max(26 - j, j - 37)));
    }
  std::printf("depth-averaged on 5 m cells: mean speed %.2e m/s at 8 s; the farthest %d cells out\n", std::hypot(HU, HV) / H, reach);
  EXPECT_LT(std::hypot(HU, HV) / H, 1e-3);
  EXPECT_GE(reach, 3);
}

