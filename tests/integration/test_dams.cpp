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

// The largest value of a raster of the run over the cells whose centres lie in xa <= x < xb.
double max_between(const std::string& tif, double xa, double xb) {
  return read_raster_values(tif).max_where([&](double x, double) { return x >= xa && x < xb; });
}

}  // namespace

// A crest line becomes the cells it passes through, a footprint the cells it covers or its outline
// passes through, each with the dam's height. A diagonal line and a polygon far thinner than a cell
// still part the grid: the cells a line passes through touch at least at corners, and no 4-connected
// path of cells off the dam (the scheme's fluxes pass the cells' faces) crosses them. The crest's
// gauge knows which faces lead to the line's right and left.
TEST(Dams, NoWallIsThinnerThanTheGrid) {
  TempDir d;
  const auto g = flat_grid(40, 10.0);
  const double x0 = 500000, y0 = 5200000;
  make_lines(d / "diag.geojson", {{{x0 + 37, y0 - 5}, {x0 + 405, y0 + 403}}}, "EPSG:32632");
  terrain::DamRequest rq{"dams[0]", d / "diag.geojson", "", true, 5.0, ""};
  const auto diag = terrain::rasterize_dam(g, rq);
  EXPECT_TRUE(diag.lines);
  EXPECT_FALSE(reachable(g, diag.height, 39, std::size_t(39) * 40));  // south-east corner to north-west corner
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
  // The dam's cells are the crest's cells, each at the dam's height.
  EXPECT_EQ(long(diag.crest.size()), diag.cells);
  for (std::size_t k = 0; k < g.cells(); ++k) EXPECT_TRUE(diag.height[k] == 0.0 || diag.height[k] == 5.0);
  // A wall 2 m thick (a fifth of a cell) across the grid: one cell in each row, the one it lies in.
  make_polygons(d / "thin.geojson", {{{x0 + 203, y0 - 10}, {x0 + 205, y0 - 10}, {x0 + 205, y0 + 410}, {x0 + 203, y0 + 410}, {x0 + 203, y0 - 10}}},
                "EPSG:32632");
  const auto thin = terrain::rasterize_dam(g, {"dams[1]", d / "thin.geojson", "", true, 5.0, ""});
  EXPECT_FALSE(thin.lines);
  EXPECT_TRUE(thin.crest.empty());
  EXPECT_FALSE(reachable(g, thin.height, 0, 39));
  for (int j = 0; j < 40; ++j) EXPECT_GT(thin.height[std::size_t(j) * 40 + 20], 0.0) << "row " << j;
  EXPECT_EQ(thin.cells, 40);
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

// A pile of granular material 10 m high collapsing on flat ground (Coulomb, 2 deg) reaches the line
// x = 505 m at depth h and speed u (measured without a dam: h about 1 m, u about 10 m/s, so that
// h + u^2 / 2g is about 6 m). A dam one cell wide across the whole grid there, 8 m high (above the
// flow's run-up), stops it: nothing passes, whether the dam is a straight crest line, a diagonal one
// or a wall polygon 2 m thick on 10 m cells. A dam 3 m high (above the flow's depth, below its
// run-up) is overtopped: the flow climbs it with its velocity head.
TEST(Dams, ADamHigherThanTheFlowsRunUpStopsIt) {
  TempDir d;
  make_dem_of(d / "dem.tif", 80, 10.0, [](int, int) { return 0.0; });
  const double x0 = 500000, y0 = 5200000, xd = x0 + 505;
  make_polygons(d / "rel.geojson", {square(x0 + 200, y0 + 300, 200)}, "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson", 10);
  sc.mutable_releases(0)->set_thickness_m(10);
  sc.mutable_material()->set_bed_friction_deg(2);
  sc.mutable_numerics()->set_end_time_s(300);
  sc.mutable_outputs()->set_maps(false);
  fs::create_directories(d / "open");
  jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "open");
  const double h = max_between(d / "open/max_depth.tif", xd - 5, xd + 5), u = max_between(d / "open/max_speed.tif", xd - 5, xd + 5);
  ASSERT_GT(max_between(d / "open/max_depth.tif", xd + 30, x0 + 800), 0.5);  // without a dam the flow goes on
  ASSERT_LT(h, 3.0);
  ASSERT_GT(h + u * u / (2 * 9.81), 3.5);
  ASSERT_LT(h + u * u / (2 * 9.81), 7.0);
  make_lines(d / "straight.geojson", {{{xd, y0 - 50}, {xd, y0 + 850}}}, "EPSG:32632");
  make_lines(d / "diagonal.geojson", {{{xd - 40, y0 - 50}, {xd + 40, y0 + 850}}}, "EPSG:32632");
  make_polygons(d / "wall.geojson", {{{xd - 1, y0 - 50}, {xd + 1, y0 - 50}, {xd + 1, y0 + 850}, {xd - 1, y0 + 850}, {xd - 1, y0 - 50}}},
                "EPSG:32632");
  auto run = [&](const std::string& name, const std::string& file, double height) {
    auto s = sc;
    auto* dam = s.add_dams();
    dam->set_name(name);
    dam->set_path(file);
    dam->set_height_m(height);
    fs::create_directories(d / name);
    jobs::run_scenario(jobs::resolve_scenario(s, d.p.string()), d / name);
    const auto rec = run_record(d / (name + "/run.json"));
    EXPECT_EQ(rec.dams_size(), 1);
    EXPECT_EQ(rec.dams(0).name(), name);
    EXPECT_LT(rec.mass_balance().relative_error(), 1e-12) << name;
    EXPECT_GT(max_between(d / (name + "/max_depth.tif"), xd - 55, xd - 45), 1.0) << name;  // the flow reached it
    return rec;
  };
  for (const char* name : {"straight", "diagonal", "wall"}) {
    const auto rec = run(name, std::string(name) + ".geojson", 8.0);
    EXPECT_EQ(max_between(d / (std::string(name) + "/max_depth.tif"), xd + 45, x0 + 800), 0.0) << name;
    if (rec.dams(0).kind() == "crest lines") EXPECT_EQ(rec.dams(0).overflow_m3(), 0.0) << name;
  }
  const auto low = run("low", "straight.geojson", 3.0);
  std::printf("at the dam without it: h %.2f m, u %.2f m/s, h + u^2/2g %.2f m; 3 m dam: %.0f m3 over\n", h, u,
              h + u * u / (2 * 9.81), low.dams(0).overflow_m3());
  EXPECT_GT(low.dams(0).overflow_m3(), 1e-3 * low.mass_balance().volume_initial_m3());
  EXPECT_GT(max_between(d / "low/max_depth.tif", xd + 30, x0 + 800), 0.05);
}

