// The VOF laboratory set-ups' options through the run driver: each is validated by name and reaches
// the run; scenario errors name the field; the comparison figure.
#include <algorithm>

#include "engine/vof/bc/conditions.hpp"
#include "engine/vof/solver.hpp"
#include "jobs/drivers/vof_lab/config.hpp"
#include "jobs/drivers/vof_lab/setup.hpp"
#include "jobs/scenario/options.hpp"
#include "tests/support/run_helpers.hpp"

using namespace runout::test_support::run;

// lab.coulomb_pressure: "excess" takes the Coulomb viscosity's pressure less the still air's
// hydrostatic pressure, so that the air a domain holds above the material adds no strength. B2 at
// 5 mm with the whole top open, once 15 cm and once 30 cm high: with "excess" the collapse is the
// same (within half a cell, 2 % of the rest time, 0.05 deg). With the full pressure (the default)
// the taller domain's extra 1.5 Pa of air change it: run to 1 s, the rest time moves from 0.88 to
// 0.52 s and the front by four cells (docs/design/vof.md), which the checks below would catch. (The peak
// speed, in the thin surface layer, differs by less than 1 % either way.)
TEST(Scenarios, LabCoulombExcessPressureDoesNotDependOnTheAirAbove) {
  struct Fig {
    double peak, rest, angle, front;
  };
  auto run = [](double y_max, const char* pressure) {
    auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab/b2-collapse-0deg.json");
    auto* lab = r.scenario.mutable_lab();
    lab->set_nx(100);
    lab->set_y_max(y_max);
    lab->set_ny(int(std::lround(y_max / 0.005)));
    lab->set_write_interval_s(0);
    lab->set_end_time_s(0.8);
    for (auto& b : *lab->mutable_boundaries())
      if (b.side() == "top") b.clear_from();  // open over the container too: only air lies above
    lab->set_coulomb_pressure(pressure);
    r = jobs::resolve_scenario(r.scenario, std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab");
    TempDir d;
    const auto sum = jobs::run_scenario(r, d.p.string());
    EXPECT_EQ(sum.stop, "end-time");
    const auto j = run_record(d / "run.json");
    const Fig f{record_figure(j, "peak_speed_m_s"), record_figure(j, "rest_time_s"), record_figure(j, "upper_surface_angle_deg"),
                record_figure(j, "front_x_m")};
    std::printf("B2 at 5 mm, %s pressure, domain %.2f m high: peak %.4f m/s, rest %.3f s, surface %.2f deg, front %.4f m\n",
                pressure, y_max, f.peak, f.rest, f.angle, f.front);
    return f;
  };
  const Fig low = run(0.15, "excess"), high = run(0.30, "excess");
  EXPECT_NEAR(high.peak, low.peak, 0.02 * low.peak);
  EXPECT_NEAR(high.rest, low.rest, 0.02 * low.rest);
  EXPECT_NEAR(high.angle, low.angle, 0.05);
  EXPECT_NEAR(high.front, low.front, 0.5 * 0.005);
  EXPECT_GT(low.rest, 0);  // came to rest
}

// A lab option whose default stays unset (jobs/scenario.cpp, unset_default), so that older scenarios
// keep their hash: left out it reads "", the default spelled out resolves to the same hash, the
// other value is kept and changes the hash, an unknown one is named with the option in the error.
void expect_unset_default_option(const std::string& option, const std::string& dflt, const std::string& other,
                                 const std::string& unknown, const std::function<std::string(const v1::Lab&)>& get) {
  const std::string head = R"({"engine": "vof", "lab": {"x_max": 1, "y_max": 1, "nx": 10, "ny": 10,
      "fill": [{"x_max": 0.5, "y_max": 0.5}])";
  auto with = [&](const std::string& v) { return jobs::parse_scenario_json(head + ", \"" + option + "\": \"" + v + "\"}}"); };
  const auto plain = jobs::resolve_scenario(jobs::parse_scenario_json(head + "}}"), ".");
  EXPECT_EQ(get(plain.scenario.lab()), "") << option;
  EXPECT_EQ(jobs::scenario_hash(jobs::resolve_scenario(with(dflt), ".")), jobs::scenario_hash(plain)) << option;
  const auto changed = jobs::resolve_scenario(with(other), ".");
  EXPECT_EQ(get(changed.scenario.lab()), other) << option;
  EXPECT_NE(jobs::scenario_hash(changed), jobs::scenario_hash(plain)) << option;
  expect_resolve_error(with(unknown), {"lab." + option, unknown});
}

