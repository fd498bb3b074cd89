// The nightly regression's accepted reference (regression/<case>/reference.json) as
// runout.v1.RegressionReference: what --accept writes is what a later run reads, the bundled
// reference reads, and a reference without a figure is refused naming it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "jobs/regression/regression.hpp"
#include "tests/support/temp_dir.hpp"

namespace fs = std::filesystem;
using runout::test_support::TempDir;

TEST(RegressionReference, AcceptedReferenceReadsBack) {
  TempDir d;
  const fs::path src = d.p / "max_depth.tif";
  std::ofstream(src) << "not read by accept";
  runout::jobs::RegressionFigures f;
  f.runout_m = 2739.729571;
  f.affected_area_m2 = 1837200;
  f.max_depth_m = 10.81642977;
  f.max_speed_m_s = 66.5338256;
  f.volume_error = 4.026729379e-16;
  f.farmhouse_depth_m = 0.202661141753;
  f.farmhouse_distance_m = 0;
  const std::string reason = "a \"quoted\" reason\nover two lines";
  runout::jobs::accept_reference((d.p / "ref").string(), f, src.string(), reason, "abc123", "9.9.9");
  const auto r = runout::jobs::read_reference((d.p / "ref").string());
  EXPECT_EQ(r.figures.runout_m, f.runout_m);
  EXPECT_EQ(r.figures.affected_area_m2, f.affected_area_m2);
  EXPECT_EQ(r.figures.max_depth_m, f.max_depth_m);
  EXPECT_EQ(r.figures.max_speed_m_s, f.max_speed_m_s);
  EXPECT_EQ(r.figures.volume_error, f.volume_error);
  EXPECT_EQ(r.figures.farmhouse_depth_m, f.farmhouse_depth_m);
  EXPECT_EQ(r.figures.farmhouse_distance_m, 0.0);
  EXPECT_EQ(r.reason, reason);
  EXPECT_EQ(r.scenario_hash, "abc123");
  EXPECT_EQ(r.software_version, "9.9.9");
  EXPECT_EQ(r.tolerances.runout_rel, runout::jobs::RegressionTolerances{}.runout_rel);  // the defaults, no reference before
  EXPECT_TRUE(fs::exists(d.p / "ref" / "max_depth.tif"));
}

TEST(RegressionReference, BundledReferenceReadsAndAMissingFigureIsNamed) {
  const auto r = runout::jobs::read_reference(std::string(RUNOUT_SOURCE_DIR) + "/regression/in-den-arelen");
  EXPECT_GT(r.figures.runout_m, 2000);  // the accepted 10 m run reaches the valley floor: 2738.2 m (regression/in-den-arelen/HISTORY.md)
  EXPECT_EQ(r.tolerances.runout_rel, 0.02);
  TempDir d2;
  std::ofstream(d2.p / "reference.json") << R"({"figures": {"runout_m": 1}, "tolerances": {}})";
  try {
    runout::jobs::read_reference(d2.p.string());
    FAIL() << "a reference without figures was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("figures.affected_area_m2"), std::string::npos) << e.what();
  }
}
