// Structures (scenario `structures[]`): buildings, walls and pylons as footprints with a height or a
// top elevation. The depth-averaged engine takes them as walls on every cell their footprints touch
// (a footprint dam); the 3D engine leaves their columns out up to their top, gives them wall patches
// of their own and reports the flow's force on them (run.json, structure_loads.csv).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <vector>

#include "jobs/drivers/run.hpp"
#include "jobs/scenario/scenario.hpp"
#include "tests/support/run_helpers.hpp"
#include "terrain/column_mesh.hpp"
#include "terrain/terrain.hpp"

using namespace runout;
using namespace runout::test_support::run;

namespace {

constexpr double kX0 = 500000, kY0 = 5200000;

// A pile 10 m high collapsing east on flat ground (Coulomb, 2 deg; tests/integration/test_dams.cpp),
// a building 30 x 60 m across its way at x = 350-380 m.
v1::Scenario collapse(const TempDir& d, double building_height) {
  make_dem_of(d / "dem.tif", 60, 10.0, [](int, int) { return 0.0; });
  make_polygons(d / "rel.geojson", {square(kX0 + 100, kY0 + 250, 100)}, "EPSG:32632");
  make_polygons(d / "house.geojson", {{{kX0 + 350, kY0 + 270}, {kX0 + 380, kY0 + 270}, {kX0 + 380, kY0 + 330}, {kX0 + 350, kY0 + 330}, {kX0 + 350, kY0 + 270}}},
                "EPSG:32632", (",\"roof\":" + std::to_string(building_height)).c_str());
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson", 10);
  sc.mutable_releases(0)->set_thickness_m(10);
  sc.mutable_material()->set_bed_friction_deg(2);
  sc.mutable_numerics()->set_end_time_s(300);
  sc.mutable_outputs()->set_maps(false);
  auto* st = sc.add_structures();
  st->set_name("farmhouse");
  st->set_path("house.geojson");
  st->set_height_m(building_height);
  return sc;
}

jobs::RunSummary run_in(const TempDir& d, const v1::Scenario& sc, const std::string& name) {
  fs::create_directories(d / name);
  return jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / name);
}

}  // namespace

// The depth-averaged engine: the building is a wall higher than the flow's run-up; the flow goes
// round it and never onto it, the volume is kept, and run.json reports the flow next to it. A top
// elevation (top_attribute, on flat ground at 0 m) gives the same run as the same height.
TEST(Structures, ABuildingIsAWallTheDepthAveragedFlowGoesRound) {
  TempDir d;
  const auto sc = collapse(d, 20);
  run_in(d, sc, "height");
  const auto rec = run_record(d / "height/run.json");
  ASSERT_EQ(rec.structures_size(), 1);
  const auto& s = rec.structures(0);
  EXPECT_EQ(s.name(), "farmhouse");
  // The cells the footprint covers (3 x 6) and those its outline touches: its east and north edges lie
  // on cell lines, and a piece on a line belongs to the cell above or east of it (6 + 3).
  EXPECT_EQ(s.cells(), 27);
  EXPECT_EQ(s.height_max_m(), 20);
  EXPECT_GT(s.max_depth_next_m(), 0.5);
  EXPECT_GT(s.max_pressure_next_kpa(), 1);
  EXPECT_FALSE(s.has_peak_force_kn());  // loads are the 3D engine's
  EXPECT_LT(rec.mass_balance().relative_error(), 1e-12);
  const auto depth = read_raster_values(d / "height/max_depth.tif");
  EXPECT_EQ(depth.max_where([](double x, double y) { return x > kX0 + 350 && x < kX0 + 380 && y > kY0 + 270 && y < kY0 + 330; }), 0.0);
  EXPECT_GT(depth.max_where([](double x, double y) { return x > kX0 + 400 && (y < kY0 + 260 || y > kY0 + 340); }), 0.1);  // round it
  EXPECT_NE(std::find(rec.parameters().begin(), rec.parameters().end(), "structure: farmhouse, 20 m high"), rec.parameters().end());

  auto top = sc;
  top.mutable_structures(0)->clear_height_m();
  top.mutable_structures(0)->set_top_attribute("roof");
  run_in(d, top, "top");
  const auto again = read_raster_values(d / "top/max_depth.tif").v;
  ASSERT_EQ(again.size(), depth.v.size());
  for (std::size_t k = 0; k < again.size(); ++k)
    if (!(std::isnan(again[k]) && std::isnan(depth.v[k]))) ASSERT_EQ(again[k], depth.v[k]) << k;
}

