// A 3D nest inside a depth-averaged run (scenario `nest`, one-way coupling): the depth-averaged run
// records the scheme's own fluxes through the nest's boundary, the 3D engine runs the nest with that
// inflow, and inside the nest the hazard rasters are the 3D run's.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "jobs/drivers/run.hpp"
#include "jobs/scenario/scenario.hpp"
#include "tests/support/run_helpers.hpp"

using namespace runout;
using namespace runout::test_support::run;

namespace {

constexpr double kX0 = 500000, kY0 = 5200000;

// A slope of 30 deg falling east into a flat at x = 400 m (10 m cells, 600 x 200 m), a block 3 m
// thick over 60 x 60 m near the top, Coulomb phi 25 deg, delta 20 deg; a nest of 100 x 100 m on
// the slope below the release, on columns of 5 m.
v1::Scenario slope_with_nest(const TempDir& d) {
  const double t = std::tan(30 * M_PI / 180);
  make_dem_box(d / "dem.tif", 60, 20, 10.0, kX0, kY0, [&](int i, int) { return std::max(0.0, 400 - (i + 0.5) * 10) * t; });
  make_polygons(d / "rel.geojson", {square(kX0 + 50, kY0 + 70, 60)}, "EPSG:32632");
  make_polygons(d / "nest.geojson", {square(kX0 + 250, kY0 + 50, 100)}, "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson", 10);
  sc.mutable_releases(0)->set_thickness_m(3);
  sc.mutable_material()->set_internal_friction_deg(25);
  sc.mutable_material()->set_bed_friction_deg(20);
  sc.mutable_numerics()->set_end_time_s(40);
  sc.mutable_outputs()->set_maps(false);
  auto* n = sc.mutable_nest();
  n->set_path("nest.geojson");
  n->set_refinement(2);
  return sc;
}

}  // namespace

// Conservation: the volume the 3D nest takes in equals the depth-averaged flux into it through its
// boundary within 1 %, the nest's own balance holds to round-off, and the parent's rasters inside the
// nest are the nest's.
TEST(Nest, TheNestTakesInTheDepthAveragedFluxAndItsMapsReplaceTheDepthAveragedOnes) {
  TempDir d;
  const auto sc = slope_with_nest(d);
  jobs::RunOptions opt;  // as the job system runs it: with a checkpoint file, the 3D nest's
  opt.checkpoint_path = (d / "run.ckpt");
  opt.checkpoint_interval_s = 5;
  const auto sum = jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d.p.string(), opt);
  ASSERT_TRUE(sum.nest.has_value());
  EXPECT_TRUE(fs::exists(d / "run.ckpt"));
  const auto rec = run_record(d / "run.json");
  ASSERT_TRUE(rec.has_nest());
  const auto& n = rec.nest();
  std::printf("nest: %d cells, %d faces, %d mesh cells of %.1f m columns, layers %.2f-%.1f m; in: depth-averaged %.1f m3, 3D %.1f m3 "
              "(difference %.2e); 3D balance %.1e; %d steps recorded; 3D %.1f s\n",
              n.cells(), n.boundary_faces(), n.mesh_cells(), n.column_width_m(), n.first_layer_m(), n.band_height_m(),
              n.inflow_depth_averaged_m3(), n.inflow_3d_m3(), n.inflow_relative_difference(), n.volume_error_3d(), n.recorded_steps(),
              n.seconds_3d());
  EXPECT_EQ(n.cells(), 100);
  EXPECT_EQ(n.boundary_faces(), 40);
  EXPECT_NEAR(n.column_width_m(), 5.0, 1e-9);
  EXPECT_GT(n.inflow_depth_averaged_m3(), 0.3 * rec.release().volume_m3());  // most of the flow passes the nest
  EXPECT_LT(n.inflow_relative_difference(), 0.01);
  EXPECT_LT(n.volume_error_3d(), 1e-9);
  const auto nest_run = run_record(d / "nest/run.json");
  EXPECT_EQ(nest_run.engine(), "vof");
  // The nest's frames cover its columns' bounding box (20 x 20 columns of 5 m), not the domain.
  GDALDatasetUniquePtr frame(GDALDataset::Open(("HDF5:\"" + (d / "nest/fields.h5") + "\"://f00000/alpha").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->GetRasterXSize(), 20);  // east
  EXPECT_EQ(frame->GetRasterCount(), 20);  // north
  const auto outer = read_raster_values(d / "max_depth.tif"), inner = read_raster_values(d / "nest/max_depth.tif");
  int inside = 0;
  for (int r = 0; r < outer.h; ++r)
    for (int i = 0; i < outer.w; ++i) {
      const double x = outer.cx(i) - kX0, y = outer.cy(r) - kY0;
      if (x > 250 && x < 350 && y > 50 && y < 150) {
        ++inside;
        EXPECT_NEAR(outer.v[std::size_t(r) * outer.w + i], inner.v[std::size_t(r) * inner.w + i], 1e-6) << x << ", " << y;
      }
    }
  EXPECT_EQ(inside, 100);
  EXPECT_NE(std::find(sum.notes.begin(), sum.notes.end(),
                      "inside the 3D nest (100 cells) the hazard rasters are the 3D engine's (nest/run.json); outside, the depth-averaged "
                      "engine's"),
            sum.notes.end());
}