// lab.coulomb_pressure: "total" by default (left unset, so that older scenarios keep their hash),
// "excess" accepted, anything else named in the error.
TEST(Scenarios, LabCoulombPressureIsValidated) {
  expect_unset_default_option("coulomb_pressure", "total", "excess", "effective", [](const v1::Lab& l) { return l.coulomb_pressure(); });
}

// lab.wall_viscosity: "face" by default (left unset; results version 5 tells its results from the
// cell's), "cell" accepted and reaching the run (B2's front, docs/validation/validation.md B2: the walls with
// the cell's viscosity hold the sliding toe back), anything else named in the error.
TEST(Scenarios, LabWallViscosityIsValidatedAndReachesTheRun) {
  expect_unset_default_option("wall_viscosity", "face", "cell", "wall", [](const v1::Lab& l) { return l.wall_viscosity(); });
  // B2 on 5 mm cells to 0.6 s: the front runs further with the face's viscosity on the bed.
  double front[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab/b2-collapse-0deg.json");
    auto* lab = r.scenario.mutable_lab();
    lab->set_nx(100);
    lab->set_ny(30);
    lab->set_end_time_s(0.6);
    lab->set_write_interval_s(0);
    if (k == 1) {
      lab->set_wall_viscosity("cell");
      r = jobs::resolve_scenario(r.scenario, std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab");
    }
    TempDir d;
    ASSERT_EQ(jobs::run_scenario(r, d.p.string()).stop, "end-time");
    front[k] = record_figure(d / "run.json", "front_x_m");
  }
  std::printf("B2 at 5 mm, 0.6 s: front %.4f m (face viscosity on the walls), %.4f m (the cell's)\n", front[0], front[1]);
  EXPECT_GE(front[0], front[1] + 0.005);  // at least a cell further
}

// lab.outer_correctors: 1 by default (left unset, so that older scenarios keep their hash), 1-20
// accepted, anything else named in the error; it reaches the run: on coarse B2 under the consistent
// coupling, three outer correctors take more than one and a half times the pressure iterations of one
// per step.
TEST(Scenarios, LabOuterCorrectorsAreValidatedAndReachTheRun) {
  const std::string head = R"({"engine": "vof", "lab": {"x_max": 1, "y_max": 1, "nx": 10, "ny": 10,
      "fill": [{"x_max": 0.5, "y_max": 0.5}])";
  auto with = [&](int n) { return jobs::parse_scenario_json(head + ", \"outer_correctors\": " + std::to_string(n) + "}}"); };
  const auto plain = jobs::resolve_scenario(jobs::parse_scenario_json(head + "}}"), ".");
  EXPECT_FALSE(plain.scenario.lab().has_outer_correctors());
  EXPECT_EQ(jobs::scenario_hash(jobs::resolve_scenario(with(1), ".")), jobs::scenario_hash(plain));
  const auto three = jobs::resolve_scenario(with(3), ".");
  EXPECT_EQ(three.scenario.lab().outer_correctors(), 3);
  EXPECT_NE(jobs::scenario_hash(three), jobs::scenario_hash(plain));
  expect_resolve_error(with(0), {"lab.outer_correctors", "1..20"});
  expect_resolve_error(with(21), {"lab.outer_correctors", "1..20"});
  double its[2] = {0, 0}, steps[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    auto r = coarse_b2(0.2);
    auto* lab = r.scenario.mutable_lab();
    lab->set_write_interval_s(0);
    lab->set_pressure_coupling("consistent");
    if (k == 1) lab->set_outer_correctors(3);
    r = jobs::resolve_scenario(r.scenario, std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab");
    TempDir d;
    ASSERT_EQ(jobs::run_scenario(r, d.p.string()).stop, "end-time");
    const auto j = run_record(d / "run.json");
    its[k] = record_figure(j, "pressure_iterations");
    steps[k] = record_figure(j, "steps");
  }
  std::printf("coarse B2 to 0.2 s, consistent: %.0f pressure iterations in %.0f steps (1 outer corrector), %.0f in %.0f (3)\n", its[0], steps[0],
              its[1], steps[1]);
  EXPECT_GT(its[1] / steps[1], 1.5 * its[0] / steps[0]);  // measured 2.2 (later solves start nearer their answer)
}

// lab.pressure_preconditioner: "gamg" by default (left unset), "hypre" (BoomerAMG) gives the same
// collapse (the last corrector's solve to the same tolerance), anything else is named in the error.
TEST(Scenarios, LabPressurePreconditionerIsChosenByName) {
  expect_unset_default_option("pressure_preconditioner", "gamg", "hypre", "sor",
                              [](const v1::Lab& l) { return l.pressure_preconditioner(); });
  double peak[2] = {0, 0}, angle[2] = {0, 0}, iterations[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    auto r = coarse_b2(0.3);
    auto* lab = r.scenario.mutable_lab();
    lab->set_write_interval_s(0);
    if (k == 1) lab->set_pressure_preconditioner("hypre");
    r = jobs::resolve_scenario(r.scenario, std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab");
    TempDir d;
    try {
      ASSERT_EQ(jobs::run_scenario(r, d.p.string()).stop, "end-time");
    } catch (const std::exception& e) {
      if (k == 1 && std::string(e.what()).find("no hypre") != std::string::npos) GTEST_SKIP() << e.what();
      throw;
    }
    const auto j = run_record(d / "run.json");
    peak[k] = record_figure(j, "peak_speed_m_s");
    angle[k] = record_figure(j, "mean_surface_angle_deg");
    iterations[k] = record_figure(j, "pressure_iterations");
  }
  EXPECT_NE(iterations[1], iterations[0]) << "the same CG iterations: was hypre taken at all?";
  // The correctors before the last solve to a relative 0.1 only, so the two preconditioners' runs
  // part at that level: 0.4 % in the peak speed.
  std::printf("peak speed %.6f / %.6f m/s, mean surface %.3f / %.3f deg, %.0f / %.0f CG iterations (gamg / hypre)\n", peak[0], peak[1],
              angle[0], angle[1], iterations[0], iterations[1]);
  EXPECT_NEAR(peak[1], peak[0], 0.02 * peak[0]);
  EXPECT_NEAR(angle[1], angle[0], 0.5);
}

TEST(Scenarios, LabScenarioErrorsNameTheField) {
  // Without `lab`, engine "vof" is the 3D engine on a DEM: it needs one.
  auto s = jobs::parse_scenario_json(R"({"engine": "vof"})");
  try {
    jobs::resolve_scenario(s, ".");
    FAIL();
  } catch (const jobs::ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("dem.path: missing"), std::string::npos) << e.what();
  }
  s = jobs::parse_scenario_json(R"({"engine": "vof", "mesh": {"growth": 1.1}, "lab": {"x_max": 1, "y_max": 1, "nx": 10, "ny": 10,
      "fill": [{"x_max": 0.5, "y_max": 0.5}]}})");
  try {
    jobs::resolve_scenario(s, ".");
    FAIL();
  } catch (const jobs::ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh: not used by a laboratory set-up"), std::string::npos) << e.what();
  }
  s = jobs::parse_scenario_json(R"({"engine": "vof", "lab": {"x_max": 1, "y_max": 1, "nx": 10, "ny": 10,
      "fill": [{"x_max": 0.5, "y_max": 0.5}], "boundaries": [{"side": "front", "kind": "wall"}]}})");
  try {
    jobs::resolve_scenario(s, ".");
    FAIL();
  } catch (const jobs::ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("lab.boundaries[0].side"), std::string::npos) << e.what();
  }
}

