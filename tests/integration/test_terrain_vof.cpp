// The 3D engine on terrain: a block released on a uniform inclined plane (a synthetic DEM turned by
// 0, 30 and 45 deg to the grid) through the terrain driver's mesh, release and configuration
// (validation.md, "3D engine on terrain"): steeper than its bed friction it accelerates at
// g (sin theta - tan delta cos theta) (the material's momentum: the internal forces cancel, the bed's
// friction takes tan delta of the weight's normal part), flatter it stays at rest.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "engine/vof/solver.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/run.hpp"
#include "jobs/formats/run_record.hpp"
#include "jobs/drivers/vof_terrain/config.hpp"
#include "jobs/drivers/vof_terrain/mesh.hpp"
#include "jobs/drivers/vof_terrain/release.hpp"
#include "jobs/drivers/vof_terrain/setup.hpp"
#include "jobs/scenario/options.hpp"
#include "terrain/column_mesh.hpp"
#include "tests/support/local_raster.hpp"
#include "tests/support/temp_dir.hpp"

namespace {

namespace vof = runout::engine::vof;
namespace vt = runout::jobs::vof_terrain;
using runout::terrain::Grid;

constexpr double kPi = 3.14159265358979323846;
const std::filesystem::path kArelen3d = std::filesystem::path(RUNOUT_SOURCE_DIR) / "scenarios" / "in-den-arelen-3d.json";

struct PlaneCase {
  double slope_deg = 35, turn_deg = 0, delta_deg = 20, phi_deg = 40;
  double dx = 10, block_m = 60, thickness_m = 2;
  double taper_m = 0;  ///< the thickness grows from 0 over this much from the block's edges
  int nx = 40, ny = 32;  // turned 45 deg the block's corner lies 47 m from the side
  int refinement = 1;    ///< mesh.refinement: columns per grid cell along each axis
  std::string normal_stress;  ///< vof.bed_normal_stress; empty: the default
  int active_layers = 4;      ///< vof.active_layers (-1: every cell)
  int threads = 0;            ///< OpenMP threads; 0: as they are
};

// A plane falling at slope_deg towards the azimuth turn_deg (0: east, counter-clockwise).
Grid plane_grid(const PlaneCase& pc) {
  Grid g;
  g.nx = pc.nx;
  g.ny = pc.ny;
  g.dx = pc.dx;
  g.x_min = 600000;
  g.y_min = 5100000;
  g.crs_name = "EPSG:32632";
  g.z.resize(g.cells());
  g.outside.assign(g.cells(), 0);
  const double t = std::tan(pc.slope_deg * kPi / 180), a = pc.turn_deg * kPi / 180;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double x = (i + 0.5 - 0.5 * g.nx) * g.dx, y = (j + 0.5 - 0.5 * g.ny) * g.dx;
      g.z[std::size_t(j) * std::size_t(g.nx) + std::size_t(i)] = 2000 - t * (x * std::cos(a) + y * std::sin(a));
    }
  return g;
}

struct PlaneRun {
  double acceleration = 0;  ///< of the material's mean velocity downslope over [0.5, 1] s [m/s2]
  double speed_end = 0;     ///< the material's mean speed at the end [m/s]
  double speed_core = 0;    ///< the same over the columns 10 cells or more from the plane's sides [m/s]
  double exact = 0;         ///< g (sin theta - tan delta cos theta)
  double volume_error = 0;  ///< relative, what left through the sides counted
  double outflow = 0;       ///< relative
  std::vector<double> end_fields;  ///< alpha, the velocity's components and p per cell at the end
  vof::BedLoad load;               ///< what the bed carried at the last step (column friction)
  int footprint_growth = 0;        ///< columns deeper than 1 cm at the end that were not at the start
  int footprint_reach = 0;         ///< of those, the farthest from the start's footprint, in columns
  double reach_m = 0;              ///< the same in metres
  double t0_depth_error = 0;       ///< the hazard maps' depth per grid cell at the start against the release's [m]
};

// The hazard maps integrate each grid cell's columns: the largest difference between their depth
// per grid cell and the release's normal thickness h0 [m].
double start_depth_error(const runout::terrain::ColumnMesh& cm, const vof::Mesh& m, const runout::engine::Terrain2D& t2,
                         const vof::VofSolver& s, const std::vector<double>& h0) {
  const vt::Columns vc = vt::columns_of(cm);
  const vt::ColumnHazard hz(vc, m, runout::engine::SurfaceGeometry::from(t2).c, {});
  const auto d = hz.depth(s);
  double e = 0;
  for (std::size_t k = 0; k < h0.size(); ++k) e = std::max(e, std::abs(d[k] - h0[k]));
  return e;
}