// The bundled scenario of validation.md D4 resolves: the farmhouse as a structure of both runs, the
// nest on 5 m columns (bench.farmhouse_nest runs it).
TEST(Nest, TheBundledFarmhouseScenarioResolves) {
  const auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/in-den-arelen-farmhouse.json");
  ASSERT_TRUE(r.nest);
  EXPECT_TRUE(r.nest->nest_part);
  EXPECT_EQ(r.nest->engine, jobs::kVofTerrainEngine);
  EXPECT_EQ(r.nest->scenario.mesh().refinement(), 2);
  ASSERT_EQ(r.structures.size(), 1u);
  ASSERT_EQ(r.nest->structures.size(), 1u);
  EXPECT_EQ(r.structures[0].name, "farmhouse");
  EXPECT_NE(std::find(r.input_files.begin(), r.input_files.end(), r.nest->corridor_path), r.input_files.end());
}

// Interrupted in its 3D nest (as the job system stops a worker), a nested run writes no results and
// leaves the 3D run's checkpoint; continued from it, the depth-averaged part runs again from its
// start and the 3D nest goes on from the checkpoint, to the uninterrupted run's results.
TEST(Nest, AnInterruptedNestedRunContinuesFromItsThreeDCheckpoint) {
  TempDir d;
  const auto r = jobs::resolve_scenario(slope_with_nest(d), d.p.string());
  jobs::RunOptions whole;
  const auto ref = jobs::run_scenario(r, d / "whole", whole);
  jobs::RunOptions cut;
  cut.checkpoint_path = d / "cut.ckpt";
  cut.checkpoint_interval_s = 5;
  cut.progress = [&](const engine::Progress&) { return !fs::exists(d / "cut.ckpt"); };  // stop after the 3D run's first checkpoint
  cut.progress_every = 1;
  const auto stopped = jobs::run_scenario(r, d / "cut", cut);
  EXPECT_EQ(stopped.stop, "cancelled");
  EXPECT_FALSE(fs::exists(d / "cut/run.json"));
  ASSERT_TRUE(fs::exists(d / "cut.ckpt"));
  jobs::RunOptions go_on;
  go_on.restart_path = d / "cut.ckpt";
  const auto sum = jobs::run_scenario(r, d / "continued", go_on);
  const auto a = run_record(d / "whole/run.json"), b = run_record(d / "continued/run.json");
  ASSERT_TRUE(b.nest().has_continued_from_s());
  std::printf("continued from t = %.2f s (3D start %.2f s): 3D inflow %.6f vs %.6f m3, balance %.1e; stop %s vs %s\n",
              b.nest().continued_from_s(), b.nest().start_time_s(), b.nest().inflow_3d_m3(), a.nest().inflow_3d_m3(),
              b.nest().volume_error_3d(), sum.stop.c_str(), ref.stop.c_str());
  EXPECT_GT(b.nest().continued_from_s(), b.nest().start_time_s());
  EXPECT_NEAR(b.nest().inflow_3d_m3(), a.nest().inflow_3d_m3(), 1e-6 * a.nest().inflow_3d_m3());
  EXPECT_LT(b.nest().volume_error_3d(), 1e-9);
  EXPECT_NE(std::find_if(b.notes().begin(), b.notes().end(), [](const std::string& n) { return n.find("the 3D nest continued from its checkpoint") == 0; }),
            b.notes().end());
  const auto da = read_raster_values(d / "whole/max_depth.tif"), db = read_raster_values(d / "continued/max_depth.tif");
  ASSERT_EQ(da.v.size(), db.v.size());
  double worst = 0;
  for (std::size_t k = 0; k < da.v.size(); ++k)
    if (std::isfinite(da.v[k]) && std::isfinite(db.v[k])) worst = std::max(worst, std::abs(da.v[k] - db.v[k]));
  std::printf("largest difference of the max depth: %.2e m\n", worst);
  EXPECT_LT(worst, 1e-3);
}

