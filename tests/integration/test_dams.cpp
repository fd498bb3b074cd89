// Dams and walls (scenario `dams[]`): how they are rasterised (no wall thinner than the grid), a dam
// higher than the flow stops it, whatever its geometry's thickness or direction, and a dam lower than
// a reservoir lets the volume above its crest pass (against the closed form), with the crossing
// counted at its crest.
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <vector>

#include "jobs/drivers/run.hpp"
#include "jobs/scenario/scenario.hpp"
#include "tests/support/run_helpers.hpp"
#include "terrain/terrain.hpp"

using namespace runout;
using namespace runout::test_support::run;

namespace {

// A grid of n x n cells of `cell` m from (500000, 5200000), flat, in UTM 32N.
terrain::Grid flat_grid(int n, double cell) {
  terrain::Grid g;
  g.nx = g.ny = n;
  g.dx = cell;
  g.x_min = 500000;
  g.y_min = 5200000;
  OGRSpatialReference s;
  s.importFromEPSG(32632);
  char* w = nullptr;
  s.exportToWkt(&w);
  g.crs_wkt = w;
  CPLFree(w);
  g.crs_name = "EPSG:32632";
  g.z.assign(g.cells(), 0.0);
  return g;
}

// Whether a 4-connected path of cells that are not raised leads from cell `from` to cell `to`.
bool reachable(const terrain::Grid& g, const std::vector<double>& raise, std::size_t from, std::size_t to) {
  std::vector<std::uint8_t> seen(g.cells(), 0);
  std::deque<std::size_t> q{from};
  seen[from] = 1;
  while (!q.empty()) {
    const std::size_t k = q.front();
    q.pop_front();
    if (k == to) return true;
    const int i = int(k % g.nx), j = int(k / g.nx);
    for (auto [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
      const int u = i + di, v = j + dj;
      if (u < 0 || v < 0 || u >= g.nx || v >= g.ny) continue;
      const std::size_t m = std::size_t(v) * g.nx + u;
      if (!seen[m] && raise[m] == 0) {
        seen[m] = 1;
        q.push_back(m);
      }
    }
  }
  return false;
}

// The largest of a raster of the run east of x (grid cells' centres), and its geotransform's x0, dx.
double max_east_of(const std::string& tif, double x) {
  GDALDatasetUniquePtr ds(GDALDataset::Open(tif.c_str(), GDAL_OF_RASTER));
  EXPECT_TRUE(ds);
  if (!ds) return NAN;
  double gt[6];
  ds->GetGeoTransform(gt);
  const int w = ds->GetRasterXSize(), h = ds->GetRasterYSize();
  std::vector<double> v(std::size_t(w) * h);
  EXPECT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, w, h, v.data(), w, h, GDT_Float64, 0, 0), CE_None);
  double m = 0;
  for (int r = 0; r < h; ++r)
    for (int i = 0; i < w; ++i)
      if (gt[0] + (i + 0.5) * gt[1] > x && std::isfinite(v[std::size_t(r) * w + i])) m = std::max(m, v[std::size_t(r) * w + i]);
  return m;
}

}  // namespace

// A crest line becomes a band of raised cells: every cell it passes through, grown by one cell in the
// four directions. A diagonal line and a polygon far thinner than a cell still part the grid: no
// 4-connected path of unraised cells (the scheme's fluxes pass the cells' faces) crosses them. The
// crest's gauge knows which faces lead to the line's right and left.
TEST(Dams, NoWallIsThinnerThanTheGrid) {
  TempDir d;
  const auto g = flat_grid(40, 10.0);
  const double x0 = 500000, y0 = 5200000;
  make_lines(d / "diag.geojson", {{{x0 + 37, y0 - 5}, {x0 + 405, y0 + 403}}}, "EPSG:32632");
  terrain::DamRequest rq{"dams[0]", d / "diag.geojson", "", true, 5.0, ""};
  const auto diag = terrain::rasterize_dam(g, rq);
  EXPECT_TRUE(diag.lines);
  EXPECT_FALSE(reachable(g, diag.raise, 39, std::size_t(39) * 40));  // south-east corner to north-west corner
  // The crest's gauge: a line heading north-east has the south-east on its right: its cells' east and
  // south faces lead right (or to another crest cell), their west and north faces left.
  // The part on the grid: from y = 0 (at 5 / 408 of the line) to x = 400 (at 363 / 368).
  EXPECT_NEAR(diag.length_m, std::hypot(368.0, 408.0) * (363.0 / 368 - 5.0 / 408), 1e-6);
  int right = 0, left = 0;
  for (const auto& side : diag.sides) {
    EXPECT_GE(side[1], 0);  // east
    EXPECT_GE(side[2], 0);  // south
    EXPECT_LE(side[0], 0);  // west
    EXPECT_LE(side[3], 0);  // north
    for (int f = 0; f < 4; ++f) (side[f] > 0 ? right : side[f] < 0 ? left : f) += side[f] != 0;
  }
  EXPECT_GT(right, 30);
  EXPECT_GT(left, 30);
  // Every raised cell of the diagonal band is at most one cell from a cell the line passes through.
  for (std::size_t k = 0; k < g.cells(); ++k) EXPECT_TRUE(diag.raise[k] == 0.0 || diag.raise[k] == 5.0);
  // A wall 2 m thick (a fifth of a cell) across the grid.
  make_polygons(d / "thin.geojson", {{{x0 + 203, y0 - 10}, {x0 + 205, y0 - 10}, {x0 + 205, y0 + 410}, {x0 + 203, y0 + 410}, {x0 + 203, y0 - 10}}},
                "EPSG:32632");
  const auto thin = terrain::rasterize_dam(g, {"dams[1]", d / "thin.geojson", "", true, 5.0, ""});
  EXPECT_FALSE(thin.lines);
  EXPECT_TRUE(thin.crest.empty());
  EXPECT_FALSE(reachable(g, thin.raise, 0, 39));
  for (int j = 0; j < 40; ++j) {  // three cells across: the one it lies in and its two neighbours
    int n = 0;
    for (int i = 0; i < 40; ++i) n += thin.raise[std::size_t(j) * 40 + i] > 0;
    EXPECT_EQ(n, 3) << "row " << j;
  }
  // Bad dams: no height, a point, no cell of the domain.
  EXPECT_THROW(terrain::rasterize_dam(g, {"dams[2]", d / "thin.geojson", "", false, 0, ""}), terrain::TerrainError);
  make_lines(d / "far.geojson", {{{x0 + 9000, y0}, {x0 + 9500, y0}}}, "EPSG:32632");
  try {
    terrain::rasterize_dam(g, {"dams[3]", d / "far.geojson", "", true, 5.0, ""});
    ADD_FAILURE() << "a dam off the grid was accepted";
  } catch (const terrain::TerrainError& e) {
    EXPECT_NE(std::string(e.what()).find("dams[3]"), std::string::npos) << e.what();
  }
}

