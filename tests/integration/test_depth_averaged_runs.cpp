// Depth-averaged runs through the run driver: reported maxima, non-finite states, checkpoints and
// exact continuation.
#include "tests/support/run_helpers.hpp"

using namespace runout::test_support::run;

// Depth-averaged runs report the maps' maxima: run.json's, the summary's and the progress's
// maximum speed take the flow threshold of outputs.flow_threshold_m, so run.json's figure is the
// maximum of max_speed.tif (thin films sliding on faster are left out of both).
TEST(DepthAveraged, ReportedMaximumSpeedIsTheMapsMaximum) {
  TempDir d;
  make_dem(d / "dem.tif", 120, 20.0, 35);
  make_polygons(d / "rel.geojson", {square(500200, 5201000, 300)}, "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson");
  auto r = jobs::resolve_scenario(sc, d.p.string());
  fs::create_directories(d / "out");
  jobs::RunOptions opt;
  opt.progress_every = 1;
  double progress_max = 0;
  opt.progress = [&](const engine::Progress& p) {
    progress_max = std::max(progress_max, p.max_speed);
    return true;
  };
  const auto sum = jobs::run_scenario(r, d / "out", opt);
  GDALDatasetUniquePtr ms(GDALDataset::Open((d / "out/max_speed.tif").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(ms);
  std::vector<float> v(std::size_t(sum.nx) * sum.ny);
  ASSERT_EQ(ms->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, sum.nx, sum.ny, v.data(), sum.nx, sum.ny, GDT_Float32, 0, 0), CE_None);
  float raster_max = 0;
  for (float x : v)
    if (x != -9999.0f) raster_max = std::max(raster_max, x);
  EXPECT_GT(raster_max, 10.0f);
  EXPECT_EQ(float(sum.max_speed), raster_max);
  EXPECT_NEAR(record_figure(d / "out/run.json", "max_speed_m_s"), sum.max_speed, 1e-9 * sum.max_speed);
  EXPECT_LE(progress_max, sum.max_speed);
  EXPECT_GT(progress_max, 0.5 * sum.max_speed);
}

// A run whose state turns non-finite fails with a message and writes no results.
TEST(DepthAveraged, NonFiniteStateFailsTheRun) {
  TempDir d;
  make_dem(d / "dem.tif", 60, 20.0, 30);
  make_polygons(d / "rel.geojson", {square(500200, 5200400, 200)}, "EPSG:32632");
  auto r = jobs::resolve_scenario(base_scenario(d / "dem.tif", d / "rel.geojson"), d.p.string());
  r.config.gravity = 1e306;  // past the scenario's checks: the first step's momenta overflow
  fs::create_directories(d / "out");
  try {
    jobs::run_scenario(r, d / "out");
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(d / "out/run.json"));
}

namespace {

bool same_bytes(const std::string& a, const std::string& b) {
  const std::string x = read_text(a), y = read_text(b);
  return !x.empty() && x == y;
}

// run.json without what may differ between a run and its continuation: the creation time, the
// timings and where it was continued from.
std::string run_record_figures(const std::string& path) {
  auto j = run_record(path);
  j.clear_created_utc();
  j.clear_timings_s();
  j.mutable_solver()->clear_continued_from_t_s();
  return j.DebugString();
}

// Two runs' outputs are the same bits: every raster, the outline, the time series' frames (depth,
// speed) and XDMF, and run.json's figures.
void expect_same_outputs(const std::string& a, const std::string& b) {
  for (const char* f : {"max_depth.tif", "max_speed.tif", "max_pressure.tif", "deposit.tif", "arrival_time.tif", "outline.geojson",
                        "timeseries.xmf"})
    EXPECT_TRUE(same_bytes(a + "/" + f, b + "/" + f)) << f;
  EXPECT_EQ(run_record_figures(a + "/run.json"), run_record_figures(b + "/run.json"));
  const int frames = int(record_figure(a + "/run.json", "timeseries_frames"));
  EXPECT_EQ(frames, int(record_figure(b + "/run.json", "timeseries_frames")));
  for (int f = 0; f < frames; ++f)
    for (const char* q : {"depth", "speed"}) {
      char sub[64];
      std::snprintf(sub, sizeof sub, "://frames/%05d/%s", f, q);
      std::vector<float> v[2];
      for (int k = 0; k < 2; ++k) {
        GDALDatasetUniquePtr ds(GDALDataset::Open(("HDF5:\"" + (k ? b : a) + "/timeseries.h5\"" + sub).c_str(), GDAL_OF_RASTER));
        ASSERT_TRUE(ds) << sub;
        const int nx = ds->GetRasterXSize(), ny = ds->GetRasterYSize();
        v[k].resize(std::size_t(nx) * ny);
        ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, nx, ny, v[k].data(), nx, ny, GDT_Float32, 0, 0), CE_None);
      }
      ASSERT_EQ(v[0].size(), v[1].size()) << sub;
      EXPECT_EQ(std::memcmp(v[0].data(), v[1].data(), v[0].size() * sizeof(float)), 0) << sub;
    }
}