// A nest is refused where it cannot be run, naming the field.
TEST(Nest, BadNestsAreRefusedNamingTheField) {
  TempDir d;
  auto sc = slope_with_nest(d);
  auto vof = sc;
  vof.set_engine("vof");
  expect_error(vof, d, "nest: only for engine \"depth-averaged\"");
  auto thin = sc;
  make_polygons(d / "thin.geojson", {{{kX0 + 250, kY0 + 50}, {kX0 + 260, kY0 + 50}, {kX0 + 260, kY0 + 150}, {kX0 + 250, kY0 + 150}, {kX0 + 250, kY0 + 50}}},
                "EPSG:32632");
  thin.mutable_nest()->set_path("thin.geojson");
  expect_error(thin, d, "the nest is one cell wide at grid cell (25, 5)");
  auto edge = sc;
  make_polygons(d / "edge.geojson", {square(kX0 + 500, kY0 + 50, 100)}, "EPSG:32632");
  edge.mutable_nest()->set_path("edge.geojson");
  expect_error(edge, d, "the nest reaches the grid's edge");
  try {  // a checkpoint the nest's 3D run cannot read is refused before the depth-averaged part runs
    jobs::RunOptions opt;
    opt.restart_path = (d / "some.ckpt");
    jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "restart", opt);
    ADD_FAILURE() << "a nested run continued from a missing checkpoint";
  } catch (const jobs::ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("checkpoint " + (d / "some.ckpt") + ": no such file"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(d / "restart/timeseries.h5"));
  auto voellmy = sc;
  voellmy.mutable_material()->set_rheology("voellmy");
  voellmy.mutable_material()->clear_bed_friction_deg();
  voellmy.mutable_material()->set_voellmy_mu(0.2);
  voellmy.mutable_material()->set_voellmy_xi(1000);
  expect_error(voellmy, d, "nest: the 3D run of the nest:");
  auto lone_vof = sc;  // a depth-averaged scenario's `vof` block is its nest's 3D run: without a nest it is refused
  lone_vof.clear_nest();
  lone_vof.mutable_vof()->set_write_interval_s(1);
  expect_error(lone_vof, d, "vof: only for engine \"vof\" (the 3D engine on the DEM), or for the 3D run of a depth-averaged scenario's nest");
  auto mesh = sc;
  mesh.mutable_mesh()->set_refinement(2);
  expect_error(mesh, d, "mesh: only for engine \"vof\" (the 3D engine on the DEM); a nest's mesh is in `nest`");
}

// A depth-averaged scenario's `vof` block sets its nest's 3D run (frames, Courant number): the nest's
// resolved scenario carries it, with the option table's defaults for what it leaves out.
TEST(Nest, TheVofBlockOfADepthAveragedScenarioSetsTheNestsThreeDRun) {
  TempDir d;
  auto sc = slope_with_nest(d);
  sc.mutable_vof()->set_write_interval_s(0.5);
  sc.mutable_vof()->set_max_courant(0.1);
  const auto r = jobs::resolve_scenario(sc, d.p.string());
  ASSERT_TRUE(r.nest);
  EXPECT_DOUBLE_EQ(r.nest->scenario.vof().write_interval_s(), 0.5);
  EXPECT_DOUBLE_EQ(r.nest->scenario.vof().max_courant(), 0.1);
  EXPECT_EQ(r.nest->scenario.vof().outer_correctors(), 3);  // the default
  auto too_often = sc;
  too_often.mutable_vof()->set_write_interval_s(0.001);
  expect_error(too_often, d, "nest: the 3D run of the nest: vof.write_interval_s");
}

