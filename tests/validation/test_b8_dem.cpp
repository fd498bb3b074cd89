// B8 through the DEM path (validation.md B8, "through the DEM path"): the curved chute of
// scenarios/lab/b8-curved-chute.json (Wieland, Gray & Hutter 1999) written as a DEM raster in local
// metres (the bed's elevation under each cell centre, the whole chute on both sides of its plane of
// symmetry), the spherical cap as a release-thickness raster, run by the 3D engine on terrain
// (vertical columns, layers graded from the ground, Coulomb friction bed) and compared with the
// analytic chute mesh's run (bed-normal columns, half the chute) at the same cell size.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "jobs/drivers/run.hpp"
#include "jobs/drivers/vof_lab/geometry.hpp"
#include "jobs/scenario/scenario.hpp"
#include "tests/support/local_raster.hpp"
#include "tests/support/run_record.hpp"
#include "tests/support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using namespace runout;
using test_support::record_figure;
using test_support::run_record;
using test_support::TempDir;

constexpr double kPi = 3.14159265358979323846;
const std::string kB8 = std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab/b8-curved-chute.json";

// The chute's bed in the world: x horizontal down the chute, y across (0 on the plane of symmetry),
// z up; the lab's channel coordinates (X along the upper chute, Y normal to it) turned by the
// inclination.
struct WorldChute {
  jobs::vof_lab::ChuteBed bed;
  double incl;
  explicit WorldChute(const v1::Lab& L) : bed(L), incl(L.inclination_deg() * kPi / 180) {}
  // The bed point at arc length s and across y: world x and z.
  std::pair<double, double> at(double s, double y) const {
    const auto p = bed.point(s, 0, std::abs(y));
    return {p.x * std::cos(incl) + p.y * std::sin(incl), -p.x * std::sin(incl) + p.y * std::cos(incl)};
  }
  // The arc length under world x at y (the bed's x grows with s).
  double arc(double x, double y) const {
    double a = -2, b = 6;
    for (int k = 0; k < 80; ++k) {
      const double m = 0.5 * (a + b);
      (at(m, y).first < x ? a : b) = m;
    }
    return 0.5 * (a + b);
  }
};

struct ChuteFigures {
  double volume0 = 0;          ///< released [m3], the whole chute
  double on_chute = 0, in_bend = 0, on_runout = 0;  ///< shares of the deposit's volume
  double from = NAN, to = NAN;  ///< the deposit (depth above 1 mm) along the arc length [m]
  double half_width_runout = 0;  ///< its half-width beyond the bend [m]
  double highest_s = NAN, highest_depth = 0, centroid_s = 0;
  double left = 0;  ///< share of the released volume that left the domain
};

// The lab scenario on the analytic chute mesh at cell size c (its record's curved_chute).
ChuteFigures lab_run(double c, const fs::path& out) {
  auto r = jobs::load_scenario(kB8);
  auto* lab = r.scenario.mutable_lab();
  const double c0 = (lab->x_max() - lab->x_min()) / lab->nx();
  lab->set_nx(int(std::lround(lab->nx() * c0 / c)));
  lab->set_ny(int(std::lround(lab->ny() * c0 / c)));
  lab->set_nz(int(std::lround(lab->nz() * c0 / c)));
  lab->set_write_interval_s(2.0);
  fs::create_directories(out);
  const auto sum = jobs::run_scenario(r, out.string());
  EXPECT_EQ(sum.stop, "end-time");
  const auto j = run_record(out / "run.json");
  // The mesh holds the released half cap (pi hc^2 (3 r - hc) / 6 within 2 %); the mass runs down the
  // chute and through the bend onto the run-out, fans out there wider than the 0.30 m it was
  // released beside the plane of symmetry, comes to rest around the end of the bend (2.15 m) with
  // its highest point on the chute side of its centroid; alpha stays within [0, 1].
  const double rc = 0.32, hc = 0.22;
  EXPECT_NEAR(record_figure(j, "volume_initial_m3"), kPi * hc * hc * (3 * rc - hc) / 6, 0.02 * kPi * hc * hc * (3 * rc - hc) / 6);
  EXPECT_GT(record_figure(j, "peak_speed_m_s"), 1.0);
  EXPECT_GT(record_figure(j, "share_on_runout"), 0.5);
  EXPECT_GT(record_figure(j, "half_width_on_runout_m"), 0.4);
  EXPECT_LT(record_figure(j, "highest_x_m"), record_figure(j, "centroid_x_m"));
  EXPECT_LT(record_figure(j, "highest_x_m"), 2.4);
  EXPECT_LT(record_figure(j, "volume_relative_error"), 0.4);  // the film over the open sides: 35 % at 5 cm, 7.6 % at 2.5 cm
  EXPECT_GT(record_figure(j, "alpha_min"), -1e-6);
  EXPECT_LT(record_figure(j, "alpha_max"), 1 + 1e-6);
  // fields.xmf places the values at the cells' centres as they lie on the bent chute.
  const std::string xmf = test_support::read_text(out / "fields.xmf");
  EXPECT_NE(xmf.find("TopologyType=\"3DSMesh\""), std::string::npos);
  EXPECT_NE(xmf.find("fields.h5:/centres"), std::string::npos);
  ChuteFigures f;
  f.volume0 = 2 * record_figure(j, "volume_initial_m3");
  f.on_chute = record_figure(j, "share_on_chute");
  f.in_bend = record_figure(j, "share_in_bend");
  f.on_runout = record_figure(j, "share_on_runout");
  f.from = record_figure(j, "deposit_from_m");
  f.to = record_figure(j, "deposit_to_m");
  f.half_width_runout = record_figure(j, "half_width_on_runout_m");
  f.highest_s = record_figure(j, "highest_x_m");
  f.highest_depth = record_figure(j, "highest_depth_m");
  f.centroid_s = record_figure(j, "centroid_x_m");
  f.left = record_figure(j, "volume_relative_error");
  return f;
}