jobs::ResolvedScenario arelen_30m_short() {
  auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/tests/data/arelen-30m.json");
  r.scenario.mutable_numerics()->set_end_time_s(150);
  r.config.time.t_end = 150;
  r.scenario.mutable_outputs()->set_timeseries_interval_s(20);
  r.timeseries_interval = 20;
  return r;
}

}  // namespace

// Depth-averaged checkpoints: writing them changes nothing, and a run stopped at an arbitrary step
// (through the progress hook, as Ctrl-C does) and continued from its checkpoint writes the outputs of
// the uninterrupted run, bit for bit, time series included.
TEST(DepthAveraged, ContinuedRunWritesTheUninterruptedRunsOutputs) {
  const auto r = arelen_30m_short();
  TempDir d;
  for (const char* o : {"whole", "checked", "part", "continued"}) fs::create_directories(d / o);
  const auto whole = jobs::run_scenario(r, d / "whole");
  ASSERT_EQ(whole.stop, "end-time");
  jobs::RunOptions opt;
  opt.checkpoint_path = d / "every.h5";
  opt.checkpoint_interval_s = 30;
  jobs::run_scenario(r, d / "checked", opt);
  expect_same_outputs(d / "whole", d / "checked");
  EXPECT_TRUE(fs::exists(d / "every.h5"));
  EXPECT_TRUE(fs::exists(d / "every.h5.timeseries.h5"));
  // Stopped at step 401, then continued from there (the checkpoint replaced by the continued run's).
  jobs::RunOptions cut;
  cut.checkpoint_path = d / "cut.h5";
  cut.progress_every = 1;
  cut.progress = [](const engine::Progress& p) { return p.step < 401; };
  const auto part = jobs::run_scenario(r, d / "part", cut);
  ASSERT_EQ(part.stop, "cancelled");
  ASSERT_EQ(part.steps, 401);
  jobs::RunOptions cont;
  cont.restart_path = d / "cut.h5";
  cont.checkpoint_path = d / "cut.h5";
  const auto continued = jobs::run_scenario(r, d / "continued", cont);
  EXPECT_EQ(continued.steps, whole.steps);
  expect_same_outputs(d / "whole", d / "continued");
  EXPECT_NEAR(record_figure(d / "continued/run.json", "continued_from_t_s"), part.t, 1e-6 * part.t);
  EXPECT_FALSE(run_record(d / "whole/run.json").solver().has_continued_from_t_s());
  // Continued again from the last periodic checkpoint of the run with checkpoints.
  fs::remove_all(d / "continued");
  fs::create_directories(d / "continued");
  jobs::RunOptions again;
  again.restart_path = d / "every.h5";
  jobs::run_scenario(r, d / "continued", again);
  expect_same_outputs(d / "whole", d / "continued");
}