// A polygon fill (B3's triangle at 50 deg): the initial volume is the triangle's, to the cell size.
TEST(Scenarios, LabPolygonFillHoldsTheTriangle) {
  auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab/b3-triangle-pvc.json");
  auto* lab = r.scenario.mutable_lab();
  lab->set_nx(80);  // 1 cm cells
  lab->set_ny(19);
  lab->set_end_time_s(0.05);
  TempDir d;
  const auto sum = jobs::run_scenario(r, d.p.string());
  const double h = 0.4 * std::tan(18.0 * 3.14159265358979 / 180), area = 0.5 * 0.4 * h, thickness = 0.01;
  EXPECT_NEAR(sum.volume_initial, area * thickness, 0.1 * area * thickness);
  EXPECT_GT(sum.max_speed, 0.05);  // steeper than phi on a 50 deg chute: it moves at once
  auto bad = jobs::parse_scenario_json(R"({"engine": "vof", "lab": {"x_max": 1, "y_max": 1, "nx": 10, "ny": 10,
      "fill": [{"polygon_xy": [0, 0, 1, 0, 1]}]}})");
  expect_resolve_error(bad, {"lab.fill[0].polygon_xy"});
}

// A curved chute's errors name the field: a 2D set-up, a mesh reaching the bend's centre of
// curvature, a cap higher than its sphere, the column's weight as the bed's load (its bend's
// centripetal load is not in the laboratory's columns).
TEST(Scenarios, LabChuteErrorsNameTheField) {
  const std::string base = std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab/b8-curved-chute.json";
  auto expect = [&](const std::function<void(runout::v1::Lab*)>& edit, const std::string& field) {
    auto r = jobs::load_scenario(base);
    edit(r.scenario.mutable_lab());
    try {
      jobs::resolve_scenario(r.scenario, ".");
      ADD_FAILURE() << "accepted: " << field;
    } catch (const jobs::ScenarioError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  expect([](runout::v1::Lab* l) { l->set_nz(0); }, "lab.chute");
  expect([](runout::v1::Lab* l) { l->set_y_max(0.6); }, "lab.y_max");
  expect([](runout::v1::Lab* l) { l->mutable_fill(0)->set_cap_height(0.5); }, "lab.fill[0].cap_height");
  expect([](runout::v1::Lab* l) { l->mutable_chute()->set_bend_end_m(1.0); }, "lab.chute.bend_end_m");
  expect([](runout::v1::Lab* l) { l->set_phi_deg(85); }, "lab.phi_deg");
  expect([](runout::v1::Lab* l) { l->set_bed_normal_stress("column"); }, "lab.bed_normal_stress");
}

// comparison.png (validation.md part B): a plane run draws its section and monitors, a 3D run its
// plan view, and the reference values of lab.reference in orange; without a reference nothing
// orange is drawn; a reference front that is no range and a negative depth ratio are refused by
// name.
TEST(Scenarios, LabComparisonFigureDrawsTheReference) {
  auto r = coarse_b2(0.1);
  ASSERT_TRUE(r.scenario.lab().has_reference());
  auto* lab = r.scenario.mutable_lab();
  lab->set_write_interval_s(0);
  auto orange_pixels = [](const std::string& png, int x_from = 0) {
    GDALDatasetUniquePtr ds(GDALDataset::Open(png.c_str(), GDAL_OF_RASTER));
    if (!ds || ds->GetRasterCount() < 3) return -1L;
    const int w = ds->GetRasterXSize(), h = ds->GetRasterYSize();
    std::vector<unsigned char> band[3];
    for (int b = 0; b < 3; ++b) {
      band[b].resize(std::size_t(w) * h);
      if (ds->GetRasterBand(b + 1)->RasterIO(GF_Read, 0, 0, w, h, band[b].data(), w, h, GDT_Byte, 0, 0) != CE_None) return -1L;
    }
    long n = 0;
    // The reference colour (217, 89, 0); the speed scale never has zero blue with that much green.
    for (std::size_t k = 0; k < band[0].size(); ++k)
      n += int(k % std::size_t(w)) >= x_from && band[0][k] > 205 && band[0][k] < 230 && band[1][k] > 80 && band[1][k] < 100 && band[2][k] == 0;
    return n;
  };
  TempDir with, without;
  const auto s1 = jobs::run_scenario(r, with.p.string());
  EXPECT_NE(std::find(s1.files.begin(), s1.files.end(), "comparison.png"), s1.files.end());
  EXPECT_GT(orange_pixels(with / "comparison.png"), 50);  // the reference text and the dashed slope
  lab->clear_reference();
  jobs::run_scenario(r, without.p.string());
  EXPECT_EQ(orange_pixels(without / "comparison.png"), 0);
  auto bad = jobs::parse_scenario_json(R"({"engine": "vof", "lab": {"x_max": 1, "y_max": 1, "nx": 10, "ny": 10,
      "fill": [{"x_max": 0.5, "y_max": 0.5}], "reference": {"front_x_min": 0.3, "front_x_max": 0.2}}})");
  expect_resolve_error(bad, {"lab.reference.front_x_max"});
  // A 3D run draws its plan view (flow depth, arrows, the deepest column, the obstacle's shadow)
  // with the reference depth ratio in orange (B7's files: "up to four times", described).
  auto r3 = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab/b7-wide-chute-cylinder.json");
  ASSERT_TRUE(r3.scenario.lab().reference().has_depth_ratio_max());
  auto* l3 = r3.scenario.mutable_lab();
  l3->set_nx(47);
  l3->set_ny(10);
  l3->set_nz(24);
  l3->set_end_time_s(0.1);
  l3->set_write_interval_s(0);
  TempDir with3, without3;
  const auto s3 = jobs::run_scenario(r3, with3.p.string());
  EXPECT_NE(std::find(s3.files.begin(), s3.files.end(), "comparison.png"), s3.files.end());
  EXPECT_GT(orange_pixels(with3 / "comparison.png"), 50);
  {
    // The mark on the colour bar, right of the map (the text lines lie below it, on the left).
    GDALDatasetUniquePtr ds(GDALDataset::Open((with3 / "comparison.png").c_str(), GDAL_OF_RASTER));
    ASSERT_TRUE(ds);
    EXPECT_GT(orange_pixels(with3 / "comparison.png", ds->GetRasterXSize() - 110), 10);
  }
  l3->clear_reference();
  jobs::run_scenario(r3, without3.p.string());
  EXPECT_EQ(orange_pixels(without3 / "comparison.png"), 0);
  auto bad3 = jobs::parse_scenario_json(R"({"engine": "vof", "lab": {"x_max": 1, "y_max": 1, "nx": 10, "ny": 10,
      "fill": [{"x_max": 0.5, "y_max": 0.5}], "reference": {"depth_ratio_max": -4}}})");
  expect_resolve_error(bad3, {"lab.reference.depth_ratio_max"});
}