// Bad structures are refused before the run, naming the field and the file.
TEST(Structures, BadStructuresAreRefusedNamingTheField) {
  TempDir d;
  auto sc = collapse(d, 20);
  auto none = sc;
  none.mutable_structures(0)->clear_height_m();
  expect_error(none, d, "structures[0]: needs height_m, height_attribute or top_attribute");
  auto both = sc;
  both.mutable_structures(0)->set_top_attribute("roof");
  expect_error(both, d, "structures[0]: give one of height_m, height_attribute and top_attribute");
  auto twice = sc;
  *twice.add_structures() = sc.structures(0);
  expect_error(twice, d, "structures[1].name");
  auto below = sc;
  below.mutable_structures(0)->clear_height_m();
  below.mutable_structures(0)->set_top_attribute("id");  // 0 m: at the ground
  expect_error(below, d, "its top (id = 0.00 m) lies 0.00 m above the ground");
  auto missing = sc;
  missing.mutable_structures(0)->set_path("nowhere.geojson");
  expect_error(missing, d, "structures[0].path");
}

// On the 3D engine's columns a structure takes the columns whose centres lie inside its footprint
// (a footprint smaller than a column: the one holding its centroid) up to the layer whose middle
// lies below its top; a structure lower than half the first layer takes nothing and is refused.
TEST(Structures, TheThreeDMeshLeavesTheStructuresColumnsOutUpToTheirTop) {
  TempDir d;
  const terrain::Grid g = flat_grid(10, 10.0, 100.0);
  terrain::ColumnMeshSpec spec{1.0, 1.0, 10.0, 2};  // ten layers of 1 m, 5 m columns
  make_polygons(d / "house.geojson", {{{kX0 + 20, kY0 + 20}, {kX0 + 40, kY0 + 20}, {kX0 + 40, kY0 + 30}, {kX0 + 20, kY0 + 30}, {kX0 + 20, kY0 + 20}}},
                "EPSG:32632");
  make_polygons(d / "pylon.geojson", {square(kX0 + 71, kY0 + 71, 1)}, "EPSG:32632");
  auto m = terrain::column_mesh(g, spec);
  terrain::place_structures(m, g,
                            {{"structures[0]", d / "house.geojson", "", true, 6.4, ""}, {"structures[1]", d / "pylon.geojson", "", true, 20.0, ""}});
  int house = 0, pylon = 0;
  for (std::size_t col = 0; col < m.kept.size(); ++col) {
    if (m.structure[col] == 0) {
      ++house;
      EXPECT_EQ(m.base[col], 6);  // layer middles 0.5 ... 5.5 m lie below 6.4 m
    }
    if (m.structure[col] == 1) {
      ++pylon;
      EXPECT_EQ(col, std::size_t(14) * 20 + 14);  // the 5 m column holding (71.5, 71.5)
      EXPECT_EQ(m.base[col], 10);                 // higher than the band: the whole column
    }
  }
  EXPECT_EQ(house, 4 * 2);
  EXPECT_EQ(pylon, 1);
  auto low = terrain::column_mesh(g, spec);
  try {
    terrain::place_structures(low, g, {{"structures[0]", d / "house.geojson", "", true, 0.4, ""}});
    ADD_FAILURE() << "a structure lower than half the first layer was taken";
  } catch (const terrain::TerrainError& e) {
    EXPECT_NE(std::string(e.what()).find("structures[0]: lower than half the mesh's first layer"), std::string::npos) << e.what();
  }
}