// A checkpoint belongs to its scenario: another scenario's, a missing one and a file that is no
// checkpoint are refused with a ScenarioError naming the file.
TEST(DepthAveraged, CheckpointOfAnotherScenarioIsRefused) {
  auto r = arelen_30m_short();
  r.config.time.t_end = 20;
  r.scenario.mutable_numerics()->set_end_time_s(20);
  TempDir d;
  fs::create_directories(d / "a");
  fs::create_directories(d / "b");
  jobs::RunOptions opt;
  opt.checkpoint_path = d / "cp.h5";
  opt.checkpoint_interval_s = 5;
  jobs::run_scenario(r, d / "a", opt);
  ASSERT_TRUE(fs::exists(d / "cp.h5"));
  auto other = r;
  other.scenario.mutable_material()->set_bed_friction_deg(16);
  other.config.material.delta = 16 * M_PI / 180;
  auto expect_refused = [&](const jobs::ResolvedScenario& sc, const std::string& path, const std::string& needle) {
    jobs::RunOptions o;
    o.restart_path = path;
    try {
      jobs::run_scenario(sc, d / "b", o);
      ADD_FAILURE() << "no error for " << path;
    } catch (const jobs::ScenarioError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(d / "b/run.json"));
  };
  expect_refused(other, d / "cp.h5", "another scenario");
  expect_refused(r, d / "missing.h5", "no such file");
  expect_refused(r, d / "a/run.json", "not an HDF5 file");
}

// A forest on the run-out (a polygon file, scenario `resistance`): the flow stops shorter than
// without it, the forest keeps what it detrained (detrained_depth.tif, run.json's
// mass_balance.volume_detrained_m3), and the volume balance holds to round-off.
TEST(DepthAveraged, ForestShortensTheRunoutAndKeepsWhatItDetrained) {
  TempDir d;
  make_dem(d / "dem.tif", 120, 20.0, 35);
  make_polygons(d / "rel.geojson", {square(500200, 5201000, 300)}, "EPSG:32632");
  // The forest covers the flat run-out (from x = 1500 m; the slope ends at 1440 m) across the grid.
  make_polygons(d / "forest.geojson", {{{501500, 5200000}, {502400, 5200000}, {502400, 5202400}, {501500, 5202400}, {501500, 5200000}}},
                "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson");
  sc.mutable_numerics()->set_end_time_s(150);
  fs::create_directories(d / "open");
  const auto open = jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "open");
  // The band widened to the whole flow (the default band lets a fast, thin avalanche pass): the drag
  // acts while it flows, and where it slows below 6 m/s the forest detrains it.
  auto* rs = sc.mutable_resistance();
  rs->add_areas()->set_path("forest.geojson");
  rs->set_speed_max_m_s(200);
  rs->set_depth_min_m(0);
  fs::create_directories(d / "forest");
  const auto forest = jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "forest");
  EXPECT_LT(forest.runout_m, open.runout_m - 40) << forest.runout_m << " against " << open.runout_m;
  const auto rec = run_record(d / "forest/run.json");
  const auto& mb = rec.mass_balance();
  EXPECT_GT(mb.volume_detrained_m3(), 0.05 * mb.volume_initial_m3());
  EXPECT_LT(mb.relative_error(), 1e-12);
  EXPECT_NEAR(mb.volume_final_m3() + mb.volume_outflow_m3() + mb.volume_detrained_m3(), mb.volume_initial_m3(),
              1e-9 * mb.volume_initial_m3());
  EXPECT_TRUE(fs::exists(d / "forest/detrained_depth.tif"));
  EXPECT_FALSE(fs::exists(d / "open/detrained_depth.tif"));
  EXPECT_EQ(run_record(d / "open/run.json").mass_balance().volume_detrained_m3(), 0.0);
  // The raster holds the detrained thickness: its volume is run.json's.
  GDALDatasetUniquePtr ds(GDALDataset::Open((d / "forest/detrained_depth.tif").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(ds);
  std::vector<double> v(std::size_t(forest.nx) * forest.ny);
  ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, forest.nx, forest.ny, v.data(), forest.nx, forest.ny, GDT_Float64, 0, 0),
            CE_None);
  double on_ground = 0;
  for (double x : v)
    if (x > 0) on_ground += x * forest.dx * forest.dx;  // normal thickness on a flat run-out
  EXPECT_NEAR(on_ground / mb.volume_detrained_m3(), 1.0, 0.02) << on_ground << " against " << mb.volume_detrained_m3();
}