// lab.momentum_convection: "upwind" by default, "limited_linear" accepted and passed to the
// engine (it changes the run), anything else named in the error.
TEST(Scenarios, LabMomentumConvectionIsValidatedAndChangesTheRun) {
  const std::string head = R"({"engine": "vof", "lab": {"x_min": -0.1, "x_max": 0.1, "y_max": 0.06, "nx": 20, "ny": 6,
      "fill": [{"x_min": -0.1, "x_max": 0, "y_max": 0.05}], "boundaries": [{"side": "top", "kind": "atmosphere"},
      {"side": "right", "kind": "atmosphere"}], "end_time_s": 0.15, "write_interval_s": 0)";
  const auto plain = jobs::resolve_scenario(jobs::parse_scenario_json(head + "}}"), ".");
  EXPECT_EQ(plain.scenario.lab().momentum_convection(), "");  // upwind, unset: the scenario's hash is unchanged
  const auto up = jobs::resolve_scenario(jobs::parse_scenario_json(head + R"(, "momentum_convection": "upwind"}})"), ".");
  EXPECT_EQ(up.scenario.SerializeAsString(), plain.scenario.SerializeAsString());
  const auto ll = jobs::resolve_scenario(jobs::parse_scenario_json(head + R"(, "momentum_convection": "limited_linear"}})"), ".");
  EXPECT_EQ(ll.scenario.lab().momentum_convection(), "limited_linear");
  const TempDir d1, d2;
  const auto a = jobs::run_scenario(plain, d1.p.string()), b = jobs::run_scenario(ll, d2.p.string());
  const double fa = record_figure((d1.p / "run.json").string(), "front_x_m"),
               fb = record_figure((d2.p / "run.json").string(), "front_x_m");
  std::printf("collapse to 0.15 s on 1 cm cells: front %.3f m (upwind), %.3f m (limited linear); %ld and %ld steps\n", fa, fb, a.steps, b.steps);
  EXPECT_GE(fb, fa);  // less numerical viscosity: the front runs at least as far
  EXPECT_NE(a.steps, b.steps);  // the option reaches the engine
  EXPECT_NE(a.max_speed, b.max_speed);
  auto bad = jobs::parse_scenario_json(head + R"(, "momentum_convection": "central"}})");
  expect_resolve_error(bad, {"lab.momentum_convection", "central"});
}