// A square block of normal thickness `thickness_m` whose centre lies a quarter of the plane above its
// centre (upslope), run for `t_end` s.
PlaneRun run_plane(const PlaneCase& pc, double t_end) {
  const Grid g = plane_grid(pc);
  const double th = pc.slope_deg * kPi / 180, a = pc.turn_deg * kPi / 180;
  const runout::engine::Terrain2D t2 = runout::jobs::engine_terrain(g);
  std::vector<double> h0(g.cells(), 0.0);
  const double along0 = -0.25 * pc.nx * pc.dx;  // the block's centre, downslope coordinate
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double x = (i + 0.5 - 0.5 * g.nx) * g.dx, y = (j + 0.5 - 0.5 * g.ny) * g.dx;
      const double along = x * std::cos(a) + y * std::sin(a), across = -x * std::sin(a) + y * std::cos(a);
      const double inside = 0.5 * pc.block_m - std::max(std::abs(along - along0), std::abs(across));  // to the nearest edge
      if (inside > 0)
        h0[std::size_t(j) * std::size_t(g.nx) + std::size_t(i)] = pc.thickness_m * (pc.taper_m > 0 ? std::min(1.0, inside / pc.taper_m) : 1.0);
    }
  const auto vertical = runout::engine::state_from_normal_depth(t2, h0).H;
  auto spec = vt::default_column_mesh(pc.thickness_m / std::cos(th));
  spec.refinement = pc.refinement;
  const auto cm = runout::terrain::column_mesh(g, spec);
  const auto frame = vt::frame_of(cm);
  const vof::Mesh m = vt::terrain_mesh(cm, frame);
  const auto alpha = vt::release_alpha(cm, vertical);
  runout::jobs::ResolvedScenario r;
  r.scenario.set_engine("vof");
  r.scenario.mutable_material()->set_density_kg_m3(300);
  r.scenario.mutable_material()->set_internal_friction_deg(pc.phi_deg);
  r.scenario.mutable_material()->set_bed_friction_deg(pc.delta_deg);
  if (!pc.normal_stress.empty()) r.scenario.mutable_vof()->set_bed_normal_stress(pc.normal_stress);
  r.scenario.mutable_vof()->set_active_layers(pc.active_layers);
  const int threads_before = omp_get_max_threads();
  if (pc.threads > 0) omp_set_num_threads(pc.threads);
  runout::jobs::apply_option_rules(runout::jobs::terrain_vof_options(), r.scenario);
  const vof::MeshColumns cols = vt::bed_columns(vt::columns_of(cm), m, g);
  vof::VofSolver s(m, vt::terrain_config(r, cols));
  s.initialise(alpha);
  // Downslope in the engine's frame (x east, y up, z south).
  const vof::Vec down{std::cos(th) * std::cos(a), -std::sin(th), -std::cos(th) * std::sin(a)};
  // The material's mean velocity over the cells `in` takes (all by default).
  auto mean_velocity = [&](const std::function<bool(const vof::Vec&)>& in = nullptr) {
    vof::Vec mom;
    double vol = 0;
    for (int c = 0; c < m.cells(); ++c) {
      if (in && !in(m.centre[std::size_t(c)])) continue;
      const double w = s.alpha()[std::size_t(c)] * m.volume[std::size_t(c)];
      mom = mom + w * s.velocity()[std::size_t(c)];
      vol += w;
    }
    return vol > 0 ? (1.0 / vol) * mom : vof::Vec{};
  };
  double v0 = 0;
  for (int c = 0; c < m.cells(); ++c) v0 += alpha[std::size_t(c)] * m.volume[std::size_t(c)];
  PlaneRun out;
  out.t0_depth_error = start_depth_error(cm, m, t2, s, h0);  // before the first step
  // Material that leaves through the plane's sides (thin fast edges, turned 45 deg) is counted.
  double outflow = 0;
  auto count_outflow = [&](const vof::StepStats& st) {
    for (int f = m.n_internal; f < m.faces(); ++f) outflow += s.granular_flux()[std::size_t(f)] * st.dt;
    return true;
  };
  s.run(0.5, count_outflow);
  const double t1 = s.time(), u1 = dot(mean_velocity(), down);
  s.run(t_end, count_outflow);
  const vof::Vec u = mean_velocity();
  out.acceleration = (dot(u, down) - u1) / (s.time() - t1);
  out.speed_end = norm(u);
  const double hx = 0.5 * pc.nx * pc.dx - 10 * pc.dx, hz = 0.5 * pc.ny * pc.dx - 10 * pc.dx;
  out.speed_core = norm(mean_velocity([&](const vof::Vec& x) { return std::abs(x.x) <= hx && std::abs(x.z) <= hz; }));
  out.exact = 9.81 * (std::sin(th) - std::tan(pc.delta_deg * kPi / 180) * std::cos(th));
  double v1 = 0;
  for (int c = 0; c < m.cells(); ++c) v1 += s.alpha()[std::size_t(c)] * m.volume[std::size_t(c)];
  out.volume_error = std::abs(v1 + outflow - v0) / v0;
  for (int c = 0; c < m.cells(); ++c) {
    const vof::Vec& U = s.velocity()[std::size_t(c)];
    out.end_fields.insert(out.end_fields.end(), {s.alpha()[std::size_t(c)], U.x, U.y, U.z, s.pressure()[std::size_t(c)]});
  }
  out.load = s.bed_load();
  // The footprint: columns holding more than 1 cm of material, at the start and at the end.
  auto footprint = [&](const std::vector<double>& a) {
    std::vector<vof::Vec> at;
    for (int k = 0; k < cols.columns(); ++k) {
      double v = 0;
      for (int i = cols.start[std::size_t(k)]; i < cols.start[std::size_t(k) + 1]; ++i)
        v += a[std::size_t(cols.cells[std::size_t(i)])] * m.volume[std::size_t(cols.cells[std::size_t(i)])];
      if (v > 0.01 * cm.dx * cm.dx) at.push_back(m.Cf[std::size_t(cols.bed_face[std::size_t(k)])]);
    }
    return at;
  };
  const auto before = footprint(alpha), after = footprint(s.alpha());
  for (const vof::Vec& x : after) {
    double nearest = 1e30;
    for (const vof::Vec& y : before) nearest = std::min(nearest, std::hypot(x.x - y.x, x.z - y.z));
    if (nearest > 0.5 * cm.dx) {
      ++out.footprint_growth;
      out.footprint_reach = std::max(out.footprint_reach, int(std::lround(nearest / cm.dx)));
      out.reach_m = std::max(out.reach_m, nearest);
    }
  }
  omp_set_num_threads(threads_before);
  out.outflow = outflow / v0;
  return out;
}

}  // namespace

