// Bad input to `runout run` and the service: every scenario field with a value outside its
// documented range (docs/user/scenarios.md "Valid ranges"), non-finite numbers, lenient JSON, input files that are
// not regular files. Each is refused with a ScenarioError naming the field; the bundled scenarios
// stay valid with the same hash.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "jobs/drivers/run.hpp"
#include "jobs/scenario/scenario.hpp"
#include "terrain/terrain.hpp"
#include "tests/support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace runout;

namespace {

const std::string kSrc = RUNOUT_SOURCE_DIR;

std::vector<std::string> bundled_scenarios() {
  std::vector<std::string> out;
  for (const char* dir : {"scenarios", "tests/data", "regression"}) {
    if (!fs::exists(kSrc + "/" + dir)) continue;
    for (const auto& e : fs::recursive_directory_iterator(kSrc + "/" + dir)) {
      if (e.path().extension() != ".json" || e.path().filename() == "run.json") continue;
      std::ifstream in(e.path());
      std::stringstream ss;
      ss << in.rdbuf();
      const auto t = ss.str();
      if (t.find("\"dem\"") == std::string::npos && t.find("\"lab\"") == std::string::npos) continue;
      out.push_back(e.path().string());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

using runout::test_support::read_text;
using runout::test_support::TempDir;

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

// The depth-averaged base: In den Arelen at 30 m (tests/data), and the VOF base: B10 a = 0.5.
const std::string kDataDir = kSrc + "/tests/data";
const std::string kLabDir = kSrc + "/scenarios/lab";
v1::Scenario arelen() { return jobs::parse_scenario_json(read_text(kDataDir + "/arelen-30m.json")); }
v1::Scenario b10() { return jobs::parse_scenario_json(read_text(kLabDir + "/b10-column-a0.5.json")); }

// The message of the ScenarioError that resolving `s` throws ("" when none).
std::string resolve_error(const v1::Scenario& s, const std::string& base) {
  try {
    jobs::resolve_scenario(s, base);
  } catch (const jobs::ScenarioError& e) {
    return e.what();
  }
  return "";
}
std::string parse_error(const std::string& json) {
  try {
    jobs::parse_scenario_json(json);
  } catch (const jobs::ScenarioError& e) {
    return e.what();
  }
  return "";
}

struct BadCase {
  const char* what;
  std::function<void(v1::Scenario&)> change;
  const char* field;  // the message starts with this field
  const char* range;  // and holds this (the range or the reason)
};

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

v1::Release& rel(v1::Scenario& s) { return *s.mutable_releases(0); }

const std::vector<BadCase> kDepthAveraged = {
    {"thickness 1e300", [](v1::Scenario& s) { rel(s).set_thickness_m(1e300); }, "releases[0].thickness_m", "(0, 500] m, got 1e+300"},
    {"thickness 1e6", [](v1::Scenario& s) { rel(s).set_thickness_m(1e6); }, "releases[0].thickness_m", "(0, 500] m"},
    {"thickness inf", [](v1::Scenario& s) { rel(s).set_thickness_m(kInf); }, "releases[0].thickness_m", "got inf"},
    {"thickness nan", [](v1::Scenario& s) { rel(s).set_thickness_m(kNaN); }, "releases[0].thickness_m", "got nan"},
    {"thickness 0", [](v1::Scenario& s) { rel(s).set_thickness_m(0); }, "releases[0].thickness_m", "(0, 500] m, got 0"},
    {"min slope 90", [](v1::Scenario& s) { rel(s).set_min_slope_deg(90); }, "releases[0].min_slope_deg", "[0, 90) deg"},
    {"max slope nan", [](v1::Scenario& s) { rel(s).set_max_slope_deg(kNaN); }, "releases[0].max_slope_deg", "(0, 90] deg"},
    {"density inf", [](v1::Scenario& s) { s.mutable_material()->set_density_kg_m3(kInf); }, "material.density_kg_m3", "(0, 10000] kg/m3, got inf"},
    {"ranks -1", [](v1::Scenario& s) { s.set_ranks(-1); }, "ranks", "0..65536"},
    {"ranks for the depth-averaged engine", [](v1::Scenario& s) { s.set_ranks(2); }, "ranks", "the depth-averaged engine runs on one process"},
    {"ranks for an ensemble",
     [](v1::Scenario& s) {
       s.set_ranks(2);
       s.set_engine("vof");
       s.mutable_variations()->set_samples(2);
     },
     "ranks", "an ensemble's members run on one process each"},
    {"density 1e308", [](v1::Scenario& s) { s.mutable_material()->set_density_kg_m3(1e308); }, "material.density_kg_m3", "(0, 10000] kg/m3"},
    {"density -300", [](v1::Scenario& s) { s.mutable_material()->set_density_kg_m3(-300); }, "material.density_kg_m3", "got -300"},
    {"bed friction 90", [](v1::Scenario& s) { s.mutable_material()->set_bed_friction_deg(90); }, "material.bed_friction_deg", "[0, 90)"},
    {"internal friction nan", [](v1::Scenario& s) { s.mutable_material()->set_internal_friction_deg(kNaN); }, "material.internal_friction_deg", "[0, 90)"},
    {"voellmy xi inf",
     [](v1::Scenario& s) {
       s.mutable_material()->set_rheology("voellmy");
       s.mutable_material()->set_voellmy_mu(0.2);
       s.mutable_material()->set_voellmy_xi(kInf);
     },
     "material.voellmy_xi", "(0, 100000] m/s^2, got inf"},
    {"voellmy xi 1e9 (unused by coulomb)", [](v1::Scenario& s) { s.mutable_material()->set_voellmy_xi(1e9); }, "material.voellmy_xi", "(0, 100000]"},
    {"voellmy mu 5", [](v1::Scenario& s) { s.mutable_material()->set_voellmy_mu(5); }, "material.voellmy_mu", "[0, 5)"},
    {"cfl 1e-12", [](v1::Scenario& s) { s.mutable_numerics()->set_cfl(1e-12); }, "numerics.cfl", "[0.01, 0.5], got 1e-12"},
    {"cfl 0.6", [](v1::Scenario& s) { s.mutable_numerics()->set_cfl(0.6); }, "numerics.cfl", "[0.01, 0.5]"},
    {"end time inf", [](v1::Scenario& s) { s.mutable_numerics()->set_end_time_s(kInf); }, "numerics.end_time_s", "(0, 100000] s, got inf"},
    {"end time 1e300", [](v1::Scenario& s) { s.mutable_numerics()->set_end_time_s(1e300); }, "numerics.end_time_s", "(0, 100000] s"},
    {"end time 0", [](v1::Scenario& s) { s.mutable_numerics()->set_end_time_s(0); }, "numerics.end_time_s", "(0, 100000] s"},
    {"stop fraction 1", [](v1::Scenario& s) { s.mutable_numerics()->set_stop_fraction(1); }, "numerics.stop_fraction", "[0, 1)"},
    {"outline threshold inf", [](v1::Scenario& s) { s.mutable_outputs()->set_outline_threshold_m(kInf); }, "outputs.outline_threshold_m", "(0, 100] m"},
    {"flow threshold inf", [](v1::Scenario& s) { s.mutable_outputs()->set_flow_threshold_m(kInf); }, "outputs.flow_threshold_m", "(0, 100] m"},
    {"flow threshold -1", [](v1::Scenario& s) { s.mutable_outputs()->set_flow_threshold_m(-1); }, "outputs.flow_threshold_m", "(0, 100] m"},
    {"time series interval inf", [](v1::Scenario& s) { s.mutable_outputs()->set_timeseries_interval_s(kInf); }, "outputs.timeseries_interval_s", "[0, 100000] s"},
    {"time series interval nan", [](v1::Scenario& s) { s.mutable_outputs()->set_timeseries_interval_s(kNaN); }, "outputs.timeseries_interval_s", "got nan"},
    {"resolution 1e308", [](v1::Scenario& s) { s.mutable_grid()->set_resolution_m(1e308); }, "grid.resolution_m", "(0, 10000] m (0: the DEM's), got 1e+308"},
    {"resolution inf", [](v1::Scenario& s) { s.mutable_grid()->set_resolution_m(kInf); }, "grid.resolution_m", "got inf"},
    {"resolution -10", [](v1::Scenario& s) { s.mutable_grid()->set_resolution_m(-10); }, "grid.resolution_m", "got -10"},
    {"limits.max_wall_s inf", [](v1::Scenario& s) { s.mutable_limits()->set_max_wall_s(kInf); }, "limits.max_wall_s", "finite"},
};

const std::vector<BadCase> kLab = {
    {"end time inf", [](v1::Scenario& s) { s.mutable_lab()->set_end_time_s(kInf); }, "lab.end_time_s", "(0, 10000] s, got inf"},
    {"end time 1e300", [](v1::Scenario& s) { s.mutable_lab()->set_end_time_s(1e300); }, "lab.end_time_s", "(0, 10000] s"},
    {"max courant 1e-9", [](v1::Scenario& s) { s.mutable_lab()->set_max_courant(1e-9); }, "lab.max_courant", "[0.01, 1], got 1e-09"},
    {"x_max inf", [](v1::Scenario& s) { s.mutable_lab()->set_x_max(kInf); }, "lab.x_max", "[-10000, 10000] m, got inf"},
    {"x_min -inf", [](v1::Scenario& s) { s.mutable_lab()->set_x_min(-kInf); }, "lab.x_min", "got -inf"},
    {"y_max 1e300", [](v1::Scenario& s) { s.mutable_lab()->set_y_max(1e300); }, "lab.y_max", "[-10000, 10000] m"},
    {"z_max nan", [](v1::Scenario& s) { s.mutable_lab()->set_z_max(kNaN); }, "lab.z_max", "got nan"},
    {"inclination nan", [](v1::Scenario& s) { s.mutable_lab()->set_inclination_deg(kNaN); }, "lab.inclination_deg", "(-90, 90)"},
    {"write interval inf", [](v1::Scenario& s) { s.mutable_lab()->set_write_interval_s(kInf); }, "lab.write_interval_s", "[0, 10000] s"},
    {"checkpoint interval inf", [](v1::Scenario& s) { s.mutable_lab()->set_checkpoint_interval_s(kInf); }, "lab.checkpoint_interval_s", "[0, 10000] s"},
    {"rotation period inf", [](v1::Scenario& s) { s.mutable_lab()->set_rotation_period_s(kInf); }, "lab.rotation_period_s", "[0, 1e+06] s"},
    {"station inf", [](v1::Scenario& s) { s.mutable_lab()->add_stations_x(kInf); }, "lab.stations_x[0]", "got inf"},
    {"fill x_max inf", [](v1::Scenario& s) { s.mutable_lab()->mutable_fill(0)->set_x_max(kInf); }, "lab.fill[0].x_max", "got inf"},
    {"fill polygon nan",
     [](v1::Scenario& s) {
       auto* f = s.mutable_lab()->mutable_fill(0);
       for (double v : {0.0, 0.0, 0.05, 0.0, kNaN, 0.02}) f->add_polygon_xy(v);
     },
     "lab.fill[0].polygon_xy[4]", "got nan"},
    {"fill cap radius inf", [](v1::Scenario& s) { s.mutable_lab()->mutable_fill(0)->set_cap_radius(kInf); }, "lab.fill[0].cap_radius", "got inf"},
    {"boundary from inf", [](v1::Scenario& s) { s.mutable_lab()->mutable_boundaries(0)->set_from(kInf); }, "lab.boundaries[0].from", "got inf"},
    {"inflow height inf",
     [](v1::Scenario& s) {
       auto* b = s.mutable_lab()->add_boundaries();
       b->set_side("left");
       b->set_kind("inflow");
       b->set_inflow_height(kInf);
     },
     "lab.boundaries[2].inflow_height", "got inf"},
    {"inflow u0 1e9", [](v1::Scenario& s) { s.mutable_lab()->mutable_boundaries(0)->set_inflow_u0(1e9); }, "lab.boundaries[0].inflow_u0", "[-100, 100] m/s"},
    {"obstacle corner inf",
     [](v1::Scenario& s) {
       auto* o = s.mutable_lab()->add_obstacles();
       o->set_shape("polygon");
       for (double v : {0.1, 0.0, kInf, 0.0, 0.1, 0.01}) o->add_polygon_xy(v);
     },
     "lab.obstacles[0].polygon_xy[2]", "got inf"},
    {"phi inf", [](v1::Scenario& s) { s.mutable_lab()->set_phi_deg(kInf); }, "lab.phi_deg", "(0, 80)"},
    {"reference front inf",
     [](v1::Scenario& s) {
       s.mutable_lab()->mutable_reference()->set_front_x_min(0.1);
       s.mutable_lab()->mutable_reference()->set_front_x_max(kInf);
     },
     "lab.reference.front_x_max", ""},
};

void expect_refused(const std::vector<BadCase>& cases, v1::Scenario (*base)(), const std::string& dir) {
  ASSERT_EQ(resolve_error(base(), dir), "");
  for (const auto& c : cases) {
    auto s = base();
    c.change(s);
    const auto m = resolve_error(s, dir);
    EXPECT_EQ(m.rfind(std::string(c.field) + ": ", 0), 0u) << c.what << ": " << (m.empty() ? "accepted" : m);
    EXPECT_NE(m.find(c.range), std::string::npos) << c.what << ": " << m;
  }
}

}  // namespace

TEST(BadScenario, DepthAveragedFieldsOutsideTheirRangesAreRefused) { expect_refused(kDepthAveraged, arelen, kDataDir); }
TEST(BadScenario, LabFieldsOutsideTheirRangesAreRefused) { expect_refused(kLab, b10, kLabDir); }

// A 3D run's ranks are accepted (laboratory, terrain, a depth-averaged scenario's nest) and change
// nothing it computes: not the scenario's hash.
TEST(Scenarios, RanksAreForThreeDRunsAndLeaveTheHashAlone) {
  auto lab = b10();
  const auto one = jobs::resolve_scenario(lab, kLabDir);
  lab.set_ranks(4);
  const auto four = jobs::resolve_scenario(lab, kLabDir);
  EXPECT_EQ(jobs::scenario_hash(one), jobs::scenario_hash(four));
  auto terrain = arelen();
  terrain.set_engine("vof");
  terrain.set_ranks(2);
  EXPECT_EQ(resolve_error(terrain, kDataDir), "");
  auto nested = arelen();
  nested.mutable_nest()->set_path("../../scenarios/data/arelen/farmhouse-nest.geojson");
  nested.set_ranks(2);
  EXPECT_EQ(resolve_error(nested, kDataDir), "");
}

// The bounds themselves are valid (the ranges are closed where the README says so).
TEST(BadScenario, ValuesAtTheBoundsAreAccepted) {
  auto s = arelen();
  rel(s).set_thickness_m(500);
  s.mutable_material()->set_density_kg_m3(10000);
  s.mutable_numerics()->set_cfl(0.01);
  s.mutable_numerics()->set_end_time_s(1e5);
  s.mutable_outputs()->set_outline_threshold_m(100);
  s.mutable_outputs()->set_timeseries_interval_s(1e5);
  s.mutable_grid()->set_resolution_m(1e4);
  EXPECT_EQ(resolve_error(s, kDataDir), "");
  s = arelen();
  s.mutable_grid()->set_resolution_m(0);  // unset: the DEM's
  EXPECT_EQ(resolve_error(s, kDataDir), "");
  auto l = b10();
  l.mutable_lab()->set_max_courant(0.01);
  l.mutable_lab()->set_end_time_s(1e4);
  l.mutable_lab()->set_write_interval_s(10);  // b10's 0.05 s would be 200,000 frames (at most 1000)
  EXPECT_EQ(resolve_error(l, kLabDir), "");
  l.mutable_lab()->set_write_interval_s(0);  // unset: every 10 s, not the default 0.05 s
  EXPECT_EQ(resolve_error(l, kLabDir), "");
}

// Lenient JSON that protobuf's parser takes: a key twice, one value where a list is needed.
TEST(BadScenario, DuplicateKeysAndNonListsAreRefused) {
  struct {
    const char* json;
    const char* needle;
  } cases[] = {
      {R"({"dem": {"path": "a.tif"}, "grid": {"resolution_m": 30}, "grid": {"resolution_m": 90}})", "scenario JSON: grid: given twice"},
      {R"({"material": {"density_kg_m3": 300, "bed_friction_deg": 15, "density_kg_m3": 200}})", "scenario JSON: material.density_kg_m3: given twice"},
      {R"({"grid": {"resolution_m": 30, "resolutionM": 90}})", "scenario JSON: grid.resolution_m: given twice"},
      {R"({"releases": {"path": "r.geojson", "thickness_m": 1}})", "scenario JSON: releases: must be a list [...], got an object"},
      {R"({"outputs": {"rasters": "max_depth"}})", "scenario JSON: outputs.rasters: must be a list [...], got a string"},
      {R"({"engine": "vof", "lab": {"fill": {"x_max": 1, "y_max": 1}}})", "scenario JSON: lab.fill: must be a list"},
      {R"({"engine": "vof", "lab": {"stations_x": 0.5}})", "scenario JSON: lab.stations_x: must be a list [...], got a number"},
      {R"({"releases": [{"path": "a", "path": "b"}]})", "scenario JSON: releases[0].path: given twice"},
  };
  for (const auto& c : cases) {
    const auto m = parse_error(c.json);
    EXPECT_NE(m.find(c.needle), std::string::npos) << c.json << " -> " << (m.empty() ? "accepted" : m);
  }
  // What stays valid: lists, null, empty objects and lists, escapes, keys in both spellings once.
  EXPECT_EQ(parse_error(R"({"name": "a \"b\" \\ \u00e9 {[", "releases": [], "grid": null, "outputs": {"rasters": ["max_depth"]},
      "numerics": {"endTimeS": 5}, "material": {}})"),
            "");
}

// Input files that are not regular files: refused when the scenario is resolved, naming the field.
TEST(BadScenario, InputsThatAreNotRegularFilesAreRefused) {
  TempDir d;
  auto with_dem = [&](const std::string& dem) {
    auto s = arelen();
    s.mutable_dem()->set_path(dem[0] == '/' ? dem : d / dem);
    return resolve_error(s, kDataDir);
  };
  ASSERT_EQ(mkfifo((d / "fifo.tif").c_str(), 0600), 0);
  EXPECT_EQ(with_dem("fifo.tif"), "dem.path: '" + (d / "fifo.tif") + "' is not a regular file");
  fs::create_symlink("loop.tif", d.p / "loop.tif");
  const auto loop = with_dem("loop.tif");
  EXPECT_EQ(loop.rfind("dem.path: cannot read '" + (d / "loop.tif") + "': ", 0), 0u) << loop;
  fs::create_directories(d.p / "folder.tif");
  EXPECT_EQ(with_dem("folder.tif"), "dem.path: '" + (d / "folder.tif") + "' is not a regular file");
  EXPECT_EQ(with_dem("/dev/zero"), "dem.path: '/dev/zero' is not a regular file");
  EXPECT_EQ(with_dem(std::string("dem.tif\0.txt", 12)).rfind("dem.path: holds a control character (U+0000) at byte ", 0), 0u);
  // A companion file read with the DEM.
  fs::copy_file(kSrc + "/scenarios/data/arelen/davos_srtm3.tif", d.p / "dem.tif");
  EXPECT_EQ(with_dem("dem.tif"), "");
  ASSERT_EQ(mkfifo((d / "dem.prj").c_str(), 0600), 0);
  EXPECT_NE(with_dem("dem.tif").find("dem.path: '" + (d / "dem.prj") + "' (read with the file) is not a regular file"), std::string::npos);
  // A release that is a FIFO; the scenario file itself.
  auto s = arelen();
  rel(s).set_path(d / "fifo.tif");
  EXPECT_EQ(resolve_error(s, kDataDir).rfind("releases[0].path: ", 0), 0u);
  try {
    jobs::load_scenario(d / "fifo.tif");
    ADD_FAILURE() << "a FIFO read as a scenario";
  } catch (const jobs::ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  }
}

// Infinity written in the JSON (protobuf reads "Infinity"), through load_scenario as `runout run` does.
TEST(BadScenario, InfinityInTheFileIsRefused) {
  TempDir d;
  auto text = read_text(kDataDir + "/arelen-30m.json");
  const std::string dem = "\"../../scenarios/data/arelen/";
  for (std::size_t k; (k = text.find(dem)) != std::string::npos;) text.replace(k, dem.size(), "\"" + kSrc + "/scenarios/data/arelen/");
  const auto at = text.find("\"density_kg_m3\": 300");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 20, "\"density_kg_m3\": \"Infinity\"");
  write_text(d / "s.json", text);
  try {
    jobs::load_scenario(d / "s.json");
    ADD_FAILURE() << "accepted";
  } catch (const jobs::ScenarioError& e) {
    EXPECT_EQ(std::string(e.what()), "material.density_kg_m3: must lie in (0, 10000] kg/m3, got inf");
  }
}

// A thickness attribute that is not a number is said to be one (GDAL reads "abc" as 0).
TEST(BadScenario, ThicknessAttributeThatIsNotANumber) {
  TempDir d;
  auto text = read_text(kSrc + "/scenarios/data/arelen/release.geojson");
  const auto at = text.find("\"thickness_m\":1.5");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 17, "\"thickness_m\":\"abc\"");
  write_text(d / "rel.geojson", text);
  auto s = arelen();
  s.mutable_grid()->set_resolution_m(90);
  rel(s).set_path(d / "rel.geojson");
  const auto r = jobs::resolve_scenario(s, kDataDir);
  fs::create_directories(d.p / "out");
  try {
    jobs::run_scenario(r, (d.p / "out").string());
    ADD_FAILURE() << "accepted";
  } catch (const terrain::TerrainError& e) {
    EXPECT_NE(std::string(e.what()).find("attribute 'thickness_m' is not a number: 'abc'"), std::string::npos) << e.what();
  }
}

// Every bundled scenario (except the test data that is bad on purpose) loads, and resolving it again
// gives the same hash. RUNOUT_PRINT_HASHES=1 prints the hashes (to compare across versions).
TEST(BundledScenarios, StayValidAndKeepTheirHash) {
  const bool print = std::getenv("RUNOUT_PRINT_HASHES") != nullptr;
  int n = 0;
  for (const auto& f : bundled_scenarios()) {
    if (f.find("missing-dem") != std::string::npos || f.find("bad-") != std::string::npos) continue;
    try {
      const auto r = jobs::load_scenario(f);
      const auto h = jobs::scenario_hash(r);
      const auto again = jobs::resolve_scenario(r.scenario, fs::path(f).parent_path().string());
      EXPECT_EQ(jobs::scenario_hash(again), h) << f;
      if (print) std::cout << fs::relative(f, kSrc).string() << " " << h << "\n";
      ++n;
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
  EXPECT_GT(n, 20);
}