// lab.viscous_transpose: "harmonic" by default, "explicit" and "off" accepted, anything else named
// in the error.
TEST(Scenarios, LabViscousTransposeIsValidated) {
  const std::string head = R"({"engine": "vof", "lab": {"x_max": 1, "y_max": 1, "nx": 10, "ny": 10,
      "fill": [{"x_max": 0.5, "y_max": 0.5}])";
  const auto plain = jobs::resolve_scenario(jobs::parse_scenario_json(head + "}}"), ".");
  EXPECT_EQ(plain.scenario.lab().viscous_transpose(), "harmonic");
  const auto off = jobs::resolve_scenario(jobs::parse_scenario_json(head + R"(, "viscous_transpose": "off"}})"), ".");
  EXPECT_EQ(off.scenario.lab().viscous_transpose(), "off");
  const auto lin = jobs::resolve_scenario(jobs::parse_scenario_json(head + R"(, "viscous_transpose": "explicit"}})"), ".");
  EXPECT_EQ(lin.scenario.lab().viscous_transpose(), "explicit");
  auto bad = jobs::parse_scenario_json(head + R"(, "viscous_transpose": "implicit"}})");
  expect_resolve_error(bad, {"lab.viscous_transpose", "implicit"});
}

// The lab block's boundary kinds are the engine's boundary-condition registry (scenarios spell '_'
// as '-') but for the conditions another model feeds at run time (a nest's boundary), and each choice of the engine's options reaches a VofConfig: no list of names besides
// the engine's.
TEST(LabOptions, BoundaryKindsAreTheEngineRegistrys) {
  std::vector<std::string> scenario_kinds = jobs::option(jobs::lab_options(), "lab.boundaries[].kind").choices;
  for (auto& k : scenario_kinds) std::replace(k.begin(), k.end(), '-', '_');
  std::vector<std::string> engine_kinds;
  for (const auto* r : runout::engine::vof::boundary_conditions())
    if (!r->coupled) engine_kinds.emplace_back(r->name);
  EXPECT_NE(runout::engine::vof::find_boundary_condition("nest_inflow"), nullptr);
  std::sort(scenario_kinds.begin(), scenario_kinds.end());
  std::sort(engine_kinds.begin(), engine_kinds.end());
  EXPECT_EQ(scenario_kinds, engine_kinds);
  for (const auto& name : jobs::option(jobs::lab_options(), "lab.viscous_transpose").choices) {
    runout::v1::Lab lab;
    lab.set_viscous_transpose(name);
    EXPECT_EQ(runout::engine::name_of(runout::engine::vof::kTransposeNames,
                                      jobs::vof_lab::lab_config(lab, jobs::vof_lab::lab_material(lab)).viscous_transpose),
              name);
  }
}