// A pile of granular material 10 m high collapsing on flat ground (Coulomb, 5 deg) spreads at up
// to about 10 m/s; a dam 15 m high across the whole grid, 100 m from the pile, stops it: nothing
// passes, whether the dam is a straight crest line, a diagonal one, or a wall polygon 2 m thick on
// 10 m cells. Without the dam the flow goes beyond it.
TEST(Dams, ADamHigherThanTheFlowStopsIt) {
  TempDir d;
  make_dem_of(d / "dem.tif", 80, 10.0, [](int, int) { return 0.0; });
  const double x0 = 500000, y0 = 5200000, xd = std::getenv("XD") ? std::atof(std::getenv("XD")) : 505, beyond = x0 + xd + 30;
  make_polygons(d / "rel.geojson", {square(x0 + 200, y0 + 300, 200)}, "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson", 10);
  sc.mutable_releases(0)->set_thickness_m(std::getenv("TH") ? std::atof(std::getenv("TH")) : 10);
  sc.mutable_material()->set_bed_friction_deg(std::getenv("FRIC") ? std::atof(std::getenv("FRIC")) : 5);
  sc.mutable_numerics()->set_end_time_s(300);
  sc.mutable_outputs()->set_maps(false);
  fs::create_directories(d / "open");
  jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "open");
  std::printf("open: depth beyond %.3f speed at dam %.2f\n", max_east_of(d / "open/max_depth.tif", beyond),
              max_east_of(d / "open/max_speed.tif", x0 + xd - 20));
  ASSERT_GT(max_east_of(d / "open/max_depth.tif", beyond), 0.5);
  make_lines(d / "straight.geojson", {{{x0 + xd, y0 - 50}, {x0 + xd, y0 + 850}}}, "EPSG:32632");
  make_lines(d / "diagonal.geojson", {{{x0 + xd - 40, y0 - 50}, {x0 + xd + 40, y0 + 850}}}, "EPSG:32632");
  make_polygons(d / "wall.geojson",
                {{{x0 + xd - 1, y0 - 50}, {x0 + xd + 1, y0 - 50}, {x0 + xd + 1, y0 + 850}, {x0 + xd - 1, y0 + 850}, {x0 + xd - 1, y0 - 50}}},
                "EPSG:32632");
  for (const char* name : {"straight", "diagonal", "wall"}) {
    auto s = sc;
    auto* dam = s.add_dams();
    dam->set_name(name);
    dam->set_path(std::string(name) + ".geojson");
    dam->set_height_m(std::getenv("DH") ? std::atof(std::getenv("DH")) : 15);
    fs::create_directories(d / name);
    jobs::run_scenario(jobs::resolve_scenario(s, d.p.string()), d / name);
    EXPECT_EQ(max_east_of(d / (std::string(name) + "/max_depth.tif"), beyond + 50), 0.0) << name;
    const auto rec = run_record(d / (std::string(name) + "/run.json"));
    ASSERT_EQ(rec.dams_size(), 1);
    EXPECT_EQ(rec.dams(0).name(), name);
    EXPECT_GT(rec.dams(0).max_depth_m(), 0.5) << name;  // the flow reached it
    EXPECT_LT(rec.dams(0).overflow_m3(), 1e-9 * rec.mass_balance().volume_initial_m3()) << name;
    EXPECT_LT(rec.mass_balance().relative_error(), 1e-12);
  }
}