// The material's momentum grows at the Coulomb rate whatever the plane's orientation to the grid:
// the friction takes the column's weight (vof.bed_normal_stress "column", the default), whose
// bed-normal part it carries whole. Measured: 1.020 / 1.008 / 0.966 of g (sin(theta) - tan(delta)
// cos(theta)) turned 0 / 30 / 45 deg; frictionless 0.98 / 0.97 of g sin(theta) (validation.md D1).
// The bounds fail when the friction or the non-orthogonal correction goes missing (1.6-2.1 x) or the
// load falls back to the ground cell's pressure (1.16-1.23 x).
TEST(TerrainVof, BlockOnAnInclinedPlaneAcceleratesAtTheCoulombRate) {
  for (double turn : {0.0, 30.0, 45.0}) {
    PlaneCase pc;
    pc.turn_deg = turn;
    const PlaneRun r = run_plane(pc, 1.0);
    std::printf("35 deg plane turned %.0f deg, delta 20: acceleration %.3f m/s2 = %.3f x exact; friction load / weight's normal part %.3f; "
                "volume error %.1e, outflow %.1e\n",
                turn, r.acceleration, r.acceleration / r.exact, r.load.friction_load / r.load.weight_normal, r.volume_error, r.outflow);
    EXPECT_NEAR(r.acceleration / r.exact, 1.0, 0.05);
    EXPECT_NEAR(r.load.friction_load / r.load.weight_normal, 1.0, 1e-9);
    EXPECT_LT(r.volume_error, 1e-6);
  }
  // Along the grid on columns of 5 m (mesh.refinement 2): 1.009 x exact (1.031 on 10 m columns).
  PlaneCase refined;
  refined.refinement = 2;
  const PlaneRun rr = run_plane(refined, 1.0);
  std::printf("35 deg plane, delta 20, 5 m columns (refinement 2): %.3f x exact\n", rr.acceleration / rr.exact);
  EXPECT_NEAR(rr.acceleration / rr.exact, 1.0, 0.03);
  for (double turn : {0.0, 45.0}) {
    PlaneCase pc;
    pc.turn_deg = turn;
    pc.delta_deg = 0;
    const PlaneRun r = run_plane(pc, 1.0);
    std::printf("35 deg plane turned %.0f deg, frictionless: acceleration %.3f x g sin(theta)\n", turn, r.acceleration / r.exact);
    EXPECT_NEAR(r.acceleration / r.exact, 1.0, 0.04);
  }
}

// The other loads the friction can take: the ground cell's pressure ("pressure") carries 0.85-0.87
// of the weight's normal part in the sliding block (the rest in viscous normal stress) and the
// block runs 1.16-1.23 x the exact rate; the total normal stress ("total", p less the viscous normal
// stress) is near it (docs/design/vof.md, "The bed friction's load").
TEST(TerrainVof, FrictionOnTheGroundCellsPressureOrTotalNormalStress) {
  for (const char* load : {"pressure", "total"}) {
    PlaneCase pc;
    pc.normal_stress = load;
    const PlaneRun r = run_plane(pc, 1.0);
    std::printf("35 deg plane, delta 20, load \"%s\": %.3f x exact\n", load, r.acceleration / r.exact);
    if (std::string(load) == "pressure") {
      EXPECT_GT(r.acceleration / r.exact, 1.08);
      EXPECT_LT(r.acceleration / r.exact, 1.3);
    } else {
      EXPECT_NEAR(r.acceleration / r.exact, 1.0, 0.2);
    }
  }
}

