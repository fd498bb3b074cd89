// VOF checkpoints: runs continued from any checkpoint are the uninterrupted run, bit for bit
// (docs/design/vof.md, "Checkpoints").
#include "tests/support/run_helpers.hpp"

using namespace runout::test_support::run;

namespace {
// Two VOF runs' fields.h5 hold the same datasets with the same bits and the same frame times.
void expect_same_vof_fields(const std::string& a, const std::string& b) {
  GDALAllRegister();
  GDALDatasetUniquePtr fa(GDALDataset::Open((a + "/fields.h5").c_str(), GDAL_OF_RASTER));
  GDALDatasetUniquePtr fb(GDALDataset::Open((b + "/fields.h5").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(fa && fb) << a << " " << b;
  auto list = [](GDALDataset& ds, const char* domain, bool names_only) {
    std::vector<std::string> v;
    for (char** m = ds.GetMetadata(domain); m && *m; ++m) {
      std::string e = *m;
      if (names_only) {
        if (e.find("_NAME=") == std::string::npos) continue;
        e = e.substr(e.find("://") + 3);  // the dataset's path in the file
      }
      v.push_back(e);
    }
    return v;
  };
  EXPECT_EQ(list(*fa, "", false), list(*fb, "", false));  // the frames' times
  const auto names = list(*fa, "SUBDATASETS", true);
  ASSERT_EQ(names, list(*fb, "SUBDATASETS", true));
  ASSERT_GT(names.size(), 5u);
  for (const auto& n : names) {
    std::vector<double> v[2];
    for (int k = 0; k < 2; ++k) {
      GDALDatasetUniquePtr ds(GDALDataset::Open(("HDF5:\"" + (k ? b : a) + "/fields.h5\"://" + n).c_str(), GDAL_OF_RASTER));
      ASSERT_TRUE(ds) << n;
      const int nx = ds->GetRasterXSize(), ny = ds->GetRasterYSize(), nb = ds->GetRasterCount();
      v[k].resize(std::size_t(nx) * ny * nb);
      for (int band = 1; band <= nb; ++band)
        ASSERT_EQ(ds->GetRasterBand(band)->RasterIO(GF_Read, 0, 0, nx, ny, v[k].data() + std::size_t(band - 1) * nx * ny, nx, ny, GDT_Float64,
                                                    0, 0),
                  CE_None);
    }
    ASSERT_EQ(v[0].size(), v[1].size()) << n;
    EXPECT_EQ(std::memcmp(v[0].data(), v[1].data(), v[0].size() * sizeof(double)), 0) << n << " differs";
  }
}
// run.json of a VOF run without what may differ between a continued run and the uninterrupted one:
// the timings and the time it was continued from.
std::string vof_record(const std::string& dir) {
  auto j = run_record(dir + "/run.json");
  j.clear_timings_s();
  j.clear_created_utc();
  j.mutable_solver()->clear_continued_from_t_s();
  j.mutable_execution()->clear_petsc_options();  // PETSc's database gains the options of each run in the process
  j.mutable_terrain_mesh()->clear_footprint_seconds();  // a timing
  return j.DebugString();
}
void expect_same_vof_outputs(const std::string& a, const std::string& b) {
  expect_same_vof_fields(a, b);
  EXPECT_EQ(vof_record(a), vof_record(b));
}

// The run stopped after `stop_step` steps through the progress hook (as SIGTERM and Ctrl-C stop it),
// its checkpoint written to `cp` there (and every `every` s before, if given).
jobs::RunSummary run_cut(const jobs::ResolvedScenario& r, const fs::path& dir, const fs::path& cp, long stop_step,
                         double every = 0) {
  jobs::RunOptions cut;
  cut.checkpoint_path = cp;
  if (every > 0) cut.checkpoint_interval_s = every;
  cut.progress_every = 1;
  cut.progress = [stop_step](const engine::Progress& p) { return p.step < stop_step; };
  return jobs::run_scenario(r, dir, cut);
}

// A VOF scenario run in every way a run can go: without checkpoints; with checkpoints every
// `every` s; stopped after `stop_step` steps through the progress hook (as SIGTERM and Ctrl-C stop
// it), its checkpoint written there, and continued from it (writing its own checkpoints to the same
// file); continued again from the last checkpoint that continued run wrote; and continued from the
// last periodic checkpoint of the run with checkpoints. Each writes the outputs of the run without
// checkpoints, bit for bit.
void expect_exact_vof_continuation(const jobs::ResolvedScenario& r, double every, long stop_step) {
  TempDir d;
  for (const char* o : {"whole", "checked", "part", "continued", "again", "periodic"}) fs::create_directories(d / o);
  const auto whole = jobs::run_scenario(r, d / "whole");
  ASSERT_EQ(whole.stop, "end-time");
  ASSERT_GT(whole.steps, stop_step + 10);
  jobs::RunOptions checked;
  checked.checkpoint_path = d / "every.h5";
  checked.checkpoint_interval_s = every;
  EXPECT_EQ(jobs::run_scenario(r, d / "checked", checked).steps, whole.steps);
  ASSERT_TRUE(fs::exists(d / "every.h5"));
  expect_same_vof_outputs(d / "whole", d / "checked");
  const auto part = run_cut(r, d / "part", d / "cut.h5", stop_step, every);
  ASSERT_EQ(part.stop, "cancelled");
  ASSERT_EQ(part.steps, stop_step);
  jobs::RunOptions cont;
  cont.restart_path = d / "cut.h5";
  cont.checkpoint_path = d / "cut.h5";
  cont.checkpoint_interval_s = every;
  EXPECT_EQ(jobs::run_scenario(r, d / "continued", cont).steps, whole.steps);
  expect_same_vof_outputs(d / "whole", d / "continued");
  EXPECT_NEAR(record_figure(d / "continued/run.json", "continued_from_t_s"), part.t, 1e-9);
  jobs::RunOptions again;
  again.restart_path = d / "cut.h5";  // the continued run's last periodic checkpoint
  EXPECT_EQ(jobs::run_scenario(r, d / "again", again).steps, whole.steps);
  expect_same_vof_outputs(d / "whole", d / "again");
  EXPECT_GT(record_figure(d / "again/run.json", "continued_from_t_s"), part.t);
  jobs::RunOptions periodic;
  periodic.restart_path = d / "every.h5";
  EXPECT_EQ(jobs::run_scenario(r, d / "periodic", periodic).steps, whole.steps);
  expect_same_vof_outputs(d / "whole", d / "periodic");
}
}  // namespace

// The coarse B2 collapse under PISO (the default), stopped at an arbitrary step.
TEST(Scenarios, VofRunContinuedFromAnyCheckpointIsTheUninterruptedRun) {
  expect_exact_vof_continuation(coarse_b2(0.3), 0.3 / 7, 137);
}

// The same under the consistent pressure coupling with two outer correctors (the momentum predictor
// and its solver).
TEST(Scenarios, VofRunContinuedFromAnyCheckpointIsTheUninterruptedRunConsistentCoupling) {
  auto r = coarse_b2(0.25);
  auto* lab = r.scenario.mutable_lab();
  lab->set_pressure_coupling("consistent");
  lab->set_outer_correctors(2);
  r = jobs::resolve_scenario(r.scenario, std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab");
  expect_exact_vof_continuation(r, 0.25 / 6, 101);
}

// A 3D block (the B2 column on 1.5 cm cells, three cells across).
TEST(Scenarios, VofRunContinuedFromAnyCheckpointIsTheUninterruptedRun3d) {
  auto r = coarse_b2(0.15);
  auto* lab = r.scenario.mutable_lab();
  lab->set_nx(30);
  lab->set_ny(10);
  lab->set_nz(3);
  lab->set_z_min(0);
  lab->set_z_max(0.045);
  lab->set_write_interval_s(0.05);
  r = jobs::resolve_scenario(r.scenario, std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab");
  expect_exact_vof_continuation(r, 0.15 / 5, 53);
}

// A checkpoint of an earlier format (without the pressure solver's state) is refused by name, so
// that the service runs such a job again from the start.
TEST(Scenarios, VofCheckpointOfAnEarlierFormatIsRefused) {
  auto r = coarse_b2(0.1);
  TempDir d;
  fs::create_directories(d / "a");
  fs::create_directories(d / "b");
  jobs::RunOptions o;
  o.checkpoint_path = d / "cp.h5";
  o.checkpoint_interval_s = 0.05;
  ASSERT_EQ(jobs::run_scenario(r, d / "a", o).stop, "end-time");
  std::string bytes = read_text(d / "cp.h5");
  const std::string now = "runout VOF checkpoint 3", old = "runout VOF checkpoint 2";
  const auto at = bytes.find(now);
  ASSERT_NE(at, std::string::npos);
  bytes.replace(at, now.size(), old);
  std::ofstream(d / "cp.h5", std::ios::binary | std::ios::trunc) << bytes;
  jobs::RunOptions cont;
  cont.restart_path = d / "cp.h5";
  try {
    jobs::run_scenario(r, d / "b", cont);
    FAIL() << "a checkpoint of format 2 was accepted";
  } catch (const jobs::ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("another build"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("from the start"), std::string::npos) << e.what();
  }
}

// The 3D engine on terrain (In den Arelen on 90 m columns, 4 s), stopped halfway through the progress
// hook and continued from its checkpoint: the frames, run.json and every raster of the uninterrupted
// run, bit for bit (the set-up is built again from the scenario and the checkpoint restores the
// solver, the loop's figures and the hazard maps' running maxima).
TEST(Scenarios, TerrainVofRunContinuedFromItsCheckpointIsTheUninterruptedRun) {
  const fs::path file = fs::path(RUNOUT_SOURCE_DIR) / "scenarios" / "in-den-arelen-3d.json";
  auto sc = jobs::parse_scenario_json(read_text(file));
  sc.mutable_grid()->set_resolution_m(90);
  sc.mutable_numerics()->set_end_time_s(4);
  sc.mutable_vof()->set_write_interval_s(1.5);
  const auto r = jobs::resolve_scenario(sc, file.parent_path().string());
  ASSERT_EQ(r.engine, jobs::kVofTerrainEngine);
  TempDir d;
  for (const char* o : {"whole", "part", "continued"}) fs::create_directories(d / o);
  const auto whole = jobs::run_scenario(r, d / "whole");
  ASSERT_EQ(whole.stop, "end-time");
  const long stop_step = whole.steps / 2;
  ASSERT_GT(stop_step, 10);
  const auto part = run_cut(r, d / "part", d / "cut.h5", stop_step);
  ASSERT_EQ(part.stop, "cancelled");
  ASSERT_EQ(part.steps, stop_step);
  jobs::RunOptions cont;
  cont.restart_path = d / "cut.h5";
  EXPECT_EQ(jobs::run_scenario(r, d / "continued", cont).steps, whole.steps);
  expect_same_vof_outputs(d / "whole", d / "continued");
  EXPECT_NEAR(record_figure(d / "continued/run.json", "continued_from_t_s"), part.t, 1e-9);
  int rasters = 0;
  for (const auto& e : fs::directory_iterator(d / "whole")) {
    if (e.path().extension() != ".tif") continue;
    ++rasters;
    EXPECT_EQ(read_text(e.path()), read_text(d / "continued" / e.path().filename())) << e.path().filename();
  }
  EXPECT_GE(rasters, 5);
}
