// Secondary releases of the depth-averaged engine (releases[].secondary): an area waits at rest until
// the flow reaches it, then its whole volume joins the flow; each polygon is an area of its own.
#include "jobs/digest/sha256.hpp"
#include "tests/support/run_helpers.hpp"

using namespace runout::test_support::run;

namespace {

// The synthetic slope of the terrain tests, the primary release upslope, and a secondary release
// file with one square in the flow's path and one far off it.
v1::Scenario with_secondary(const TempDir& d) {
  make_dem(d / "dem.tif", 120, 20.0, 30);
  make_polygons(d / "rel.geojson", {square(500200, 5201000, 300)}, "EPSG:32632");
  make_polygons(d / "sec.geojson", {square(500800, 5201000, 200), square(500800, 5202100, 200)}, "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson");
  auto* r = sc.add_releases();
  r->set_path(d / "sec.geojson");
  r->set_thickness_m(1.0);
  r->set_secondary(true);
  return sc;
}

// The smallest arrival time over the cells of the square (x0, y0, a) in an arrival_time.tif.
double first_arrival(const fs::path& tif, double x0, double y0, double a) {
  GDALDatasetUniquePtr ds(GDALDataset::Open(tif.c_str(), GDAL_OF_RASTER));
  EXPECT_TRUE(ds);
  double gt[6];
  ds->GetGeoTransform(gt);
  const int nx = ds->GetRasterXSize(), ny = ds->GetRasterYSize();
  std::vector<float> v(std::size_t(nx) * ny);
  EXPECT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, nx, ny, v.data(), nx, ny, GDT_Float32, 0, 0), CE_None);
  double first = INFINITY;
  for (int r = 0; r < ny; ++r)
    for (int i = 0; i < nx; ++i) {
      const double cx = gt[0] + (i + 0.5) * gt[1], cy = gt[3] + (r + 0.5) * gt[5];
      const float t = v[std::size_t(r) * nx + i];
      if (cx > x0 && cx < x0 + a && cy > y0 && cy < y0 + a && t != -9999.0f) first = std::min(first, double(t));
    }
  return first;
}

}  // namespace

TEST(SecondaryRelease, StartsWhenTheFlowArrivesAndKeepsTheMassBalance) {
  TempDir d;
  auto sc = with_secondary(d);
  fs::create_directories(d / "with");
  const auto with = jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "with");
  const auto rec = run_record(d / "with/run.json");
  ASSERT_EQ(rec.release().secondary_size(), 2);
  const auto& in_path = rec.release().secondary(0);
  const auto& off_path = rec.release().secondary(1);
  // Each polygon an area of its own: 10 x 10 cells of 1 m normal thickness on the plane that falls
  // tan 30 deg to the east and 0.02 to the south.
  EXPECT_EQ(in_path.cells(), 100);
  EXPECT_NEAR(in_path.volume_m3(), 100 * 400.0 * std::sqrt(1 + std::pow(std::tan(30 * M_PI / 180), 2) + 0.02 * 0.02), 1e-6 * in_path.volume_m3());  // the DEM holds Float32
  // The area in the path was released; its volume joined the flow, and the mass balance holds with
  // it. The one off the path never was, and none of its volume is in the flow.
  ASSERT_TRUE(in_path.has_released_at_s());
  EXPECT_FALSE(off_path.has_released_at_s());
  EXPECT_NEAR(rec.mass_balance().volume_secondary_m3(), in_path.volume_m3(), 1e-9 * in_path.volume_m3());
  EXPECT_LT(rec.mass_balance().relative_error(), 1e-12);
  const double primary = rec.mass_balance().volume_initial_m3();
  EXPECT_NEAR(rec.mass_balance().volume_final_m3() + rec.mass_balance().volume_outflow_m3(), primary + in_path.volume_m3(),
              1e-9 * primary);
  EXPECT_NEAR(with.release_volume_m3, primary, 1e-6 * primary);  // the primary release alone
  // It starts when the flow arrives: the first arrival over its cells in the run without it (the
  // runs are the same bits until then).
  sc.mutable_releases()->RemoveLast();
  fs::create_directories(d / "without");
  const auto without = jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "without");
  const double arrival = first_arrival(d / "without/arrival_time.tif", 500800, 5201000, 200);
  EXPECT_NEAR(in_path.released_at_s(), arrival, 1e-5 * arrival);  // arrival_time.tif is Float32
  // With it, more material reaches further.
  EXPECT_GT(with.affected_area_m2, without.affected_area_m2);
}

// A run stopped after the release and continued from its checkpoint is the uninterrupted run; a
// checkpoint taken with other secondary releases is refused.
TEST(SecondaryRelease, ContinuedRunIsTheUninterruptedRun) {
  TempDir d;
  const auto r = jobs::resolve_scenario(with_secondary(d), d.p.string());
  for (const char* o : {"whole", "part", "continued"}) fs::create_directories(d / o);
  jobs::run_scenario(r, d / "whole");
  const double released = run_record(d / "whole/run.json").release().secondary(0).released_at_s();
  jobs::RunOptions cut;
  cut.checkpoint_path = d / "cut.h5";
  cut.progress_every = 1;
  cut.progress = [&](const engine::Progress& p) { return p.t < released + 5; };
  ASSERT_EQ(jobs::run_scenario(r, d / "part", cut).stop, "cancelled");
  jobs::RunOptions cont;
  cont.restart_path = d / "cut.h5";
  jobs::run_scenario(r, d / "continued", cont);
  for (const char* f : {"max_depth.tif", "max_speed.tif", "deposit.tif", "arrival_time.tif"})
    EXPECT_EQ(jobs::sha256_file(d / (std::string("whole/") + f)), jobs::sha256_file(d / (std::string("continued/") + f))) << f;
  const auto a = run_record(d / "whole/run.json"), b = run_record(d / "continued/run.json");
  EXPECT_EQ(a.mass_balance().volume_final_m3(), b.mass_balance().volume_final_m3());
  EXPECT_EQ(a.release().secondary(0).released_at_s(), b.release().secondary(0).released_at_s());
}

TEST(SecondaryRelease, BadUsesAreNamed) {
  TempDir d;
  auto sc = with_secondary(d);
  sc.mutable_releases(0)->set_secondary(true);
  expect_error(sc, d, "releases: every release is secondary");
  sc = with_secondary(d);
  sc.set_engine("vof");
  sc.mutable_material()->set_internal_friction_deg(30);
  expect_error(sc, d, "releases[1].secondary: the 3D engine takes no secondary releases");
}
