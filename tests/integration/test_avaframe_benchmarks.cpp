// AvaFrame's published test cases through runout (docs/validation/validation.md, A10 and A11): the
// inclined plane with entrainment and resistance (avaInclinedPlaneEntresTest) and the channelled
// hockey stick with entrainment (avaHockeyChannelEntTest), their input files as AvaFrame ships them
// (tests/data/avaframe-ip/ and avaframe-hs/, PROVENANCE.md there).
#include <gtest/gtest.h>

#include <cmath>

#include "jobs/drivers/run.hpp"
#include "jobs/scenario/scenario.hpp"
#include "tests/support/run_helpers.hpp"

using namespace runout;
using namespace runout::test_support::run;

namespace {

const std::string kData = std::string(RUNOUT_SOURCE_DIR) + "/tests/data/avaframe-ip/";
const std::string kDataHs = std::string(RUNOUT_SOURCE_DIR) + "/tests/data/avaframe-hs/";
constexpr double kAvaFrameEntrainedKg = 1742135.46;  // AvaFrame 1.11, samosAT

// The standard normal distribution function.
double phi(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

// AvaFrame's hockey stick (generateTopo.hockey: a 34 deg plane from 2200 m, a circle of 200 m into
// the flat foreland) with its narrowing channel added on top, at (x, y) of its own frame (x from the
// top, y across from the channel's axis).
double hockey_channel(double x, double y) {
  const double a = 34.0 * M_PI / 180, z0 = 2200, rc = 200;
  const double x1 = z0 / std::tan(a), beta = 0.5 * (M_PI - a), xc = rc / std::tan(beta), yc = xc * std::cos(a), xcirc = x1 + xc;
  double z = x < x1 - yc ? z0 - std::tan(a) * x : x <= x1 + xc ? rc - std::sqrt(std::abs(rc * rc - (xcirc - x) * (xcirc - x))) : 0.0;
  const double cff = 250, c_radius = 100, c_init = 250, mu_start = 0.2, mu_end = 0.86;
  const double c0 = x < x1 * 0.5 * (mu_start + mu_end) ? phi((x - mu_start * x1) / cff) : 1 - phi((x - mu_end * x1) / cff);
  const double extent = c_init * (1 - c0) + c0 * c_radius;
  z += std::abs(y) < extent ? extent * c0 * (1 - std::sqrt(std::abs(1 - y * y / (extent * extent)))) : extent * c0;
  return z;
}

// An AvaFrame test case as a scenario: the DEM (dem.tif in `d`, in AvaFrame's frame, EPSG:31287), its
// release (attribute thickness, normal) and cover (attribute thickness, 100 kg/m^3), Voellmy friction
// close to samosAT's at AvaFrame's density 200 kg/m^3 (inclined_plane says why), 400 s.
v1::Scenario avaframe_scenario(const TempDir& d, const std::string& release, const std::string& cover, double res) {
  v1::Scenario s = base_scenario(d / "dem.tif", release, res);
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
  a->set_path(cover);
  a->set_thickness_attribute("thickness");
  e->set_density_kg_m3(100);
  s.mutable_numerics()->set_end_time_s(400);
  s.mutable_outputs()->set_maps(false);
  return s;
}

// The benchmark's scenario: AvaFrame's inclined plane (built as its generateTopo does), release,
// cover and forest; Voellmy friction close to samosAT's for a flow about 1 m deep (mu = tan delta =
// 0.155; samosAT's turbulent term rho u^2 / ((1/kappa) ln(h/R) + B)^2 with kappa 0.43, R 0.05 m,
// B 4.13 is Voellmy's rho g u^2 / xi with xi = g (6.97 + 4.13)^2 = 1209 m/s^2 at h = 1 m).
v1::Scenario inclined_plane(const TempDir& d, double res) {
  const double t = std::tan(34.0 * M_PI / 180);
  make_dem_box(d / "dem.tif", 1001, 401, 5.0, 997.5, -5002.5, [&](int i, int) { return 2200 - t * 5.0 * i; }, "EPSG:31287");
  v1::Scenario s = avaframe_scenario(d, kData + "release1IP.shp", kData + "entrainment1IP.shp", res);
  s.mutable_resistance()->add_areas()->set_path(kData + "resistance1IP.shp");
  s.mutable_numerics()->set_stop_fraction(0);
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

// The channelled hockey stick: the flow runs down the channel and takes up the part of the cover it
// passes over (the polygon is wider than the channel), so here the friction matters. Against
// AvaFrame's samosAT reference: entrained mass within 10 % (-5.2 % at 10 m), the farthest cell
// deeper than 0.1 m within 100 m (4405 against 4465 m), the stop at 1 % of the peak kinetic energy
// within 10 % of its time (296 against 300.7 s).
TEST(AvaFrameBenchmarks, HockeyChannelTakesUpCoverAsAvaFrameDoes) {
  TempDir d;
  make_dem_box(d / "dem.tif", 1001, 401, 5.0, 997.5, -5002.5,
               [](int i, int r) { return hockey_channel(5.0 * i, 1000 - 5.0 * r); }, "EPSG:31287");
  v1::Scenario s = avaframe_scenario(d, kDataHs + "release1HS.shp", kDataHs + "entrainment1HS.shp", 10);
  s.mutable_numerics()->set_stop_fraction(0.01);
  fs::create_directories(d / "out");
  jobs::run_scenario(jobs::resolve_scenario(s, d.p.string()), d / "out");
  const auto rec = run_record(d / "out/run.json");
  const auto& mb = rec.mass_balance();
  const double entrained_kg = mb.volume_entrained_m3() * 200;
  const auto depth = read_raster_values(d / "out/max_depth.tif");
  double reach = 0;  // the farthest cell deeper than 0.1 m, as measured on AvaFrame's peak thickness
  for (int row = 0; row < depth.h; ++row)
    for (int i = 0; i < depth.w; ++i)
      if (depth.v[std::size_t(row) * depth.w + i] > 0.1) reach = std::max(reach, depth.cx(i));
  std::printf("initial %.0f kg, entrained %.0f kg (AvaFrame 333560), farthest x %.0f m (AvaFrame 4465), stop %s at %.1f s (AvaFrame 300.7)\n",
              mb.volume_initial_m3() * 200, entrained_kg, reach, rec.solver().stop().c_str(), rec.solver().simulated_s());
  EXPECT_NEAR(mb.volume_initial_m3() * 200 / 19924078.16, 1.0, 0.005);
  EXPECT_NEAR(entrained_kg / 333560.24, 1.0, 0.10);
  EXPECT_NEAR(reach, 4465, 100);
  EXPECT_EQ(rec.solver().stop(), "kinetic-energy");
  EXPECT_NEAR(rec.solver().simulated_s() / 300.7, 1.0, 0.10);
  EXPECT_LT(mb.relative_error(), 1e-12);
}