// Blocks flatter than their bed friction (15 deg, delta 20, phi 30, 10 m columns): the body rests
// but the edges, vertical steps one column wide, slump into the next columns, and the material's
// mean speed after 2 s is 0.10-0.11 m/s (5 m/s without friction), its footprint grown by up to three
// columns. Tapering the edges over two columns changes nothing. The slump is the material's: on
// cells that resolve the edge both engines let it run out 15-20 m (the next test).
TEST(TerrainVof, BlockFlatterThanItsBedFrictionIsHeld) {
  for (double taper : {0.0, 20.0}) {
    PlaneCase pc;
    pc.slope_deg = 15;
    pc.phi_deg = 30;
    pc.taper_m = taper;
    const PlaneRun r = run_plane(pc, 2.0);
    std::printf("15 deg plane, block with edges tapered over %.0f m, delta 20: mean speed %.2e m/s after 2 s (%.2e m/s without friction); "
                "footprint grown by %d columns, the farthest %d columns out\n",
                taper, r.speed_end, 2 * 9.81 * std::sin(15 * kPi / 180), r.footprint_growth, r.footprint_reach);
    EXPECT_LT(r.speed_end, 0.15);
    EXPECT_LE(r.footprint_reach, 3);
    EXPECT_LT(r.volume_error, 1e-6);
  }
}

// The same block on columns of 2.5 m (the 10 m grid with mesh.refinement 4) beside the
// depth-averaged engine on cells of 2.5 m, both to 8 s: its vertical edges are a Coulomb material's
// step 2 m high on a slope 5 deg flatter than the bed friction, and both engines let the downslope
// edge slump out 15-20 m (the depth-averaged engine holds the block whole on 10 m cells only because
// one cell's step hides the edge's gradient; on 5 m cells it slumps too). Measured: the 3D footprint
// 17.5-20 m out, the depth-averaged 20 m; the depth-averaged block at rest (4e-6 m/s), the 3D one
// still creeping at 6e-3 m/s (docs/validation/validation.md D1).
TEST(TerrainVof, RefinedBlockSlumpsAsTheDepthAveragedOneOnTheSameCells) {
  PlaneCase pc;
  pc.slope_deg = 15;
  pc.phi_deg = 30;
  pc.refinement = 4;
  const PlaneRun r = run_plane(pc, 8.0);
  // The depth-averaged engine on the same plane at 2.5 m, the same block.
  PlaneCase fine = pc;
  fine.dx = 2.5;
  fine.nx = 4 * pc.nx;
  fine.ny = 4 * pc.ny;
  const Grid g = plane_grid(fine);
  const runout::engine::Terrain2D t2 = runout::jobs::engine_terrain(g);
  std::vector<double> h0(g.cells(), 0.0);
  std::vector<std::size_t> start;
  const double along0 = -0.25 * pc.nx * pc.dx;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double x = (i + 0.5 - 0.5 * g.nx) * g.dx, y = (j + 0.5 - 0.5 * g.ny) * g.dx;
      if (std::max(std::abs(x - along0), std::abs(y)) < 0.5 * pc.block_m) {
        h0[std::size_t(j) * std::size_t(g.nx) + std::size_t(i)] = pc.thickness_m;
        start.push_back(std::size_t(j) * std::size_t(g.nx) + std::size_t(i));
      }
    }
  runout::engine::Sh2dConfig cfg;
  cfg.material.delta = pc.delta_deg * kPi / 180;
  cfg.material.phi = pc.phi_deg * kPi / 180;
  cfg.time.t_end = 8.0;
  cfg.time.stop_fraction = 0;
  const auto res = runout::engine::run_sh2d(t2, cfg, runout::engine::state_from_normal_depth(t2, h0));
  double H = 0, HU = 0, HV = 0, reach = 0;
  for (std::size_t k = 0; k < g.cells(); ++k) {
    H += res.state.H[k];
    HU += res.state.HU[k];
    HV += res.state.HV[k];
    if (res.state.H[k] * std::cos(pc.slope_deg * kPi / 180) <= 0.01 || h0[k] > 0) continue;
    double nearest = 1e30;
    for (std::size_t q : start)
      nearest = std::min(nearest, g.dx * std::hypot(double(int(k % g.nx) - int(q % g.nx)), double(int(k / g.nx) - int(q / g.nx))));
    reach = std::max(reach, nearest);
  }
  const double speed_2d = std::hypot(HU, HV) / H;
  std::printf("15 deg plane, block, delta 20, at 8 s on 2.5 m: 3D (10 m grid, refinement 4) mean speed %.2e m/s, footprint %.1f m out; "
              "depth-averaged %.2e m/s, %.1f m out\n",
              r.speed_end, r.reach_m, speed_2d, reach);
  EXPECT_GT(reach, 10.0);  // the depth-averaged block slumps on these cells
  EXPECT_LT(speed_2d, 1e-3);
  EXPECT_NEAR(r.reach_m, reach, 5.0);
  EXPECT_LT(r.speed_end, 1e-2);
  EXPECT_LT(r.volume_error, 1e-6);
  EXPECT_LT(r.t0_depth_error, 1e-9);  // the maps integrate each 10 m cell's 16 columns
}