// The 3D engine: the same kind of collapse (a block 10 m high, 60 x 60 m, phi 25 deg, delta 2 deg, on
// 10 m columns, 40 s; about 6 s here) against a building 20 x 40 m and 10 m high. The building's columns are left out; the
// flow's force on it points downstream (east), about symmetric across; the volume is kept; run.json
// and structure_loads.csv report the peak force, the impulse, the highest pressure and the profile in
// front of it, and the flow next to it.
TEST(Structures, TheThreeDEngineReportsTheFlowsLoadOnABuilding) {
  TempDir d;
  make_dem_box(d / "dem.tif", 40, 24, 10.0, kX0, kY0, [](int, int) { return 0.0; });
  make_polygons(d / "rel.geojson", {square(kX0 + 40, kY0 + 90, 60)}, "EPSG:32632");
  make_polygons(d / "house.geojson", {{{kX0 + 200, kY0 + 100}, {kX0 + 220, kY0 + 100}, {kX0 + 220, kY0 + 140}, {kX0 + 200, kY0 + 140}, {kX0 + 200, kY0 + 100}}},
                "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson", 10);
  sc.set_engine("vof");
  sc.mutable_releases(0)->set_thickness_m(10);
  sc.mutable_material()->set_bed_friction_deg(2);
  sc.mutable_material()->set_internal_friction_deg(25);
  sc.mutable_numerics()->set_end_time_s(40);
  sc.mutable_outputs()->set_maps(false);
  sc.mutable_vof()->set_write_interval_s(0);
  auto* st = sc.add_structures();
  st->set_name("farmhouse");
  st->set_path("house.geojson");
  st->set_height_m(10);
  const auto sum = run_in(d, sc, "3d");
  const auto rec = run_record(d / "3d/run.json");
  std::printf("3D: %ld steps to %.1f s in %.1f s\n", sum.steps, sum.t, sum.seconds_run);
  ASSERT_EQ(rec.structures_size(), 1);
  const auto& s = rec.structures(0);
  std::printf("peak %.1f kN at %.2f s (east %.1f, north %.1f, up %.1f), impulse %.1f kN s, p max %.1f kPa at %.2f m, next depth %.2f m\n",
              s.peak_force_kn(), s.peak_force_time_s(), s.peak_force_east_kn(), s.peak_force_north_kn(), s.peak_force_up_kn(),
              s.impulse_kn_s(), s.max_pressure_kpa(), s.max_pressure_height_m(), s.max_depth_next_m());
  EXPECT_GT(s.peak_force_kn(), 0);
  EXPECT_GT(s.peak_force_east_kn(), 0.9 * s.peak_force_kn());
  EXPECT_LT(std::abs(s.peak_force_north_kn()), 0.2 * s.peak_force_kn());
  EXPECT_GT(s.impulse_kn_s(), 0);
  EXPECT_GT(s.max_pressure_kpa(), 0);
  EXPECT_GT(s.wall_area_m2(), 2 * (20 + 40) * 9.0);  // its walls up to the layer below its top, and its roof
  EXPECT_GT(s.front_profile_height_m_size(), 3);
  EXPECT_GT(s.max_depth_next_m(), 0.3);
  EXPECT_LT(rec.mass_balance().relative_error(), 1e-6);
  std::ifstream csv(d / "3d/structure_loads.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "time_s,structure,force_east_kn,force_north_kn,force_up_kn,force_horizontal_kn,max_pressure_kpa");
  int rows = 0;
  while (std::getline(csv, line)) rows += line.find("\"farmhouse\"") != std::string::npos;
  EXPECT_GE(rows, 200);  // every 0.1 s of the 40 s, or every step where the steps are longer
}