// lab.rheology: "coulomb" by default (left unset), "mu_i" accepted and reaching the run (coarse B2:
// PVC's mu(I), whose friction rises above its Coulomb phi where it shears, stops at another front);
// the mu(I) parameters default to the material's and are checked between each other and against
// the material, each error naming the field.
TEST(Scenarios, LabRheologyIsValidatedAndReachesTheRun) {
  expect_unset_default_option("rheology", "coulomb", "mu_i", "bingham", [](const v1::Lab& l) { return l.rheology(); });
  const std::string head = R"({"engine": "vof", "lab": {"x_max": 1, "y_max": 1, "nx": 10, "ny": 10,
      "fill": [{"x_max": 0.5, "y_max": 0.5}], "rheology": "mu_i")";
  auto with = [&](const std::string& more) { return jobs::parse_scenario_json(head + more + "}}"); };
  EXPECT_NO_THROW(jobs::resolve_scenario(with(R"(, "mu_s": 0.5, "mu_2": 0.9, "mu_i0": 0.3, "grain_diameter_m": 0.001)"), "."));
  expect_resolve_error(with(R"(, "mu_s": 0.6, "mu_2": 0.5)"), {"lab.mu_2", "at least mu_s"});
  expect_resolve_error(with(R"(, "grain_density_kg_m3": 500)"), {"lab.grain_density_kg_m3", "material's density"});
  expect_resolve_error(with(R"(, "mu_s": 0.381863, "mu_2": 0.382)"), {"lab.mu_2", "too small"});
  for (const auto& m : jobs::lab_materials()) {  // the defaults: the material's (options.hpp LabMaterial)
    runout::engine::vof::VofConfig c;
    auto r = jobs::resolve_scenario(with(R"(, "material": ")" + m.name + "\""), ".");
    jobs::apply_lab_rheology(r.scenario.lab(), c);
    EXPECT_NEAR(c.mu_i.mu_s, std::tan(m.repose_deg * M_PI / 180), 1e-12) << m.name;
    EXPECT_NEAR(c.mu_i.mu_2, std::tan((m.repose_deg + 11.86) * M_PI / 180), 1e-12) << m.name;
    EXPECT_EQ(c.mu_i.grain_diameter, m.grain_diameter) << m.name;
    EXPECT_EQ(c.mu_i.grain_density, m.grain_density) << m.name;
    EXPECT_EQ(c.mu_i.i0, 0.279) << m.name;
  }
  expect_resolve_error(with(R"(, "grain_diameter_m": 0)"), {"lab.grain_diameter_m"});
  double front[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    auto r = coarse_b2(0.4);
    r.scenario.mutable_lab()->set_write_interval_s(0);
    if (k == 1) r.scenario.mutable_lab()->set_rheology("mu_i");
    r = jobs::resolve_scenario(r.scenario, std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab");
    TempDir d;
    ASSERT_EQ(jobs::run_scenario(r, d.p.string()).stop, "end-time");
    front[k] = record_figure(d / "run.json", "front_x_m");
  }
  std::printf("coarse B2 to 0.4 s: front %.4f m (coulomb), %.4f m (mu_i, PVC)\n", front[0], front[1]);
  EXPECT_GT(std::abs(front[1] - front[0]), 0.005);  // at least half a cell apart
}