// A layer over the whole plane (no edges, 2 m on 15 deg, delta 20): on the column's weight (the
// default) the bed holds it at rest, 10 columns from the sides below 1 mm/s after 2 s, on the plane
// turned 30 deg too. On the ground cell's pressure what moves is the creep of the Coulomb
// viscosity's clip, a film sheared at nu_max over a stuck bed, whose mean speed is
// g sin(theta) h^2 / (3 nu_max) (3.4 cm/s at the default 1e2: 2.7 cm/s measured).
TEST(TerrainVof, LayerFlatterThanItsBedFrictionStaysAtRest) {
  PlaneCase pc;
  pc.slope_deg = 15;
  pc.phi_deg = 30;
  pc.block_m = 5000;
  for (double turn : {0.0, 30.0}) {
    pc.turn_deg = turn;
    const PlaneRun r = run_plane(pc, 2.0);
    std::printf("15 deg plane turned %.0f deg, layer, delta 20: mean speed %.2e m/s after 2 s (%.2e m/s 10 cells from the sides)\n", turn,
                r.speed_end, r.speed_core);
    EXPECT_LT(r.speed_core, 1e-3);
  }
  const double creep = 9.81 * std::sin(15 * kPi / 180) * 2 * 2 / 3;  // times 1 / nu_max
  pc.turn_deg = 0;
  pc.normal_stress = "pressure";
  const PlaneRun soft = run_plane(pc, 2.0);
  std::printf("15 deg plane, layer, delta 20, ground cell's pressure: %.2e m/s 10 cells from the sides (creep %.2e m/s)\n", soft.speed_core,
              creep / 1e2);
  EXPECT_GT(soft.speed_core, 0.5 * creep / 1e2);
  EXPECT_LT(soft.speed_core, 1.0 * creep / 1e2);
}

// In den Arelen through the whole terrain path on a coarse grid (90 m, 5 s): every raster of the
// depth-averaged engine plus the 3D engine's, the georeferenced frames and the run record with the
// mesh quality, the volumes, the alpha bounds and the profile at the farmhouse.
TEST(TerrainVof, ArelenCoarseRunWritesTheHazardMapsFramesAndRecord) {
  namespace fs = std::filesystem;
  auto sc = runout::jobs::parse_scenario_json(runout::test_support::read_text(kArelen3d));
  sc.mutable_grid()->set_resolution_m(90);
  sc.mutable_numerics()->set_end_time_s(5);
  sc.mutable_vof()->set_write_interval_s(2.5);
  const auto r = runout::jobs::resolve_scenario(sc, kArelen3d.parent_path().string());
  ASSERT_EQ(r.engine, runout::jobs::kVofTerrainEngine);
  runout::test_support::TempDir d;
  const auto sum = runout::jobs::run_scenario(r, d.p.string());
  for (const char* f : {"max_depth.tif", "max_speed.tif", "max_pressure.tif", "deposit.tif", "arrival_time.tif", "outline.geojson", "outline.gpkg",
                        "map_max_depth.png", "map_pressure_zones.pdf", "pressure_zones.tif", "max_surface_speed.tif", "max_ground_stress.tif", "fields.h5", "fields.xmf", "run.json"})
    EXPECT_TRUE(fs::is_regular_file(d.p / f)) << f;
  const auto rec = runout::jobs::read_run_record((d.p / "run.json").string());
  EXPECT_EQ(rec.engine(), "vof");
  const auto& tm = rec.terrain_mesh();
  EXPECT_EQ(tm.cells(), tm.columns() * tm.layers());
  EXPECT_GT(tm.non_orthogonality_max_deg(), 10);  // a mountain slope
  EXPECT_GT(tm.aspect_ratio_max(), 1);
  EXPECT_NEAR(rec.release().volume_on_mesh_m3() / rec.release().volume_m3(), 1.0, 0.01);
  EXPECT_LT(rec.mass_balance().relative_error(), 1e-6);
  // The mesh follows the depth-averaged engine's footprint with the default margin (two cells of 90 m).
  EXPECT_EQ(tm.corridor(), "footprint");
  EXPECT_EQ(tm.corridor_margin_m(), 180);
  EXPECT_EQ(tm.domain_columns(), 1371);
  EXPECT_LT(tm.columns(), tm.domain_columns());
  EXPECT_GT(tm.columns(), tm.footprint_columns());
  EXPECT_GT(tm.footprint_columns(), 0);
  EXPECT_LE(tm.corridor_outflow_m3() + tm.domain_edge_outflow_m3(), rec.mass_balance().volume_outflow_m3() + 1e-9);
  EXPECT_GE(rec.solver().alpha_min(), -1e-6);
  EXPECT_LE(rec.solver().alpha_max(), 1 + 1e-6);
  EXPECT_EQ(rec.results().frames(), 3);
  EXPECT_GT(rec.results().max_depth_m(), 0.5);
  ASSERT_EQ(rec.profiles_size(), 1);
  EXPECT_EQ(rec.profiles(0).name(), "farmhouse");
  EXPECT_EQ(rec.profiles(0).profile_height_alpha_speed_size() == 0 || rec.profiles(0).profile_height_alpha_speed_size() == tm.layers(), true);
  // The frames lie in the grid's CRS (Float64 centres): east and north inside the grid.
  EXPECT_NE(runout::test_support::read_text(d.p / "fields.xmf").find("Precision=\"8\" Format=\"HDF\">fields.h5:/centres"), std::string::npos);
  std::printf("Arelen at 90 m, 5 s: %d of %d columns, %d cells, %ld steps, %.1f s run; volume error %.1e, outflow %.0f m3, runout %.0f m\n",
              tm.columns(), tm.domain_columns(), tm.cells(), sum.steps, sum.seconds_run, sum.volume_error, sum.volume_outflow, sum.runout_m);
}

