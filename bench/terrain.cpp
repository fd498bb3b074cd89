// The 3D engine on terrain: cost per step against the material, on two domain sizes.
//
//   runout_bench_terrain [--end T] [--pc ilu|gamg]
//
// The same block (60 m square, 2 m thick, phi 40, delta 20) released on a 35 deg plane (10 m
// columns) through the terrain driver's mesh, release and configuration (the scenario defaults of
// the `mesh` and `vof` blocks), on a plane of 40 x 32 columns and one of 80 x 64, run to T (default
// 1 s). Printed per domain: cells, active cells (mean over the steps), steps, microseconds per
// cell-step and per active cell-step, the share of the pressure correctors and of the pressure
// solves in the step, wall time and threads. With the active region the cost per step follows the
// active cells, not the mesh (docs/design/performance.md, "3D engine on terrain"). Threads: OMP_NUM_THREADS.
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "engine/vof/solver.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/vof_terrain/config.hpp"
#include "jobs/drivers/vof_terrain/mesh.hpp"
#include "jobs/drivers/vof_terrain/release.hpp"
#include "jobs/scenario/options.hpp"
#include "terrain/column_mesh.hpp"

namespace {

namespace vof = runout::engine::vof;
namespace vt = runout::jobs::vof_terrain;

constexpr double kPi = 3.14159265358979323846;

struct Row {
  int nx = 0, ny = 0, cells = 0, steps = 0;
  double active_mean = 0, wall_s = 0, pressure_s = 0, solve_s = 0;
};

Row run(int nx, int ny, double t_end, const std::string& pc) {
  const double slope = 35 * kPi / 180, dx = 10, block = 60, thickness = 2;
  runout::terrain::Grid g;
  g.nx = nx;
  g.ny = ny;
  g.dx = dx;
  g.x_min = 600000;
  g.y_min = 5100000;
  g.crs_name = "EPSG:32632";
  g.z.resize(g.cells());
  g.outside.assign(g.cells(), 0);
  std::vector<double> h0(g.cells(), 0.0);
  // The block's centre 100 m upslope (west) of the plane's centre, whatever the plane's size.
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = (i + 0.5 - 0.5 * nx) * dx, y = (j + 0.5 - 0.5 * ny) * dx;
      const std::size_t k = std::size_t(j) * std::size_t(nx) + std::size_t(i);
      g.z[k] = 2000 - std::tan(slope) * x;
      if (std::abs(x + 100) < 0.5 * block && std::abs(y) < 0.5 * block) h0[k] = thickness;
    }
  const auto t2 = runout::jobs::engine_terrain(g);
  const auto vertical = runout::engine::state_from_normal_depth(t2, h0).H;
  const auto cm = runout::terrain::column_mesh(g, vt::default_column_mesh(thickness / std::cos(slope)));
  const vof::Mesh m = vt::terrain_mesh(cm, vt::frame_of(cm));
  runout::jobs::ResolvedScenario r;
  r.scenario.set_engine("vof");
  r.scenario.mutable_material()->set_density_kg_m3(300);
  r.scenario.mutable_material()->set_internal_friction_deg(40);
  r.scenario.mutable_material()->set_bed_friction_deg(20);
  r.scenario.mutable_vof()->set_pressure_preconditioner(pc);
  runout::jobs::apply_option_rules(runout::jobs::terrain_vof_options(), r.scenario);
  vof::VofSolver s(m, vt::terrain_config(r, vt::bed_columns(vt::columns_of(cm), m, g)));
  s.initialise(vt::release_alpha(cm, vertical));
  Row row;
  row.nx = nx;
  row.ny = ny;
  row.cells = m.cells();
  const auto t0 = std::chrono::steady_clock::now();
  s.run(t_end, [&](const vof::StepStats& st) {
    ++row.steps;
    row.active_mean += st.active_cells;
    row.pressure_s += st.seconds_pressure;
    row.solve_s += st.seconds_pressure_solve;
    return true;
  });
  row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  row.active_mean /= std::max(1, row.steps);
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  double t_end = 1.0;
  std::string pc = "ilu";
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--end") && i + 1 < argc) {
      t_end = std::atof(argv[++i]);
    } else if (!std::strcmp(argv[i], "--pc") && i + 1 < argc) {
      pc = argv[++i];
    } else {
      std::fprintf(stderr, "usage: runout_bench_terrain [--end T] [--pc ilu|gamg]\n");
      return 2;
    }
  }
  const int threads = omp_get_max_threads();  // OMP_NUM_THREADS (loops under 4,096 elements stay serial)
  std::printf("block 60 m x 2 m on a 35 deg plane, 10 m columns, to %.2f s, pressure preconditioner %s, %d threads\n\n", t_end, pc.c_str(),
              threads);
  std::printf("| columns | cells | active cells (mean) | steps | us per cell-step | us per active cell-step | pressure correctors | "
              "of which solves | wall [s] | threads |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& [nx, ny] : {std::pair{40, 32}, std::pair{80, 64}}) {
    const Row r = run(nx, ny, t_end, pc);
    const double cs = double(r.cells) * r.steps, as = r.active_mean * r.steps;
    std::printf("| %d x %d | %d | %.0f | %d | %.2f | %.1f | %.0f %% | %.0f %% | %.1f | %d |\n", r.nx, r.ny, r.cells, r.active_mean, r.steps,
                1e6 * r.wall_s / cs, 1e6 * r.wall_s / as, 100 * r.pressure_s / r.wall_s, 100 * r.solve_s / r.wall_s, r.wall_s, threads);
    std::fflush(stdout);
  }
  return 0;
}