// lab.side_wall_width_m and lab.side_wall_friction_deg: both or neither, plane set-ups only; they
// reach the engine's configuration (their effect: VofSolver.SideWallFrictionSlowsAPlugByItsDepthOverTheWidth).
TEST(Scenarios, LabSideWallsAreValidatedAndReachTheConfiguration) {
  const std::string head = R"({"engine": "vof", "lab": {"x_max": 1, "y_max": 1, "nx": 10, "ny": 10,
      "fill": [{"x_max": 0.5, "y_max": 0.5}])";
  auto with = [&](const std::string& more) { return jobs::parse_scenario_json(head + more + "}}"); };
  const auto r = jobs::resolve_scenario(with(R"(, "side_wall_width_m": 0.005, "side_wall_friction_deg": 18)"), ".");
  runout::engine::vof::VofConfig c;
  jobs::apply_lab_rheology(r.scenario.lab(), c);
  EXPECT_EQ(c.side_walls.width, 0.005);
  EXPECT_NEAR(c.side_walls.tan_delta, std::tan(18 * M_PI / 180), 1e-15);
  expect_resolve_error(with(R"(, "side_wall_width_m": 0.005)"), {"lab.side_wall_friction_deg", "both"});
  expect_resolve_error(with(R"(, "side_wall_friction_deg": 18)"), {"lab.side_wall_width_m", "both"});
  expect_resolve_error(with(R"(, "side_wall_width_m": 0, "side_wall_friction_deg": 18)"), {"lab.side_wall_width_m"});
  expect_resolve_error(with(R"(, "nz": 2, "z_max": 0.1, "side_wall_width_m": 0.1, "side_wall_friction_deg": 18)"),
                       {"lab.side_wall_width_m", "plane set-ups"});
}