// In den Arelen on refined columns (90 m grid, mesh.refinement 2, 2 s): four columns per grid cell,
// run.json's refinement, column width and reason, the release's volume, the volume balance, the
// farmhouse's profile from its own column, and the rasters on the scenario's grid.
TEST(TerrainVof, ArelenRefinedRunMapsItsColumnsOnTheGrid) {
  auto sc = runout::jobs::parse_scenario_json(runout::test_support::read_text(kArelen3d));
  sc.mutable_grid()->set_resolution_m(90);
  sc.mutable_numerics()->set_end_time_s(2);
  sc.mutable_vof()->set_write_interval_s(0);
  sc.mutable_mesh()->set_refinement(2);
  const auto r = runout::jobs::resolve_scenario(sc, kArelen3d.parent_path().string());
  runout::test_support::TempDir d;
  const auto sum = runout::jobs::run_scenario(r, d.p.string());
  const auto rec = runout::jobs::read_run_record((d.p / "run.json").string());
  const auto& tm = rec.terrain_mesh();
  EXPECT_EQ(tm.refinement(), 2);
  EXPECT_EQ(tm.column_width_m(), 45);
  EXPECT_EQ(tm.refinement_reason(), "mesh.refinement 2");
  EXPECT_EQ(tm.domain_columns(), 4 * 1371);
  EXPECT_EQ(tm.columns() % 4, 0);
  EXPECT_EQ(tm.cells(), tm.columns() * tm.layers());
  EXPECT_NEAR(rec.release().volume_on_mesh_m3() / rec.release().volume_m3(), 1.0, 0.01);
  EXPECT_LT(rec.mass_balance().relative_error(), 1e-6);
  ASSERT_EQ(rec.profiles_size(), 1);
  const auto band = runout::test_support::read_raster_band((d.p / "max_depth.tif").string());
  EXPECT_EQ(band.nx, rec.grid().nx());
  EXPECT_EQ(band.ny, rec.grid().ny());
  EXPECT_NEAR(band.gt[1], 90, 1e-9);
  double deepest = 0;  // over the cells with data
  for (double v : band.values)
    if (std::isfinite(v)) deepest = std::max(deepest, v);
  EXPECT_NEAR(deepest, rec.results().max_depth_m(), 1e-6);
  std::printf("Arelen at 90 m, refinement 2, 2 s: %d columns, %d cells, %ld steps, %.1f s run; max depth %.2f m\n", tm.columns(), tm.cells(),
              sum.steps, sum.seconds_run, rec.results().max_depth_m());
}

// A corridor polygon (mesh.corridor "polygon") must hold the release: one around the farmhouse,
// below the release, is refused naming the field and the file; the area of interest as the corridor
// keeps every column of the domain and the release's volume.
TEST(TerrainVof, CorridorPolygonMustHoldTheRelease) {
  namespace fs = std::filesystem;
  runout::test_support::TempDir d;
  const auto square = d.p / "farmhouse.geojson";
  {
    std::ofstream f(square);
    f << R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":{"type":"Polygon",)"
         R"("coordinates":[[[9.850,46.834],[9.858,46.834],[9.858,46.839],[9.850,46.839],[9.850,46.834]]]}}]})";
  }
  auto sc = runout::jobs::parse_scenario_json(runout::test_support::read_text(kArelen3d));
  sc.mutable_grid()->set_resolution_m(90);
  sc.mutable_mesh()->set_corridor("polygon");
  sc.mutable_mesh()->set_corridor_path(square.string());
  const auto r = runout::jobs::resolve_scenario(sc, kArelen3d.parent_path().string());
  try {
    vt::TerrainSetup su;
    vt::build_terrain_setup(r, su);
    ADD_FAILURE() << "a corridor without the release was accepted";
  } catch (const std::exception& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("mesh.corridor_path"), std::string::npos) << m;
    EXPECT_NE(m.find("farmhouse.geojson"), std::string::npos) << m;
    EXPECT_NE(m.find("release cell(s) out"), std::string::npos) << m;
  }
  sc.mutable_mesh()->set_corridor_path((kArelen3d.parent_path() / "data" / "arelen" / "aoi.geojson").string());
  vt::TerrainSetup su;
  vt::build_terrain_setup(runout::jobs::resolve_scenario(sc, kArelen3d.parent_path().string()), su);
  EXPECT_EQ(su.corridor.kind, "polygon");
  EXPECT_EQ(su.columns_mesh.kept_columns(), su.domain_columns);
  EXPECT_NEAR(su.volume_on_mesh / su.release.volume_m3, 1.0, 0.01);
  // The footprint corridor on the same grid: fewer columns, the same volume on the mesh.
  sc.mutable_mesh()->set_corridor("footprint");
  sc.mutable_mesh()->clear_corridor_path();
  vt::TerrainSetup fp;
  vt::build_terrain_setup(runout::jobs::resolve_scenario(sc, kArelen3d.parent_path().string()), fp);
  EXPECT_LT(fp.columns_mesh.kept_columns(), su.columns_mesh.kept_columns());
  EXPECT_DOUBLE_EQ(fp.volume_on_mesh, su.volume_on_mesh);
  int corridor_edge = 0;
  for (auto e : fp.corridor_edge) corridor_edge += e;
  EXPECT_GT(corridor_edge, 0);
}