// A reservoir (a flat basin walled by three dams 20 m high, a release 5 m deep at rest, no friction)
// closed on its fourth side by a dam 2 m high: at rest the basin holds 2 m, so the volume above the
// crest, (5 - 2) m times the basin's area, passes the low dam and nothing passes the others. The
// weir's discharge falls with the head over it (q ~ head^1.5, the broad-crested weir), so a little of
// the excess is still on its way at the end; the crossing counted at the crest is within 5 % of the
// closed form, and the water left in the basin lies flat (the steps keep a lake at rest).
TEST(Dams, ADamLowerThanAReservoirLetsTheExcessOver) {
  TempDir d;
  make_dem_of(d / "dem.tif", 80, 10.0, [](int, int) { return 0.0; });
  const double x0 = 500000, y0 = 5200000;
  // Crest lines through the cells' centres (x, y = 205 and 505 m): the dams are the cells 200-210 and
  // 500-510 m; the basin between them is 290 m square.
  make_lines(d / "high.geojson",
             {{{x0 + 205, y0 + 205}, {x0 + 505, y0 + 205}}, {{x0 + 205, y0 + 505}, {x0 + 505, y0 + 505}}, {{x0 + 205, y0 + 205}, {x0 + 205, y0 + 505}}},
             "EPSG:32632");
  make_lines(d / "weir.geojson", {{{x0 + 505, y0 + 205}, {x0 + 505, y0 + 505}}}, "EPSG:32632");
  make_polygons(d / "basin.geojson", {{{x0 + 210, y0 + 210}, {x0 + 500, y0 + 210}, {x0 + 500, y0 + 500}, {x0 + 210, y0 + 500}, {x0 + 210, y0 + 210}}},
                "EPSG:32632");
  v1::Scenario s = base_scenario(d / "dem.tif", d / "basin.geojson", 10);
  s.mutable_releases(0)->set_thickness_m(5);
  s.mutable_material()->clear_bed_friction_deg();
  s.mutable_material()->set_rheology("voellmy");
  s.mutable_material()->set_voellmy_mu(0);
  s.mutable_material()->set_voellmy_xi(400);
  s.mutable_numerics()->set_end_time_s(3000);
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
  const double area = 290.0 * 290.0, excess = (5.0 - 2.0) * area;
  EXPECT_NEAR(rec.mass_balance().volume_initial_m3(), 5.0 * area, 1e-6 * 5 * area);
  ASSERT_EQ(rec.dams_size(), 2);
  const auto& w = rec.dams(1);
  EXPECT_EQ(w.name(), "weir");
  EXPECT_NEAR(w.overflow_m3() / excess, 1.0, 0.05) << w.overflow_m3() << " against " << excess;
  EXPECT_GT(w.crossed_right_m3(), 0.95 * excess);  // the weir's line heads north: its right is east, the outside
  EXPECT_EQ(rec.dams(0).overflow_m3(), 0.0);
  EXPECT_LT(rec.mass_balance().relative_error(), 1e-12);
  // What is left in the basin: a little above the crest.
  const double top = max_between(d / "out/deposit.tif", x0 + 210, x0 + 500);
  std::printf("weir: %.0f m3 over against %.0f (ratio %.4f); basin level %.4f m\n", w.overflow_m3(), excess,
              w.overflow_m3() / excess, top);
  EXPECT_GT(top, 2.0);
  EXPECT_LT(top, 2.1);
}