// A reservoir (a flat basin walled by three dams 20 m high, a release 5 m deep at rest, no friction)
// closed on its fourth side by a dam 2 m high: the volume above the crest, (5 - 2) m times the
// basin's area, passes the low dam and nothing passes the others. The weir's discharge falls with the
// head over it (q ~ head^1.5), so after 3000 s about 2 % is still on its way; the crossing counted at
// the crest is within 5 % of the closed form.
TEST(Dams, ADamLowerThanAReservoirLetsTheExcessOver) {
  TempDir d;
  make_dem_of(d / "dem.tif", 80, 10.0, [](int, int) { return 0.0; });
  const double x0 = 500000, y0 = 5200000;
  // Crest lines on the cells' centres (x, y = 205 and 505 m): bands of three cells, 190-220 and
  // 490-520 m; the basin between them is 270 m square.
  make_lines(d / "high.geojson",
             {{{x0 + 205, y0 + 205}, {x0 + 505, y0 + 205}}, {{x0 + 205, y0 + 505}, {x0 + 505, y0 + 505}}, {{x0 + 205, y0 + 205}, {x0 + 205, y0 + 505}}},
             "EPSG:32632");
  make_lines(d / "weir.geojson", {{{x0 + 505, y0 + 205}, {x0 + 505, y0 + 505}}}, "EPSG:32632");
  make_polygons(d / "basin.geojson", {{{x0 + 220, y0 + 220}, {x0 + 490, y0 + 220}, {x0 + 490, y0 + 490}, {x0 + 220, y0 + 490}, {x0 + 220, y0 + 220}}},
                "EPSG:32632");
  v1::Scenario s = base_scenario(d / "dem.tif", d / "basin.geojson", 10);
  s.mutable_releases(0)->set_thickness_m(5);
  s.mutable_material()->clear_bed_friction_deg();
  s.mutable_material()->set_rheology("voellmy");
  s.mutable_material()->set_voellmy_mu(0);
  s.mutable_material()->set_voellmy_xi(std::getenv("XI") ? std::atof(std::getenv("XI")) : 400);
  s.mutable_numerics()->set_end_time_s(std::getenv("TEND") ? std::atof(std::getenv("TEND")) : 3000);
  s.mutable_numerics()->set_stop_fraction(0);
  s.mutable_outputs()->set_maps(false);
  auto* high = s.add_dams();
  high->set_name("walls");
  high->set_path("high.geojson");
  high->set_height_m(20);
  auto* weir = s.add_dams();
  weir->set_name("weir");
  weir->set_path("weir.geojson");
  weir->set_height_m(2);
  fs::create_directories(d / "out");
  jobs::run_scenario(jobs::resolve_scenario(s, d.p.string()), d / "out");
  const auto rec = run_record(d / "out/run.json");
  const double area = 270.0 * 270.0, excess = (5.0 - 2.0) * area;
  EXPECT_NEAR(rec.mass_balance().volume_initial_m3(), 5.0 * area, 1e-6 * 5 * area) << rec.release().DebugString() << rec.grid().DebugString();
  ASSERT_EQ(rec.dams_size(), 2);
  const auto& w = rec.dams(1);
  EXPECT_EQ(w.name(), "weir");
  EXPECT_NEAR(w.overflow_m3() / excess, 1.0, 0.05) << w.overflow_m3() << " against " << excess;
  std::printf("overflow/excess %.4f walls %.3g\n", w.overflow_m3() / excess, rec.dams(0).overflow_m3());
  {
    GDALDatasetUniquePtr ds(GDALDataset::Open((d / "out/deposit.tif").c_str(), GDAL_OF_RASTER));
    std::vector<double> v(6400);
    ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 80, 80, v.data(), 80, 80, GDT_Float64, 0, 0);
    double in = 0, band = 0, out = 0, mx = 0, mn = 1e9;
    for (int r = 0; r < 80; ++r) for (int i = 0; i < 80; ++i) {
      const double x = (i + 0.5) * 10, y = (79 - r + 0.5) * 10, h = std::isfinite(v[r * 80 + i]) ? v[r * 80 + i] : 0;
      const bool inb = x > 220 && x < 490 && y > 220 && y < 490, inband = x > 190 && x < 520 && y > 190 && y < 520 && !inb;
      (inb ? in : inband ? band : out) += h * 100;
      if (inb) { mx = std::max(mx, h); mn = std::min(mn, h); }
    }
    std::printf("basin %.1f band %.1f outside %.1f  max %.4f min %.4f  final %.1f outflow %.1f\n", in, band, out, mx, mn,
                rec.mass_balance().volume_final_m3(), rec.mass_balance().volume_outflow_m3());
  }
  EXPECT_GT(w.crossed_right_m3(), 0.9 * excess);  // the weir's line heads north: its right is east, the outside
  EXPECT_LT(rec.dams(0).overflow_m3(), 1e-6 * excess);
  EXPECT_LT(rec.mass_balance().relative_error(), 1e-12);
}
