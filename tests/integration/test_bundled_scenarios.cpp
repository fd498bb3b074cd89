// The bundled depth-averaged scenarios, coarsened: In den Arelen, Wolfsgruben and the ISeeSnow cases.
#include <algorithm>
#include <cstdio>
#include <sstream>

#include "jobs/figures/hazard_map.hpp"
#include "jobs/figures/palette.hpp"
#include "terrain/points.hpp"
#include "tests/support/run_helpers.hpp"

using namespace runout::test_support::run;

namespace {

// The runout along the path by the benchmark's convention, computed here independently of the path
// analysis: every cell of max_pressure.tif with at least 1 kPa within 300 m of the path line,
// projected onto the line (its nearest point); the farthest such point's distance along the line.
// The path analysis (cross-sections every cell) must give it within one cell.
void check_path_runout(const TempDir& d, const jobs::ResolvedScenario& r) {
  GDALDatasetUniquePtr pr(GDALDataset::Open((d / "max_pressure.tif").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(pr);
  double gt[6];
  pr->GetGeoTransform(gt);
  const int nx = pr->GetRasterXSize(), ny = pr->GetRasterYSize();
  terrain::Grid g;
  g.nx = nx;
  g.ny = ny;
  g.dx = gt[1];
  g.x_min = gt[0];
  g.y_min = gt[3] + ny * gt[5];
  g.crs_wkt = pr->GetProjectionRef();
  const auto line = terrain::read_line(g, r.path.line_path, r.path.crs, "path");
  std::vector<float> p(std::size_t(nx) * ny);
  ASSERT_EQ(pr->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, nx, ny, p.data(), nx, ny, GDT_Float32, 0, 0), CE_None);
  double far = -1;
  for (int row = 0; row < ny; ++row)
    for (int i = 0; i < nx; ++i) {
      if (!(p[std::size_t(row) * nx + i] >= 1.0f)) continue;
      const double cx = gt[0] + (i + 0.5) * gt[1], cy = gt[3] + (row + 0.5) * gt[5];
      double best = INFINITY, s_best = 0, s0 = 0;
      for (std::size_t k = 1; k < line.size(); ++k) {
        const double ax = line[k - 1].first, ay = line[k - 1].second, bx = line[k].first - ax, by = line[k].second - ay;
        const double len = std::hypot(bx, by), t = std::clamp(((cx - ax) * bx + (cy - ay) * by) / (len * len), 0.0, 1.0);
        const double dist = std::hypot(cx - ax - t * bx, cy - ay - t * by);
        if (dist < best) {
          best = dist;
          s_best = s0 + t * len;
        }
        s0 += len;
      }
      if (best <= 300) far = std::max(far, s_best);
    }
  ASSERT_GT(far, 0);
  const auto rec = run_record(d / "run.json");
  ASSERT_TRUE(rec.results().path().has_runout_s_m());
  EXPECT_EQ(rec.results().path().criterion(), "max pressure >= 1 kPa");
  EXPECT_NEAR(rec.results().path().runout_s_m(), far, g.dx) << "path analysis against the benchmark convention";
  EXPECT_GT(rec.results().path().alpha_deg(), 5);
  EXPECT_LT(rec.results().path().alpha_deg(), 45);
  for (const char* f : {"path_profile.csv", "map_path_profile.png", "map_path_profile.pdf"}) EXPECT_TRUE(fs::exists(d / f)) << f;
  std::printf("path runout %.1f m, benchmark convention %.1f m, alpha %.2f deg, cell %.0f m\n", rec.results().path().runout_s_m(), far,
              rec.results().path().alpha_deg(), g.dx);
}

// The largest value of a raster over the cells whose centres lie within `radius` of (x, y) (the
// raster's CRS).
double max_near(const std::string& tif, double x, double y, double radius) {
  return read_raster_values(tif).max_where([&](double cx, double cy) { return std::hypot(cx - x, cy - y) <= radius; });
}

}  // namespace

TEST(Scenarios, InDenArelenReachesTheValleyFloor) {
  auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/in-den-arelen.json");
  r.dem.resolution = 30;  // coarser than the scenario's 10 m, to stay fast
  TempDir d;
  const auto sum = jobs::run_scenario(r, d.p.string());
  EXPECT_EQ(sum.crs, "EPSG:32632");
  EXPECT_LT(sum.volume_error, 1e-12);
  // 164,365 m2 of the polygon within 28-50 deg on the DEM's cubic surface at 9.56 m (its 76 m pixel / 8).
  EXPECT_NEAR(sum.release_volume_m3, 287904, 0.01 * 287904);
  check_outputs(d, sum, "WGS 84 / UTM zone 32N");
  EXPECT_TRUE(fs::exists(d / "outline.geojson"));
  // (Pure Coulomb friction with delta = 15 deg lets thin layers slide on over the long slopes above
  // 15 deg, so at 30 m the run may end by the end time rather than the kinetic-energy rule.)
  // The flow reaches the farmhouse (46.8367 N, 9.8539 E).
  GDALDatasetUniquePtr md(GDALDataset::Open((d / "max_depth.tif").c_str(), GDAL_OF_RASTER));
  OGRSpatialReference ll;
  ll.importFromEPSG(4326);
  ll.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  OGRSpatialReference utm = *md->GetSpatialRef();
  utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> ct(OGRCreateCoordinateTransformation(&ll, &utm));
  double x = 9.8539, y = 46.8367;
  ct->Transform(1, &x, &y);
  double gt[6];
  md->GetGeoTransform(gt);
  const int i = int((x - gt[0]) / gt[1]), rr = int((y - gt[3]) / gt[5]);
  float v = 0;
  ASSERT_EQ(md->GetRasterBand(1)->RasterIO(GF_Read, i, rr, 1, 1, &v, 1, 1, GDT_Float32, 0, 0), CE_None);
  EXPECT_GT(v, 0.01f);
}

// The demo as scripts/demo runs it (In den Arelen, 10 m): its maps colour speed, pressure and arrival
// time only inside the outline; the runout is one figure (the summary's, run.json's, the profile's
// and the map's point); and the path follows the flow. The flow splits into several gullies, so the
// path is the longest flow line: every station from the release's top to its farthest cell lies on
// a released or outlined cell, and it ends at the tongue that reaches farthest (south-east).
TEST(Scenarios, TheDemoMapsColourOnlyTheOutlineAndItsRunoutIsOneFigureOnTheFlowsPath) {
  const std::string file = std::string(RUNOUT_SOURCE_DIR) + "/scenarios/in-den-arelen.json";
  const auto r = jobs::load_scenario(file);
  TempDir d;
  const auto sum = jobs::run_scenario(r, d.p.string());
  const auto rec = run_record(d / "run.json");
  const auto& path = rec.results().path();
  EXPECT_EQ(path.source().rfind("the longest flow line", 0), 0u) << path.source();
  // One figure: the summary, run.json and the profile's last station at 1 kPa or more.
  ASSERT_TRUE(path.has_runout_s_m());
  EXPECT_NEAR(sum.path_runout_m, path.runout_s_m(), 1e-6);
  EXPECT_NE(jobs::runout_phrase(sum).find("runout " + std::to_string(int(std::lround(path.runout_s_m()))) + " m along the path"),
            std::string::npos)
      << jobs::runout_phrase(sum);
  std::ifstream csv(d / "path_profile.csv");
  std::string row;
  std::getline(csv, row);
  double last_s = -1;
  std::vector<std::pair<double, double>> stations;
  while (std::getline(csv, row)) {
    std::vector<double> v;
    std::stringstream ss(row);
    for (std::string c; std::getline(ss, c, ',');) v.push_back(c.empty() ? NAN : std::stod(c));
    stations.emplace_back(v[1], v[2]);
    if (v.size() > 6 && v[6] >= 1) last_s = v[0];
  }
  EXPECT_EQ(last_s, path.runout_s_m());
  // The path follows the flow: the stations up to the last on an outlined cell lie on outlined cells
  // (or, in the first 300 m, on the release), but for the smoothing's corners (at most 1 %); beyond
  // it the runout point is at most 100 m on, where a film thinner than the outline's depth still
  // exerts 1 kPa (the runout's criterion, AIMEC's).
  const auto depth = read_raster_values(d / "max_depth.tif");
  const auto runout_at = std::size_t(std::lround(path.runout_s_m() / path.section_spacing_m()));
  std::size_t on = 0, last_on = 0;
  for (std::size_t k = 0; k <= runout_at && k < stations.size(); ++k) {
    const int i = int((stations[k].first - depth.gt[0]) / depth.gt[1]), row_ = int((stations[k].second - depth.gt[3]) / depth.gt[5]);
    const bool flow = depth.v[std::size_t(row_) * depth.w + i] > r.outline_threshold;
    if (flow) last_on = k;
    on += flow || double(k) * path.section_spacing_m() < 300;
  }
  EXPECT_GE(double(on), 0.99 * double(last_on + 1)) << on << " of " << last_on + 1;
  EXPECT_LE(double(runout_at - last_on) * path.section_spacing_m(), 100.0);
  EXPECT_GT(path.runout_xyz(0), 565000);  // the south-eastern tongue
  EXPECT_LT(path.runout_xyz(1), 5187000);
  // No colour outside the outline: at the centre of every cell outside it (and not next to it, where
  // the outline's line is drawn) the maps show none of their palette's colours.
  const terrain::Grid g = terrain::grid_of_raster(d / "elevation.tif", "the demo's grid");
  for (const char* q : {"max_speed", "max_pressure", "arrival_time", "max_depth"}) {
    figures::HazardMap probe;  // where the map's frame lies: the same title, so the same layout
    probe.title = r.scenario.name() + ": " + figures::hazard_palette(q).title;
    const auto lay = figures::draw_hazard_map("", "", g, probe);
    GDALDatasetUniquePtr png(GDALDataset::Open((d / ("map_" + std::string(q) + ".png")).c_str(), GDAL_OF_RASTER));
    ASSERT_TRUE(png) << q;
    long outside = 0, coloured = 0;
    for (int row_ = 1; row_ + 1 < g.ny; ++row_)
      for (int i = 1; i + 1 < g.nx; ++i) {
        bool near = false;
        for (int a = -1; a <= 1; ++a)
          for (int b = -1; b <= 1; ++b) near |= depth.v[std::size_t(row_ + a) * g.nx + i + b] > r.outline_threshold;
        if (near || std::isnan(depth.v[std::size_t(row_) * g.nx + i])) continue;
        ++outside;
        figures::Rgb8 c{};
        for (int band = 0; band < 3; ++band)
          ASSERT_EQ(png->GetRasterBand(band + 1)->RasterIO(GF_Read, int(lay.map_x + (i + 0.5) * lay.cell_px),
                                                           int(lay.map_y + (row_ + 0.5) * lay.cell_px), 1, 1, &c[std::size_t(band)], 1,
                                                           1, GDT_Byte, 0, 0),
                    CE_None);
        for (const auto& cls : figures::hazard_palette(q).classes) coloured += c == cls.colour;
      }
    EXPECT_GT(outside, 50000) << q;
    EXPECT_EQ(coloured, 0) << q << ": cells outside the outline in a class's colour";
  }
  // The farmhouse's label does not cross the outline: the map's cells under its box are all inside
  // or all outside (the point lies on the outline's edge; its label moved off it).
  figures::HazardMap drawn;
  drawn.title = r.scenario.name() + ": maximum pressure";
  drawn.max_depth = depth.v;
  for (int row_ = 0; row_ < g.ny; ++row_)  // row 0 south, as the maps take it
    for (int i = 0; i < g.nx; ++i) drawn.max_depth[std::size_t(g.ny - 1 - row_) * g.nx + i] = depth.v[std::size_t(row_) * g.nx + i];
  drawn.outline_threshold = r.outline_threshold;
  const auto& poi = rec.results().points_of_interest(0);
  drawn.points.push_back({poi.name(), poi.x(), poi.y()});
  const auto placed = figures::draw_hazard_map(d / "labels.png", "", g, drawn);
  ASSERT_EQ(placed.label_boxes.size(), 1u);
  const auto& b = placed.label_boxes[0];
  bool in = false, out = false;
  for (double y = b[1]; y <= b[1] + b[3]; y += 1)
    for (double x = b[0]; x <= b[0] + b[2]; x += 1) {
      const int i = int((x - placed.map_x) / placed.cell_px), row_ = int((y - placed.map_y) / placed.cell_px);
      if (i < 0 || row_ < 0 || i >= g.nx || row_ >= g.ny) continue;
      (depth.v[std::size_t(row_) * g.nx + i] > r.outline_threshold ? in : out) = true;
    }
  EXPECT_FALSE(in && out) << "the farmhouse's label crosses the outline";
}

// In den Arelen with an illustrative erodible cover (a thickness raster in EPSG:2056, resampled onto
// the UTM grid) and a forest polygon: the flow takes up cover along the track and the volume balance
// counts it; cover_depth.tif holds the cover left (at most the 0.4 m laid, less where the flow passed),
// the maps outline both.
// In den Arelen with all of the ground's features: an erodible cover (a thickness raster in
// EPSG:2056), a forest (a polygon in WGS84) and a catch dam 12 m high across the northern gully (a
// crest line in EPSG:2056). The flow takes up cover, leaves material in the forest, and the dam
// catches the northern lobe: what passes it is a film (less than 1e-3 of the volume).
TEST(Scenarios, InDenArelenTakesUpTheCoverMeetsTheForestAndTheDam) {
  const auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/in-den-arelen-ground.json");
  TempDir d;
  const auto sum = jobs::run_scenario(r, d.p.string());
  EXPECT_LT(sum.volume_error, 1e-12);
  EXPECT_GT(sum.volume_entrained, 0.02 * sum.volume_initial);
  check_outputs(d, sum, "WGS 84 / UTM zone 32N");
  for (const char* f : {"cover_depth.tif", "detrained_depth.tif", "map_max_pressure.png"}) EXPECT_TRUE(fs::exists(d / f)) << f;
  const auto rec = run_record(d / "run.json");
  EXPECT_NEAR(rec.mass_balance().volume_entrained_m3(), sum.volume_entrained, 1e-9 * sum.volume_entrained);
  EXPECT_GT(rec.mass_balance().volume_detrained_m3(), 0.05 * sum.volume_initial);
  ASSERT_EQ(rec.dams_size(), 1);
  EXPECT_EQ(rec.dams(0).name(), "catch dam");
  EXPECT_EQ(rec.dams(0).height_max_m(), 12.0);
  EXPECT_NEAR(rec.dams(0).crest_length_m(), 301, 2);
  EXPECT_LT(rec.dams(0).overflow_m3(), 1e-3 * sum.volume_initial);
  EXPECT_GT(max_near(d / "max_depth.tif", 563940, 5188350, 40), 1.0);  // the flow reached the dam
  GDALDatasetUniquePtr ds(GDALDataset::Open((d / "cover_depth.tif").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(ds);
  std::vector<float> v(std::size_t(sum.nx) * sum.ny);
  ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, sum.nx, sum.ny, v.data(), sum.nx, sum.ny, GDT_Float32, 0, 0), CE_None);
  int has_nodata = 0;
  const double nodata = ds->GetRasterBand(1)->GetNoDataValue(&has_nodata);
  long laid = 0;
  for (float x : v) {
    if (!std::isfinite(x) || (has_nodata && x == float(nodata))) continue;
    EXPECT_GE(x, 0.0f);
    // The thickness is carried as the volume of the DEM's finer samples (as a release's is), so a
    // cell's normal depth may exceed the raster's 0.4 m by the slope's variation within it.
    EXPECT_LE(x, 0.41f);
    laid += x > 0.395f;
  }
  EXPECT_GT(laid, 20);  // cover the flow did not reach
}

TEST(Scenarios, WolfsgrubenRunsInTheDemCrs) {
  auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/wolfsgruben.json");
  r.dem.resolution = 20;  // coarser than the DEM's 5 m, to stay fast
  r.timeseries_interval = 0;
  TempDir d;
  const auto sum = jobs::run_scenario(r, d.p.string());
  EXPECT_EQ(sum.crs, "MGI / Austria Lambert");
  EXPECT_LT(sum.volume_error, 1e-12);
  check_outputs(d, sum, "MGI / Austria Lambert");
  EXPECT_NEAR(sum.release_area_m2, 135185, 0.05 * 135185);  // AvaFrame's projected release area
  EXPECT_GT(sum.runout_m, 1000);
  EXPECT_LT(sum.max_speed, 150);  // bounded (the curvature bound; without it this terrain ran away)
}

// The three ISeeSnow cases (validation.md A8), computed coarser than their 5 m DEMs to stay fast; the
// export is still on the DEM's own 5 m grid and extent.
TEST(Scenarios, IseesnowIdealizedTopo) {
  auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/iseesnow-idealized.json");
  r.dem.resolution = 10;
  TempDir d;
  jobs::RunOptions opt;
  opt.iseesnow_id = "01IdealizedTopo";
  const auto sum = jobs::run_scenario(r, d.p.string(), opt);
  EXPECT_EQ(sum.crs, "local metres");
  EXPECT_EQ(sum.nx, 502);
  EXPECT_LT(sum.volume_error, 1e-12);
  EXPECT_EQ(sum.volume_outflow, 0);
  EXPECT_EQ(sum.stop, "kinetic-energy");
  // 1.5 m normal to the surface over the 296.5 m x 139.8 m release rectangle (mean slope about 34 deg):
  // 71,960 m3 on the DEM's 5 m cells.
  EXPECT_NEAR(sum.release_volume_m3, 71960, 0.05 * 71960);
  EXPECT_GT(sum.runout_m, 1500);
  EXPECT_LT(sum.max_speed, 60);  // Voellmy xi = 2000 bounds the speed well below free fall
  check_outputs(d, sum, "local metres");
  EXPECT_FALSE(fs::exists(d / "outline.geojson"));  // no geographic position
  check_iseesnow(d, "release1HS", "01IdealizedTopo",
                 std::string(RUNOUT_SOURCE_DIR) + "/scenarios/data/iseesnow/idealized/DEM_IdealizedTopo.tif",
                 sum.volume_initial);
  check_path_runout(d, r);
}

TEST(Scenarios, IseesnowCoulombOnlyRunsFurtherThanVoellmy) {
  auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/iseesnow-coulomb.json");
  r.dem.resolution = 10;
  TempDir d;
  jobs::RunOptions opt;
  opt.iseesnow_id = "03CoulombOnly";
  const auto sum = jobs::run_scenario(r, d.p.string(), opt);
  EXPECT_LT(sum.volume_error, 1e-12);
  // Without turbulent drag the flow is faster and longer than IdealizedTopo's (same terrain and release):
  // the energy line of mu = 0.4 from about 1400 m of drop.
  EXPECT_GT(sum.max_speed, 80);
  EXPECT_GT(sum.runout_m, 2500);
  check_outputs(d, sum, "local metres");
  check_iseesnow(d, "release1HS", "03CoulombOnly",
                 std::string(RUNOUT_SOURCE_DIR) + "/scenarios/data/iseesnow/idealized/DEM_IdealizedTopo.tif",
                 sum.volume_initial);
  check_path_runout(d, r);
}

TEST(Scenarios, IseesnowRealTopo) {
  auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/iseesnow-realtopo.json");
  r.dem.resolution = 15;
  TempDir d;
  jobs::RunOptions opt;
  opt.iseesnow_id = "02RealTopo";
  const auto sum = jobs::run_scenario(r, d.p.string(), opt);
  EXPECT_EQ(sum.crs, "MGI / Austria Lambert");
  EXPECT_LT(sum.volume_error, 1e-12);
  EXPECT_NEAR(sum.release_area_m2, 135185, 0.1 * 135185);
  EXPECT_GT(sum.runout_m, 1000);
  check_outputs(d, sum, "MGI / Austria Lambert");
  check_iseesnow(d, "relWog", "02RealTopo",
                 std::string(RUNOUT_SOURCE_DIR) + "/scenarios/data/iseesnow/realtopo/DEM_RealTopo.tif",
                 sum.volume_initial);
  check_path_runout(d, r);
}