// An erodible cover on the run-out (polygons with a thickness attribute, scenario `entrainment`): the
// flow takes part of it up, run.json's mass balance counts it (released + entrained = final + left
// the grid, to round-off), and cover_depth.tif holds what is left: the cover it lost, at the cover's
// density, is the entrained volume at the flow's.
TEST(DepthAveraged, EntrainmentTakesUpCoverAndCountsItInTheMassBalance) {
  TempDir d;
  make_dem(d / "dem.tif", 120, 20.0, 35);
  make_polygons(d / "rel.geojson", {square(500200, 5201000, 300)}, "EPSG:32632");
  // The cover lies on the flat run-out (from x = 1500 m; the slope ends at 1440 m), 0.4 m thick.
  make_polygons(d / "cover.geojson", {{{501500, 5200000}, {502400, 5200000}, {502400, 5202400}, {501500, 5202400}, {501500, 5200000}}},
                "EPSG:32632", R"(,"thickness":0.4)");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson");
  sc.mutable_numerics()->set_end_time_s(150);
  fs::create_directories(d / "bare");
  jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "bare");
  auto* e = sc.mutable_entrainment();
  auto* a = e->add_areas();
  a->set_path("cover.geojson");
  a->set_thickness_attribute("thickness");
  fs::create_directories(d / "cover");
  const auto run = jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "cover");
  const auto rec = run_record(d / "cover/run.json");
  const auto& mb = rec.mass_balance();
  EXPECT_GT(mb.volume_entrained_m3(), 0.01 * mb.volume_initial_m3());
  EXPECT_LT(mb.relative_error(), 1e-12);
  EXPECT_NEAR(mb.volume_final_m3() + mb.volume_outflow_m3(), mb.volume_initial_m3() + mb.volume_entrained_m3(),
              1e-9 * mb.volume_initial_m3());
  EXPECT_EQ(run_record(d / "bare/run.json").mass_balance().volume_entrained_m3(), 0.0);
  EXPECT_FALSE(fs::exists(d / "bare/cover_depth.tif"));
  GDALDatasetUniquePtr ds(GDALDataset::Open((d / "cover/cover_depth.tif").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(ds);
  std::vector<double> v(std::size_t(run.nx) * run.ny);
  ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, run.nx, run.ny, v.data(), run.nx, run.ny, GDT_Float64, 0, 0), CE_None);
  double gt[6];
  ASSERT_EQ(ds->GetGeoTransform(gt), CE_None);
  // The cover taken: its cells (centres east of 501500 m) on the run-out, which falls 2 % to the
  // north: the volume of a normal thickness t there is t dx^2 / cos(theta).
  const double cos_theta = 1 / std::sqrt(1 + 0.02 * 0.02);
  double lost = 0;
  long covered = 0;
  for (int r = 0; r < run.ny; ++r)
    for (int i = 0; i < run.nx; ++i) {
      const double x = v[std::size_t(r) * run.nx + i];
      if (gt[0] + (i + 0.5) * gt[1] < 501500) {
        ASSERT_EQ(x, 0.0);
        continue;
      }
      lost += (0.4 - x) * run.dx * run.dx / cos_theta;
      covered += x > 0;
    }
  EXPECT_GT(covered, 100);
  // To the Float32 raster and the slope of the grid (a cubic resampling of the Float32 DEM).
  EXPECT_NEAR(lost * 100.0 / 300.0 / mb.volume_entrained_m3(), 1.0, 5e-5) << lost;
  // The maps outline the cover and name it in the parameter block.
  EXPECT_TRUE(fs::exists(d / "cover/map_max_depth.png"));
}

