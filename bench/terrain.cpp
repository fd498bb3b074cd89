// The 3D engine on terrain: cost per step against the material, on two domain sizes.
//
//   runout_bench_terrain [--end T] [--pc ilu|gamg]
//   runout_bench_terrain --arelen [--resolution R] [--end T]
//
// The same block (60 m square, 2 m thick, phi 40, delta 20) released on a 35 deg plane (10 m
// columns) through the terrain driver's mesh, release and configuration (the scenario defaults of
// the `mesh` and `vof` blocks), on a plane of 40 x 32 columns and one of 80 x 64, run to T (default
// 1 s). Printed per domain: cells, active cells (mean over the steps), steps, microseconds per
// cell-step and per active cell-step, the share of the pressure correctors and of the pressure
// solves in the step, wall time and threads. With the active region the cost per step follows the
// active cells, not the mesh (docs/design/performance.md, "3D engine on terrain"). Threads: OMP_NUM_THREADS.
//
// --arelen: scenarios/in-den-arelen-3d.json as bundled (30 m, the kinetic-energy stop rule; R and T
// change the grid and the end time) through the run driver, as `runout run` runs it: wall time,
// steps, simulated time, the mesh's and the active region's cells, what set each step's length
// (the Courant number in the material, at the interface or in the air, the growth limit) and the
// mean step (docs/design/performance.md, "In den Arelen at 30 m").
#include <omp.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "engine/vof/solver.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "jobs/drivers/run.hpp"
#include "jobs/drivers/vof_terrain/config.hpp"
#include "jobs/drivers/vof_terrain/mesh.hpp"
#include "jobs/drivers/vof_terrain/release.hpp"
#include "jobs/scenario/options.hpp"
#include "jobs/formats/run_record.hpp"
#include "jobs/scenario/scenario.hpp"
#include "terrain/column_mesh.hpp"

#include <filesystem>
#include <map>

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

// In den Arelen through the run driver (--arelen); t_end, res_m: the scenario's when 0.
int run_arelen(double res_m, double t_end) {
  namespace fs = std::filesystem;
  const fs::path file = fs::path(RUNOUT_SOURCE_DIR) / "scenarios" / "in-den-arelen-3d.json";
  auto r = runout::jobs::load_scenario(file.string());
  if (res_m > 0 || t_end > 0) {
    if (res_m > 0) r.scenario.mutable_grid()->set_resolution_m(res_m);
    if (t_end > 0) r.scenario.mutable_numerics()->set_end_time_s(t_end);
    r = runout::jobs::resolve_scenario(r.scenario, file.parent_path().string());
  }
  const fs::path out = fs::temp_directory_path() / ("runout_bench_arelen_" + std::to_string(::getpid()));
  fs::create_directories(out);
  std::map<std::string, long> limits;
  double dt_sum = 0;
  runout::jobs::RunOptions opt;
  opt.progress_every = 1;
  opt.progress = [&](const runout::engine::Progress& p) {
    ++limits[p.dt_limit];
    dt_sum += p.dt;
    return true;
  };
  const auto t0 = std::chrono::steady_clock::now();
  const auto sum = runout::jobs::run_scenario(r, out.string(), opt);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto rec = runout::jobs::read_run_record((out / "run.json").string());
  fs::remove_all(out);
  std::printf("In den Arelen 3D at %.0f m, %d threads: %ld steps to %.1f s of flow (stop: %s) in %.0f s wall\n", sum.dx,
              omp_get_max_threads(), sum.steps, sum.t, sum.stop.c_str(), wall);
  std::printf("mesh: %d columns, %d cells; active cells %.0f on average, %d at most; mean step %.4f s\n", rec.terrain_mesh().columns(),
              rec.terrain_mesh().cells(), rec.solver().active_cells_mean(), rec.solver().active_cells_max(), dt_sum / std::max(1L, sum.steps));
  std::printf("what set the step's length:");
  for (const auto& [what, n] : limits) std::printf(" %s %.1f %%;", what.c_str(), 100.0 * n / std::max(1L, sum.steps));
  std::printf("\nout of the mesh: %.2f %% of the released volume; affected area %.3f km2, runout %.0f m\n",
              100 * sum.volume_outflow / sum.volume_initial, sum.affected_area_m2 / 1e6, sum.runout_m);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  double t_end = 1.0, res_m = 0;
  bool arelen = false, t_given = false;
  std::string pc = "ilu";
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--end") && i + 1 < argc) {
      t_end = std::atof(argv[++i]);
      t_given = true;
    } else if (!std::strcmp(argv[i], "--pc") && i + 1 < argc) {
      pc = argv[++i];
    } else if (!std::strcmp(argv[i], "--arelen")) {
      arelen = true;
    } else if (!std::strcmp(argv[i], "--resolution") && i + 1 < argc) {
      res_m = std::atof(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: runout_bench_terrain [--end T] [--pc ilu|gamg]\n       runout_bench_terrain --arelen [--resolution R] [--end T]\n");
      return 2;
    }
  }
  if (arelen) return run_arelen(res_m, t_given ? t_end : 0);
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