// The same chute and cap through the DEM path at cell size c: DEM and thickness rasters, a terrain
// scenario with the lab's material, friction and end time, and the figures from deposit.tif.
ChuteFigures dem_run(double c, const fs::path& out) {
  const auto lab_r = jobs::load_scenario(kB8);
  const v1::Lab& L = lab_r.scenario.lab();
  const WorldChute w(L);
  const double s1 = L.chute().bend_start_m(), s2 = L.chute().bend_end_m();
  const double x0 = w.at(-0.2, 0).first, x1 = w.at(L.x_max(), 0).first, half = L.z_max() - L.z_min();
  const int nx = int(std::ceil((x1 - x0) / c)), ny = 2 * int(std::lround(half / c));
  const double y_top = 0.5 * ny * c;
  std::vector<double> dem(std::size_t(nx) * std::size_t(ny)), cap(dem.size(), 0.0);
  const auto& fill = L.fill(0);
  const double rc = fill.cap_radius(), hc = fill.cap_height();
  for (int r = 0; r < ny; ++r)
    for (int i = 0; i < nx; ++i) {
      const double x = x0 + (i + 0.5) * c, y = y_top - (r + 0.5) * c, s = w.arc(x, y);
      const std::size_t k = std::size_t(r) * std::size_t(nx) + std::size_t(i);
      dem[k] = w.at(s, y).second;
      const double q = rc * rc - (s - fill.cap_x()) * (s - fill.cap_x()) - (y - fill.cap_z()) * (y - fill.cap_z());
      if (q > 0) cap[k] = std::max(0.0, std::sqrt(q) - (rc - hc));
    }
  fs::create_directories(out);
  test_support::write_local_raster((out / "chute.tif").string(), nx, ny, x0, y_top, c, dem);
  test_support::write_local_raster((out / "cap.tif").string(), nx, ny, x0, y_top, c, cap);

  v1::Scenario sc;
  sc.set_name("B8 through the DEM path");
  sc.set_engine("vof");
  sc.mutable_dem()->set_path("chute.tif");
  sc.mutable_dem()->set_crs("local");
  sc.mutable_grid()->set_crs("dem");
  auto* rel = sc.add_releases();
  rel->set_thickness_raster("cap.tif");
  rel->set_crs("local");
  auto* m = sc.mutable_material();
  m->set_density_kg_m3(1626.67);  // the lab's sand
  m->set_internal_friction_deg(L.phi_deg());
  m->set_bed_friction_deg(L.bed_friction_deg());
  sc.mutable_numerics()->set_end_time_s(L.end_time_s());
  sc.mutable_numerics()->set_stop_fraction(0);
  sc.mutable_outputs()->set_outline_threshold_m(1e-3);
  sc.mutable_outputs()->set_flow_threshold_m(1e-3);
  sc.mutable_mesh()->set_first_layer_m(0.5 * c);
  sc.mutable_mesh()->set_growth(1.15);
  sc.mutable_mesh()->set_band_height_m(0.4);
  sc.mutable_vof()->set_write_interval_s(0);
  sc.mutable_vof()->set_max_courant(L.max_courant());
  auto r = jobs::resolve_scenario(sc, out.string());
  const fs::path run_dir = out / "run";
  fs::create_directories(run_dir);
  jobs::run_scenario(r, run_dir.string());

  const auto d = test_support::read_raster_band((run_dir / "deposit.tif").string());
  ChuteFigures f;
  if (d.values.empty()) return f;
  double vol[3] = {0, 0, 0}, vs = 0;
  for (int r = 0; r < d.ny; ++r)
    for (int i = 0; i < d.nx; ++i) {
      const double h = d.at(r, i);
      if (!(h > 1e-3)) continue;  // nodata (NaN, -9999) and the film below 1 mm
      const double x = d.x_centre(i), y = d.y_centre(r), s = w.arc(x, y);
      const double a = w.arc(x + 0.5 * c, y) - w.arc(x - 0.5 * c, y);  // the cell's length along the bed
      const double v = h * a * c;
      vol[s < s1 ? 0 : s <= s2 ? 1 : 2] += v;
      vs += v * s;
      f.from = std::isnan(f.from) ? s : std::min(f.from, s);
      f.to = std::isnan(f.to) ? s : std::max(f.to, s);
      if (s > s2) f.half_width_runout = std::max(f.half_width_runout, std::abs(y) + 0.5 * c);
      if (h > f.highest_depth) f.highest_depth = h, f.highest_s = s;
    }
  const double tot = vol[0] + vol[1] + vol[2];
  f.on_chute = vol[0] / tot, f.in_bend = vol[1] / tot, f.on_runout = vol[2] / tot;
  f.centroid_s = vs / tot;
  const auto j = run_record(run_dir / "run.json");
  f.volume0 = record_figure(j, "volume_on_mesh_m3");
  f.left = record_figure(j, "volume_outflow_m3") / f.volume0;
  return f;
}