// Material that leaves through the corridor's edge is counted apart from the domain's edge and, above
// 2 % of the released volume, run.json's notes say that the map is not complete: the release's own
// cells as the corridor polygon (in the grid's CRS; 90 m, 5 s).
TEST(TerrainVof, MaterialLeavingTheCorridorIsReported) {
  auto sc = runout::jobs::parse_scenario_json(runout::test_support::read_text(kArelen3d));
  sc.mutable_grid()->set_resolution_m(90);
  sc.mutable_numerics()->set_end_time_s(5);
  sc.mutable_vof()->set_write_interval_s(0);
  sc.mutable_vof()->clear_profiles();
  runout::test_support::TempDir d;
  const auto cells = d.p / "release-cells.geojson";
  {
    auto none = sc;
    none.mutable_mesh()->set_corridor("none");
    vt::TerrainSetup su;
    vt::build_terrain_setup(runout::jobs::resolve_scenario(none, kArelen3d.parent_path().string()), su);
    const auto& g = su.grid;
    std::ofstream f(cells);
    f << R"({"type":"FeatureCollection","crs":{"type":"name","properties":{"name":")" << g.crs_name << R"("}},"features":[)";
    bool first = true;
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        if (!(su.h0[std::size_t(j) * std::size_t(g.nx) + std::size_t(i)] > 0)) continue;
        const double x0 = g.x_min + i * g.dx + 1, x1 = x0 + g.dx - 2, y0 = g.y_min + j * g.dx + 1, y1 = y0 + g.dx - 2;
        f << (first ? "" : ",") << R"({"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[)";
        f.precision(12);
        f << "[" << x0 << "," << y0 << "],[" << x1 << "," << y0 << "],[" << x1 << "," << y1 << "],[" << x0 << "," << y1 << "],[" << x0 << "," << y0
          << "]]]}}";
        first = false;
      }
    f << "]}";
  }
  sc.mutable_mesh()->set_corridor("polygon");
  sc.mutable_mesh()->set_corridor_path(cells.string());
  const auto r = runout::jobs::resolve_scenario(sc, kArelen3d.parent_path().string());
  runout::jobs::run_scenario(r, d.p.string());
  const auto rec = runout::jobs::read_run_record((d.p / "run.json").string());
  const auto& tm = rec.terrain_mesh();
  EXPECT_EQ(tm.corridor(), "polygon");
  EXPECT_NE(tm.corridor_path().find("release-cells.geojson"), std::string::npos);
  const double released = rec.release().volume_on_mesh_m3();
  std::printf("the release's cells as the corridor: %d of %d columns; through the corridor's edge %.0f m3 (%.1f %%), the domain's %.0f m3, all %.0f m3\n",
              tm.columns(), tm.domain_columns(), tm.corridor_outflow_m3(), 100 * tm.corridor_outflow_m3() / released,
              tm.domain_edge_outflow_m3(), rec.mass_balance().volume_outflow_m3());
  EXPECT_GT(tm.corridor_outflow_m3(), 0.02 * released);
  EXPECT_LE(tm.corridor_outflow_m3() + tm.domain_edge_outflow_m3(), rec.mass_balance().volume_outflow_m3() + 1e-9);
  ASSERT_EQ(rec.notes_size(), 1);
  EXPECT_NE(rec.notes(0).find("the map is not complete"), std::string::npos) << rec.notes(0);
  EXPECT_NE(rec.notes(0).find("corridor's edge"), std::string::npos) << rec.notes(0);
}