namespace {

struct Deposit {
  double front_x = 0;  ///< the farthest cell east with max depth above 0.1 m [m from the grid's west edge]
  double area = 0;     ///< cells with max depth above 0.1 m [m2]
  double volume = 0;   ///< the final depth integrated [m3]
};

Deposit deposit_of(const std::string& dir) {
  Deposit d;
  const auto m = read_raster_values(dir + "/max_depth.tif"), f = read_raster_values(dir + "/deposit.tif");
  for (int r = 0; r < m.h; ++r)
    for (int i = 0; i < m.w; ++i) {
      const double v = m.v[std::size_t(r) * m.w + i], z = f.v[std::size_t(r) * f.w + i];
      if (std::isfinite(v) && v > 0.1) {
        d.front_x = std::max(d.front_x, m.cx(i) - kX0);
        d.area += 30.0 * 30.0;
      }
      if (std::isfinite(z)) d.volume += z * 30.0 * 30.0;
    }
  return d;
}

}  // namespace

// A nest over the whole slope (every cell but the grid's edge ring) reproduces the 3D engine's run of
// the same scenario on the same columns and layers (mesh.corridor "polygon" with the nest's
// polygon): the slope of 30 deg into a flat on 30 m cells, a block of 2 m (delta 20 deg, phi 25 deg)
// that stops on the flat. Nothing reaches the nest's boundary, so the nest's run differs from the
// whole-domain run only by its boundary's condition (open to the still air either way; the nest's
// cells along it always computed) and its time step's bound. Measured: the same front (1695 m) and
// area, the deposit's volume within 1e-3.
TEST(Nest, ANestOverTheWholeSlopeReproducesTheWholeDomain3dRun) {
  TempDir d;
  const double t = std::tan(30 * M_PI / 180);
  make_dem_box(d / "dem.tif", 60, 12, 30.0, kX0, kY0, [&](int i, int) { return std::max(0.0, 1200 - (i + 0.5) * 30) * t; });
  make_polygons(d / "rel.geojson", {square(kX0 + 150, kY0 + 120, 120)}, "EPSG:32632");
  make_polygons(d / "nest.geojson", {{{kX0 + 30, kY0 + 30}, {kX0 + 1770, kY0 + 30}, {kX0 + 1770, kY0 + 330}, {kX0 + 30, kY0 + 330}, {kX0 + 30, kY0 + 30}}},
                "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson", 30);
  sc.mutable_material()->set_internal_friction_deg(25);
  sc.mutable_material()->set_bed_friction_deg(20);
  sc.mutable_numerics()->set_end_time_s(120);
  sc.mutable_outputs()->set_maps(false);
  auto nested = sc;
  auto* n = nested.mutable_nest();
  n->set_path("nest.geojson");
  n->set_refinement(1);
  n->set_first_layer_m(0.4);
  n->set_band_height_m(16);
  auto whole = sc;
  whole.set_engine("vof");
  whole.mutable_vof()->set_write_interval_s(0);
  auto* me = whole.mutable_mesh();
  me->set_corridor("polygon");
  me->set_corridor_path("nest.geojson");
  me->set_first_layer_m(0.4);
  me->set_band_height_m(16);
  fs::create_directories(d / "nested");
  fs::create_directories(d / "whole");
  const auto sn = jobs::run_scenario(jobs::resolve_scenario(nested, d.p.string()), d / "nested");
  const auto sw = jobs::run_scenario(jobs::resolve_scenario(whole, d.p.string()), d / "whole");
  const Deposit a = deposit_of(d / "nested/nest"), b = deposit_of(d / "whole");
  const auto rn = run_record(d / "nested/run.json"), rw = run_record(d / "whole/run.json");
  std::printf("nest: front %.0f m, area %.0f m2, deposit %.1f m3, stop %s at %.1f s; whole: front %.0f m, area %.0f m2, deposit %.1f m3, "
              "stop %s at %.1f s; into the nest %.3g m3\n",
              a.front_x, a.area, a.volume, run_record(d / "nested/nest/run.json").solver().stop().c_str(),
              run_record(d / "nested/nest/run.json").solver().simulated_s(), b.front_x, b.area, b.volume, sw.stop.c_str(), sw.t,
              rn.nest().inflow_depth_averaged_m3());
  EXPECT_GT(b.front_x, 1200);  // it reached the flat
  EXPECT_LT(b.front_x, 1700);  // and stopped well inside
  EXPECT_NEAR(a.front_x, b.front_x, 30.0);
  EXPECT_NEAR(a.area / b.area, 1.0, 0.05);
  EXPECT_NEAR(a.volume / b.volume, 1.0, 0.02);
  EXPECT_LT(rn.nest().inflow_depth_averaged_m3(), 1e-6 * rw.release().volume_m3());  // nothing crossed the nest's boundary
  (void)sn;
}
