// Structures (scenario `structures[]`): buildings, walls and pylons as footprints with a height or a
// top elevation. The depth-averaged engine takes them as walls on every cell their footprints touch
// (a footprint dam); the 3D engine leaves their columns out up to their top, gives them wall patches
// of their own and reports the flow's force on them (run.json, structure_loads.csv).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <vector>

#include "jobs/drivers/report.hpp"
#include "jobs/drivers/run.hpp"
#include "jobs/drivers/vof_terrain/loads.hpp"
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

// A footprint request of the given height (the scenario's resolution makes these from structures[]).
terrain::DamRequest footprints(const std::string& field, const std::string& path, double height) {
  terrain::DamRequest q;
  q.field = field;
  q.path = path;
  q.has_height = true;
  q.height = height;
  return q;
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
    if (!(std::isnan(again[k]) && std::isnan(depth.v[k]))) {
      ASSERT_EQ(again[k], depth.v[k]) << k;
    }
}

// Bad structures are refused before the run, naming the field and the file.
TEST(Structures, BadStructuresAreRefusedNamingTheField) {
  TempDir d;
  auto sc = collapse(d, 20);
  auto none = sc;
  none.mutable_structures(0)->clear_height_m();
  expect_error(none, d, "structures[0]: needs height_m, height_attribute, top_attribute or surface_path");
  auto both = sc;
  both.mutable_structures(0)->set_top_attribute("roof");
  expect_error(both, d, "structures[0]: give one of height_m, height_attribute, top_attribute and surface_path");
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
  terrain::place_structures(m, g, {footprints("structures[0]", d / "house.geojson", 6.4), footprints("structures[1]", d / "pylon.geojson", 20.0)});
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
  // The same house from a surface model on 2.5 m cells (the ground at 100 m): the same columns and layers.
  make_dem_box(d / "dsm.tif", 40, 40, 2.5, kX0, kY0, [](int i, int r) {
    const double x = (i + 0.5) * 2.5, y = (40 - r - 0.5) * 2.5;
    return x > 20 && x < 40 && y > 20 && y < 30 ? 106.4 : 100.0;
  });
  auto from_surface = terrain::column_mesh(g, spec);
  terrain::DamRequest dsm;
  dsm.field = "structures[0]";
  dsm.surface_path = d / "dsm.tif";
  terrain::place_structures(from_surface, g, {dsm});
  EXPECT_EQ(from_surface.base, [&] {
    auto b = m.base;
    for (std::size_t col = 0; col < b.size(); ++col)
      if (m.structure[col] != 0) b[col] = 0;  // the house alone
    return b;
  }());
  auto low = terrain::column_mesh(g, spec);
  try {
    terrain::place_structures(low, g, {footprints("structures[0]", d / "house.geojson", 0.4)});
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
  EXPECT_NEAR(s.x(), kX0 + 210, 5.01);  // the centroid of its grid cells
  EXPECT_NEAR(s.y(), kY0 + 120, 5.01);
  // Columns of several metres for a flow of about a metre: the loads are reported, and said to be
  // no design values.
  ASSERT_TRUE(s.has_loads_resolved());
  EXPECT_FALSE(s.loads_resolved());
  EXPECT_GT(s.column_width_m(), 1.0);
  EXPECT_NE(s.loads_note().find("not design values"), std::string::npos) << s.loads_note();
  // The report's table of structures says so too.
  const auto tables = jobs::report_tables(rec);
  ASSERT_EQ(tables.size(), 3u);
  ASSERT_EQ(tables[2].rows.size(), 1u);
  EXPECT_EQ(tables[2].rows[0].front(), "farmhouse");
  EXPECT_EQ(tables[2].rows[0].back(), "not design values (under-resolved)");
  EXPECT_LT(rec.mass_balance().relative_error(), 1e-6);
  std::ifstream csv(d / "3d/structure_loads.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "time_s,structure,force_east_kn,force_north_kn,force_up_kn,force_horizontal_kn,max_pressure_kpa");
  int rows = 0;
  while (std::getline(csv, line)) rows += line.find("\"farmhouse\"") != std::string::npos;
  EXPECT_GE(rows, 200);  // every 0.1 s of the 40 s, or every step where the steps are longer
}

// A structure from a surface model (DSM): its cells are where the surface stands min_height_m above
// the ground (the cell centre's sample), its height the surface less the ground. Alone, or inside
// footprints, the same building gives the same run; bad surfaces are refused naming the field.
TEST(Structures, ASurfaceModelGivesTheBuildingsCellsAndHeights) {
  TempDir d;
  auto sc = collapse(d, 20);
  // The surface: the building's 3 x 6 cells 20 m high (a 1.5 m fence east of it stays below min_height_m).
  make_dem_of(d / "dsm.tif", 60, 10.0, [](int i, int r) {
    const double x = (i + 0.5) * 10, y = (60 - r - 0.5) * 10;  // the raster's rows run north to south
    if (x > 350 && x < 380 && y > 270 && y < 330) return 20.0;
    return x > 400 && x < 410 ? 1.5 : 0.0;
  });
  auto alone = sc;
  alone.mutable_structures(0)->clear_height_m();
  alone.mutable_structures(0)->clear_path();
  alone.mutable_structures(0)->set_surface_path("dsm.tif");
  run_in(d, alone, "alone");
  const auto rec = run_record(d / "alone/run.json");
  ASSERT_EQ(rec.structures_size(), 1);
  EXPECT_EQ(rec.structures(0).cells(), 18);
  EXPECT_EQ(rec.structures(0).height_max_m(), 20);
  EXPECT_NEAR(rec.structures(0).x(), kX0 + 365, 1e-6);
  EXPECT_NEAR(rec.structures(0).y(), kY0 + 300, 1e-6);
  const auto depth = read_raster_values(d / "alone/max_depth.tif");
  EXPECT_EQ(depth.max_where([](double x, double y) { return x > kX0 + 350 && x < kX0 + 380 && y > kY0 + 270 && y < kY0 + 330; }), 0.0);
  EXPECT_GT(depth.max_where([](double x, double y) { return x > kX0 + 400 && (y < kY0 + 260 || y > kY0 + 340); }), 0.1);

  auto inside = sc;  // the footprints touch 27 cells; the surface stands on 18 of them
  inside.mutable_structures(0)->clear_height_m();
  inside.mutable_structures(0)->set_surface_path("dsm.tif");
  run_in(d, inside, "inside");
  EXPECT_EQ(run_record(d / "inside/run.json").structures(0).cells(), 18);
  const auto again = read_raster_values(d / "inside/max_depth.tif").v;
  ASSERT_EQ(again.size(), depth.v.size());
  for (std::size_t k = 0; k < again.size(); ++k)
    if (!(std::isnan(again[k]) && std::isnan(depth.v[k]))) {
      ASSERT_EQ(again[k], depth.v[k]) << k;
    }

  auto low = alone;  // the fence counts when min_height_m is below its 1.5 m
  low.mutable_structures(0)->set_min_height_m(1);
  const auto r = jobs::resolve_scenario(low, d.p.string());
  EXPECT_EQ(terrain::rasterize_dam(terrain::grid_of_raster(d / "dem.tif", "test"), r.structures[0].request).cells, 18 + 60);

  auto expect_error = [&](const v1::Scenario& bad, const std::string& what) {
    try {
      run_in(d, bad, "bad");
      ADD_FAILURE() << "accepted: " << what;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  auto high = alone;
  high.mutable_structures(0)->set_min_height_m(50);
  expect_error(high, "structures[0].surface_path '" + (d / "dsm.tif") + "': stands nowhere in the domain 50.00 m or more above the ground");
  auto both = inside;
  both.mutable_structures(0)->set_height_m(8);
  expect_error(both, "structures[0]: give one of height_m, height_attribute, top_attribute and surface_path, not several");
  auto min_only = sc;
  min_only.mutable_structures(0)->set_min_height_m(1);
  expect_error(min_only, "structures[0].min_height_m: only with surface_path");
  auto none = alone;
  none.mutable_structures(0)->clear_surface_path();
  expect_error(none, "structures[0].path");
  auto missing = alone;
  missing.mutable_structures(0)->set_surface_path("no-such.tif");
  expect_error(missing, "structures[0].surface_path");
}

// The loads' verdict: columns at most a quarter of the flow's depth next to the structure resolve the
// impact (the wall-impact verification's resolution); wider ones do not, and the note says why, with
// the figures, and that the loads are no design values.
TEST(Structures, LoadsAreDesignValuesOnlyOnColumnsAQuarterOfTheFlowDepth) {
  jobs::StructureSummary q;
  q.max_depth_next_m = 0.34;
  jobs::vof_terrain::loads_verdict(5.0, q);
  EXPECT_FALSE(q.loads_resolved);
  EXPECT_DOUBLE_EQ(q.column_width_m, 5.0);
  EXPECT_NE(q.loads_note.find("not design values: columns 5 m wide for a flow 0.34 m deep"), std::string::npos) << q.loads_note;
  EXPECT_NE(q.loads_note.find("at most a quarter of the depth, 0.085 m"), std::string::npos) << q.loads_note;
  jobs::vof_terrain::loads_verdict(0.085, q);
  EXPECT_TRUE(q.loads_resolved);
  EXPECT_EQ(q.loads_note.find("not design values"), std::string::npos) << q.loads_note;
  q.max_depth_next_m = 0;  // no flow next to it: nothing resolved
  jobs::vof_terrain::loads_verdict(0.01, q);
  EXPECT_FALSE(q.loads_resolved);
}