// An erodible cover is refused by name where it cannot work: no areas, no thickness, an area away
// from the domain, a flow-dependent friction law, the 3D engine.
TEST(DepthAveraged, ErodibleCoverIsRefusedWhereItCannotWork) {
  TempDir d;
  make_dem(d / "dem.tif", 40, 20.0, 30);
  make_polygons(d / "rel.geojson", {square(500200, 5200400, 200)}, "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson");
  auto with = [&](auto change) {
    auto s = sc;
    auto* a = s.mutable_entrainment()->add_areas();
    a->set_path(d / "rel.geojson");
    a->set_thickness_m(0.3);
    change(s);
    return s;
  };
  auto s0 = sc;
  s0.mutable_entrainment()->set_erosion_energy_j_kg(3000);
  expect_resolve_error(s0, {"entrainment.areas", "at least one"});
  expect_resolve_error(with([](v1::Scenario& s) { s.mutable_entrainment()->mutable_areas(0)->clear_thickness_m(); }),
                       {"entrainment.areas[0]", "thickness"});
  expect_resolve_error(with([](v1::Scenario& s) { s.mutable_entrainment()->set_law("plough"); }), {"entrainment.law"});
  expect_resolve_error(with([](v1::Scenario& s) { s.mutable_entrainment()->set_erosion_energy_j_kg(-5); }),
                       {"entrainment.erosion_energy_j_kg"});
  expect_resolve_error(with([](v1::Scenario& s) { set_mu_i(s.mutable_material()); }),
                       {"entrainment", "constant mu"});
  make_polygons(d / "far.geojson", {square(600000, 5300000, 100)}, "EPSG:32632");
  auto far = sc;
  auto* fa = far.mutable_entrainment()->add_areas();
  fa->set_path("far.geojson");
  fa->set_thickness_m(0.3);
  expect_error(far, d, "entrainment.areas[0]");
  expect_resolve_error(with([](v1::Scenario& s) {
                         s.set_engine("vof");
                         s.mutable_material()->set_internal_friction_deg(30);
                       }),
                       {"entrainment", "3D engine"});
}

// Resistance areas are refused by name where they cannot work: no areas, an inverted band, a
// negative coefficient, an area away from the domain, a flow-dependent friction law, the 3D engine.
TEST(DepthAveraged, ResistanceAreasAreRefusedWhereTheyCannotWork) {
  TempDir d;
  make_dem(d / "dem.tif", 40, 20.0, 30);
  make_polygons(d / "rel.geojson", {square(500200, 5200400, 200)}, "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson");
  auto with = [&](auto change) {
    auto s = sc;
    s.mutable_resistance()->add_areas()->set_path(d / "rel.geojson");
    change(s);
    return s;
  };
  auto s0 = sc;
  s0.mutable_resistance()->set_drag_coefficient(0.02);
  expect_resolve_error(s0, {"resistance.areas", "at least one"});
  expect_resolve_error(with([](v1::Scenario& s) { s.mutable_resistance()->set_speed_min_m_s(50); }),
                       {"resistance.speed_min_m_s", "speed_max"});
  expect_resolve_error(with([](v1::Scenario& s) { s.mutable_resistance()->set_drag_coefficient(-1); }),
                       {"resistance.drag_coefficient"});
  expect_resolve_error(with([](v1::Scenario& s) { set_mu_i(s.mutable_material()); }),
                       {"resistance", "constant mu"});
  // An area away from the domain: refused before the run.
  make_polygons(d / "far.geojson", {square(600000, 5300000, 100)}, "EPSG:32632");
  auto far = sc;
  far.mutable_resistance()->add_areas()->set_path("far.geojson");
  expect_error(far, d, "resistance.areas[0].path");
  expect_resolve_error(with([](v1::Scenario& s) {
                         s.set_engine("vof");
                         s.mutable_material()->set_internal_friction_deg(30);
                       }),
                       {"resistance", "3D engine"});
}