void print(const char* what, const ChuteFigures& f) {
  std::printf("%-12s volume %.5f m3; chute/bend/run-out %.2f/%.2f/%.2f; deposit %.2f-%.2f m, half-width on the run-out %.2f m, "
              "highest %.3f m at %.2f m, centroid %.2f m; left %.4f\n",
              what, f.volume0, f.on_chute, f.in_bend, f.on_runout, f.from, f.to, f.half_width_runout, f.highest_depth, f.highest_s,
              f.centroid_s, f.left);
}


// The two runs at cell size c, printed side by side; the DEM path's figures against the chute
// mesh's within bounds in metres (validation.md B8, "through the DEM path", says why they are these):
// the deposit's upper end, its highest point and its centroid within 0.15 / 0.15 / 0.1 m (a quarter
// of the cap's width; the deposit's top is flat, so that its highest point moves with millimetres of
// depth), its far end within `tol_to` (the chute mesh's film over its open side runs further on
// coarse cells, while the DEM path's settles onto the bed: 3.48 against 2.81 m at 5 cm), the half-width on the run-out within 0.1 m, the share on the run-out within 0.15
// and the highest depth within 20 %; less than 10 % leaves the DEM's domain.
void compare(double c, double tol_to) {
  TempDir d;
  const ChuteFigures lab = lab_run(c, d / "lab"), dem = dem_run(c, d / "dem");
  print("chute mesh", lab);
  print("DEM path", dem);
  const double rc = 0.32, hc = 0.22, cap = kPi * hc * hc * (3 * rc - hc) / 3;
  EXPECT_NEAR(dem.volume0, cap, 0.03 * cap);
  EXPECT_NEAR(dem.on_runout, lab.on_runout, 0.15);
  EXPECT_NEAR(dem.from, lab.from, 0.15);
  EXPECT_NEAR(dem.to, lab.to, tol_to);
  EXPECT_NEAR(dem.half_width_runout, lab.half_width_runout, 0.1);
  EXPECT_NEAR(dem.highest_s, lab.highest_s, 0.15);
  EXPECT_NEAR(dem.highest_depth, lab.highest_depth, 0.2 * lab.highest_depth);
  EXPECT_NEAR(dem.centroid_s, lab.centroid_s, 0.1);
  EXPECT_LT(dem.highest_s, dem.centroid_s);
  EXPECT_LT(dem.left, 0.1);
}

}  // namespace

// On one thread (the results are the same on any number): the default suite runs two tests side by
// side, and two threaded runs on two cores wait at OpenMP's barriers (past the 10-minute limit, where
// one thread takes under 3 minutes).
TEST(Scenarios, LabB8ThroughTheDemPathAgreesWithTheAnalyticChute) {
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  compare(0.05, 0.7);
  omp_set_num_threads(threads);
}

// The scenario's 2.5 cm (label full, test vof.b8_dem_full).
TEST(Scenarios, DISABLED_LabB8ThroughTheDemPathAt25mm) { compare(0.025, 0.2); }
