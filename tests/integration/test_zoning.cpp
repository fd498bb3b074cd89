// Hazard zones from scenarios by return period (scenario `zoning`): the guideline's rule cell by cell,
// and the bundled In den Arelen zoning, whose every cell's zone is checked against the rule applied
// here, independently, to the three scenarios' depth and pressure rasters written beside the zones.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <vector>

#include "jobs/drivers/run.hpp"
#include "jobs/drivers/zoning.hpp"
#include "jobs/ensemble/variations.hpp"
#include "jobs/products/zoning.hpp"
#include "jobs/scenario/inputs.hpp"
#include "jobs/scenario/scenario.hpp"
#include "tests/support/run_helpers.hpp"

using namespace runout;
using namespace runout::test_support::run;
namespace products = runout::jobs::products;

namespace {

// A raster of the zoning's folder as numbers (no data as NaN).
std::vector<double> read_all(const fs::path& tif) { return read_raster_values(tif.string()).v; }

}  // namespace

// The rule of the Swiss guideline (BFF & EISLF 1984) as the zoning applies it, 30 kPa, 30 and 300
// years, reached where the maximum depth exceeds 0.1 m.
TEST(Zoning, TheGuidelinesRule) {
  const products::ZoningRule r{30, 30, 300, 0.1};
  EXPECT_EQ(products::zone_of(r, 30, 0.05, 500), products::kNoZone);  // not reached: no zone, whatever the pressure
  EXPECT_EQ(products::zone_of(r, 30, 0.2, 1), products::kRed);        // any flow up to 30 years
  EXPECT_EQ(products::zone_of(r, 100, 0.2, 29.9), products::kBlue);
  EXPECT_EQ(products::zone_of(r, 100, 0.2, 30), products::kRed);
  EXPECT_EQ(products::zone_of(r, 300, 2, 29), products::kBlue);
  EXPECT_EQ(products::zone_of(r, 300, 2, 300), products::kRed);
  EXPECT_EQ(products::zone_of(r, 1000, 2, 300), products::kYellow);    // rarer than the design event
  // The most severe verdict of the scenarios holds; the outside stays without a zone.
  const std::vector<double> d30 = {0.2, 0, 0, 0}, p30 = {1, 0, 0, 0};
  const std::vector<double> d300 = {1, 1, 1, 0}, p300 = {10, 40, 10, 0};
  const std::vector<double> d1000 = {1, 1, 1, 1}, p1000 = {100, 100, 100, 100};
  const auto z = products::zones(r, {{30, &d30, &p30}, {300, &d300, &p300}, {1000, &d1000, &p1000}}, {0, 0, 0, 1});
  EXPECT_EQ(z, (std::vector<std::uint8_t>{products::kRed, products::kRed, products::kBlue, products::kNoZone}));
}

// The bundled zoning of In den Arelen (30, 100 and 300 years), each scenario run as a member and the
// zones aggregated: every cell's zone is the rule applied to the three scenarios' rasters; each zone's
// area and each scenario's reach in run.json agree with the rasters; the per-scenario maps lie beside.
TEST(Zoning, InDenArelenZonesAreTheRuleAppliedToTheScenarios) {
  TempDir d;
  auto s = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/in-den-arelen-zoning.json");
  jobs::absolute_inputs(s.scenario, std::string(RUNOUT_SOURCE_DIR) + "/scenarios");
  const auto members = jobs::ensemble::expand(s.scenario);
  ASSERT_EQ(members.size(), 3u);
  std::vector<jobs::MemberResults> results;
  for (const auto& m : members) {
    const fs::path dir = d.p / ("member_" + std::to_string(m.index));
    fs::create_directories(dir);
    jobs::run_scenario(jobs::resolve_scenario(m.scenario, "/"), dir.string());
    results.push_back({m, "", dir.string()});
  }
  fs::create_directories(d.p / "zones");
  const auto rec = jobs::aggregate_zoning(s, results, (d.p / "zones").string());
  EXPECT_EQ(rec.kind(), "zoning");
  for (const char* f : {"zones.tif", "zones.qml", "zones.gpkg", "zones.geojson", "map_zones.png", "map_zones.pdf", "map_max_pressure_30y.png",
                        "map_max_pressure_100y.png", "map_max_pressure_300y.png", "run.json"})
    EXPECT_TRUE(fs::exists(d.p / "zones" / f)) << f;
  const auto zones = read_all(d.p / "zones/zones.tif");
  const double years[3] = {30, 100, 300};
  std::vector<double> depth[3], pressure[3];
  for (int k = 0; k < 3; ++k) {
    const std::string tag = std::to_string(int(years[k])) + "y.tif";
    depth[k] = read_all(d.p / "zones" / ("max_depth_" + tag));
    pressure[k] = read_all(d.p / "zones" / ("max_pressure_" + tag));
  }
  long count[4] = {0, 0, 0, 0}, reached[3] = {0, 0, 0};
  for (std::size_t c = 0; c < zones.size(); ++c) {
    if (std::isnan(depth[2][c])) continue;  // outside the domain
    int zone = 0;  // the rule, written out: red >= 30 kPa up to 300 y or any flow up to 30 y; blue reached up to 300 y
    for (int k = 0; k < 3; ++k) {
      if (!(depth[k][c] > 0.1)) continue;
      ++reached[k];
      zone = std::max(zone, years[k] <= 30 || pressure[k][c] >= 30 ? 3 : 2);
    }
    ASSERT_EQ(zones[c], zone) << "cell " << c;
    ++count[zone];
  }
  const auto& z = rec.zoning();
  ASSERT_EQ(z.zones_size(), 3);
  EXPECT_EQ(z.zones(0).cells(), count[1]);
  EXPECT_EQ(z.zones(1).cells(), count[2]);
  EXPECT_EQ(z.zones(2).cells(), count[3]);
  EXPECT_GT(count[2], 0);
  EXPECT_GT(count[3], 1000);
  ASSERT_EQ(z.scenarios_size(), 3);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(z.scenarios(k).return_period_y(), years[k]);
    EXPECT_NEAR(z.scenarios(k).reached_area_m2(), double(reached[k]) * 900, 1e-6);
  }
  EXPECT_LT(z.scenarios(0).reached_area_m2(), z.scenarios(2).reached_area_m2());  // the rarer scenario reaches further
}
