// AvaFrame's published test cases through runout (docs/validation/validation.md, "Side by side with
// AvaFrame"): the inclined plane with entrainment and resistance (avaInclinedPlaneEntresTest), its
// input files as AvaFrame ships them (tests/data/avaframe-ip/PROVENANCE.md).
#include <gtest/gtest.h>

#include <cmath>

#include "jobs/drivers/run.hpp"
#include "jobs/scenario/scenario.hpp"
#include "tests/support/run_helpers.hpp"

using namespace runout;
using namespace runout::test_support::run;

namespace {

const std::string kData = std::string(RUNOUT_SOURCE_DIR) + "/tests/data/avaframe-ip/";
constexpr double kAvaFrameEntrainedKg = 1742135.46;  // AvaFrame 1.11, samosAT

// The benchmark's scenario: AvaFrame's inclined plane (built as its generateTopo does), release,
// cover and forest; Voellmy friction close to samosAT's for a flow about 1 m deep (mu = tan delta =
// 0.155; samosAT's turbulent term rho u^2 / ((1/kappa) ln(h/R) + B)^2 with kappa 0.43, R 0.05 m,
// B 4.13 is Voellmy's rho g u^2 / xi with xi = g (6.97 + 4.13)^2 = 1209 m/s^2 at h = 1 m).
v1::Scenario inclined_plane(const TempDir& d, double res) {
  const double t = std::tan(34.0 * M_PI / 180);
  make_dem_box(d / "dem.tif", 1001, 401, 5.0, 997.5, -5002.5, [&](int i, int) { return 2200 - t * 5.0 * i; }, "EPSG:31287");
  v1::Scenario s = base_scenario(d / "dem.tif", kData + "release1IP.shp", res);
  s.mutable_grid()->set_crs("dem");
  auto* r = s.mutable_releases(0);
  r->clear_thickness_m();
  r->set_thickness_attribute("thickness");
  r->set_crs("EPSG:31287");
  auto* m = s.mutable_material();
  m->clear_bed_friction_deg();
  m->set_rheology("voellmy");
  m->set_density_kg_m3(200);
  m->set_voellmy_mu(0.155);
  m->set_voellmy_xi(1200);
  auto* e = s.mutable_entrainment();
  auto* a = e->add_areas();
  a->set_path(kData + "entrainment1IP.shp");
  a->set_thickness_attribute("thickness");
  e->set_density_kg_m3(100);
  s.mutable_resistance()->add_areas()->set_path(kData + "resistance1IP.shp");
  s.mutable_numerics()->set_end_time_s(400);
  s.mutable_numerics()->set_stop_fraction(0);
  s.mutable_outputs()->set_maps(false);
  return s;
}

}  // namespace

// The cover lies across the whole path, so both codes take it up whole: the entrained mass is the
// cover's (0.3 m x 100 kg/m^3 over the polygon's area on the 34 deg slope) in runout, and AvaFrame's
// is within 1.1 % of it (its particles sample the polygon a little larger). With AvaFrame 1.11's
// resistance (drag, no detrainment) nothing is left in the forest; with the detraining model of
// AvaFrame 1.13 and later (runout's default), the forest stops the thin, slow flow (a Voellmy flow of
// about 1 m runs at about 23 m/s, inside the drag's band; thinner than 0.6 m it detrains).
TEST(AvaFrameBenchmarks, InclinedPlaneTakesUpTheWholeCoverAsAvaFrameDoes) {
  TempDir d;
  auto s = inclined_plane(d, 10);
  s.mutable_resistance()->set_detrainment(false);
  fs::create_directories(d / "drag");
  jobs::run_scenario(jobs::resolve_scenario(s, d.p.string()), d / "drag");
  const auto rec = run_record(d / "drag/run.json");
  const auto& mb = rec.mass_balance();
  const double cover_kg = 47617.917 / std::cos(34.0 * M_PI / 180) * 0.3 * 100;  // the polygon's area (projected) on the slope
  const double entrained_kg = mb.volume_entrained_m3() * 200;
  std::printf("initial %.0f kg, entrained %.0f kg (the cover %.0f kg; AvaFrame %.0f kg), detrained %.1f m3\n",
              mb.volume_initial_m3() * 200, entrained_kg, cover_kg, kAvaFrameEntrainedKg, mb.volume_detrained_m3());
  EXPECT_NEAR(mb.volume_initial_m3() * 200, 2e7, 1e-3 * 2e7);  // 1 m normal over the release's 100,000 m^2 of slope
  EXPECT_NEAR(entrained_kg / cover_kg, 1.0, 1e-3);
  EXPECT_NEAR(entrained_kg / kAvaFrameEntrainedKg, 1.0, 0.02);
  EXPECT_EQ(mb.volume_detrained_m3(), 0.0);
  EXPECT_LT(mb.volume_outflow_m3(), 1e-9 * mb.volume_initial_m3());  // a film at the lower edge at most
  EXPECT_LT(mb.relative_error(), 1e-12);
  // The detraining forest of AvaFrame 1.13 and later.
  s.mutable_resistance()->clear_detrainment();
  fs::create_directories(d / "detrain");
  jobs::run_scenario(jobs::resolve_scenario(s, d.p.string()), d / "detrain");
  const auto det = run_record(d / "detrain/run.json").mass_balance();
  EXPECT_NEAR(det.volume_entrained_m3(), mb.volume_entrained_m3(), 1e-9 * mb.volume_entrained_m3());
  EXPECT_GT(det.volume_detrained_m3(), 0.5 * (det.volume_initial_m3() + det.volume_entrained_m3()));
  EXPECT_LT(det.relative_error(), 1e-12);
}