// The 3D engine's options on the DEM are checked before anything runs, each error naming its field.
TEST(TerrainVof, BadOptionsAreNamed) {
  const auto base = runout::jobs::parse_scenario_json(runout::test_support::read_text(kArelen3d));
  auto message = [&](const std::function<void(runout::v1::Scenario&)>& change) {
    auto s = base;
    change(s);
    try {
      runout::jobs::resolve_scenario(s, kArelen3d.parent_path().string());
    } catch (const runout::jobs::ScenarioError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([](auto& s) { s.mutable_material()->set_rheology("voellmy"); }).find("material.rheology"), std::string::npos);
  EXPECT_NE(message([](auto& s) { s.mutable_material()->clear_internal_friction_deg(); }).find("material.internal_friction_deg"), std::string::npos);
  // mu(I): its parameters are needed (as the depth-averaged mu_i law needs them) and must join.
  auto mu_i = [](runout::v1::Scenario& s) {
    auto* m = s.mutable_material();
    m->set_rheology("mu_i");
    m->set_density_kg_m3(1470);
    m->set_mu_s(0.38);
    m->set_mu_2(0.64);
    m->set_mu_i0(0.279);
    m->set_grain_diameter_m(5e-4);
    m->set_grain_density_kg_m3(2450);
  };
  EXPECT_EQ(message(mu_i), "no error");
  EXPECT_NE(message([&](auto& s) {
              mu_i(s);
              s.mutable_material()->clear_mu_i0();
            }).find("material.mu_i0"),
            std::string::npos);
  EXPECT_NE(message([&](auto& s) {
              mu_i(s);
              s.mutable_material()->set_mu_2(0.381);
            }).find("material.mu_2: mu(I): the regularisation cannot join"),
            std::string::npos);
  EXPECT_NE(message([](auto& s) { s.mutable_mesh()->set_growth(5); }).find("mesh.growth"), std::string::npos);
  EXPECT_NE(message([](auto& s) {
              s.mutable_mesh()->set_first_layer_m(2);
              s.mutable_mesh()->set_band_height_m(1);
            }).find("mesh.band_height_m"),
            std::string::npos);
  EXPECT_NE(message([](auto& s) { s.mutable_vof()->set_bed("ice"); }).find("vof.bed"), std::string::npos);
  EXPECT_NE(message([](auto& s) { s.mutable_mesh()->set_corridor("road"); }).find("mesh.corridor"), std::string::npos);
  EXPECT_NE(message([](auto& s) { s.mutable_mesh()->set_corridor("polygon"); }).find("mesh.corridor_path: missing"), std::string::npos);
  EXPECT_NE(message([](auto& s) { s.mutable_mesh()->set_corridor_path("data/arelen/aoi.geojson"); }).find("mesh.corridor_path: only with"),
            std::string::npos);
  EXPECT_NE(message([](auto& s) {
              s.mutable_mesh()->set_corridor("none");
              s.mutable_mesh()->set_corridor_margin_m(100);
            }).find("mesh.corridor_margin_m: only with"),
            std::string::npos);
  EXPECT_NE(message([](auto& s) { s.mutable_mesh()->set_corridor_margin_m(-1); }).find("mesh.corridor_margin_m"), std::string::npos);
  EXPECT_NE(message([](auto& s) {
              s.mutable_mesh()->set_corridor("polygon");
              s.mutable_mesh()->set_corridor_path("data/arelen/no-such-corridor.geojson");
            }).find("mesh.corridor_path"),
            std::string::npos);
  EXPECT_NE(message([](auto& s) { s.mutable_vof()->mutable_profiles(0)->clear_name(); }).find("vof.profiles[0].name"), std::string::npos);
  EXPECT_NE(message([](auto& s) { s.set_engine("depth-averaged"); }).find("vof: only for engine \"vof\""), std::string::npos);
  // A point outside the domain is refused when the run prepares its grid.
  auto s = base;
  s.mutable_grid()->set_resolution_m(90);
  s.mutable_vof()->mutable_profiles(0)->set_x(8.0);
  const auto r = runout::jobs::resolve_scenario(s, kArelen3d.parent_path().string());
  runout::test_support::TempDir d;
  try {
    runout::jobs::run_scenario(r, d.p.string());
    ADD_FAILURE() << "a profile point outside the grid was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("vof.profiles[0]: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("outside the grid"), std::string::npos) << e.what();
  }
}

// The engine's loops run over the OpenMP threads, and each result is the same bit for bit for any
// thread count (engine/vof/fv/parallel.hpp): the block on the plane with every cell computed
// (16,640 cells, enough for the loops to split) for 0.5 s on 1, 2 and 3 threads.
TEST(TerrainVof, ResultsDoNotDependOnTheThreadCount) {
  std::vector<double> fields[3];
  for (int k = 0; k < 3; ++k) {
    PlaneCase pc;
    pc.active_layers = -1;
    pc.threads = k + 1;
    fields[k] = run_plane(pc, 0.5).end_fields;
  }
  ASSERT_FALSE(fields[0].empty());
  for (int k = 1; k < 3; ++k) {
    ASSERT_EQ(fields[k].size(), fields[0].size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < fields[0].size(); ++i)
      if (std::memcmp(&fields[k][i], &fields[0][i], sizeof(double)) != 0) ++differ;
    EXPECT_EQ(differ, 0u) << k + 1 << " threads against 1";
  }
}