// lab.bed_normal_stress: "pressure" by default (left unset, older scenarios keep their hash),
// "column" takes the friction of the bottom's coulomb-friction parts on the weight of the material
// above each of their faces (those parts then free of shear); other coulomb-friction sides keep the
// face's pressure; a set-up without a coulomb-friction part of the bottom is refused.
TEST(Scenarios, LabBedNormalStressIsValidatedAndReachesTheConfiguration) {
  expect_unset_default_option("bed_normal_stress", "pressure", "column", "weight", [](const v1::Lab& l) { return l.bed_normal_stress(); });
  const std::string head = R"({"engine": "vof", "lab": {"x_max": 1, "y_max": 0.1, "nx": 20, "ny": 4, "bed_normal_stress": "column",
      "fill": [{"x_max": 0.5, "y_max": 0.05}])";
  const auto r = jobs::resolve_scenario(
      jobs::parse_scenario_json(head + R"(, "boundaries": [{"side": "bottom", "to": 0.6, "kind": "coulomb-friction"}, {"side": "top", "kind": "atmosphere"},
          {"side": "right", "kind": "coulomb-friction"}]}})"), ".");
  runout::jobs::vof_lab::LabSetup su;
  runout::jobs::vof_lab::build_setup(r.scenario.lab(), su);
  EXPECT_EQ(su.config.column_friction.columns.columns(), 12);  // the bottom's faces up to x = 0.6
  EXPECT_EQ(su.config.column_friction.columns.cells.size(), 12u * 4u);
  EXPECT_NEAR(su.config.column_friction.tan_delta, std::tan(su.mat.delta_deg * M_PI / 180), 1e-15);
  EXPECT_EQ(su.config.bc.at("bottom-0").type, "symmetry");
  EXPECT_EQ(su.config.bc.at("right-2").type, "coulomb_friction");  // not the bottom: its face's pressure
  try {
    runout::jobs::vof_lab::LabSetup none;
    runout::jobs::vof_lab::build_setup(
        jobs::resolve_scenario(jobs::parse_scenario_json(head + R"(, "boundaries": [{"side": "right", "kind": "coulomb-friction"}]}})"), ".")
            .scenario.lab(),
        none);
    ADD_FAILURE() << "no coulomb-friction side accepted";
  } catch (const jobs::ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("lab.bed_normal_stress"), std::string::npos) << e.what();
  }
}
