// Benchmark of the VOF engine on B2 at 0 deg (validation.md B2) to t = 1 s, the case the
// dissertation timed: OpenFOAM's interFoam with the Coulomb viscosity took 80 s wall for 1677 steps
// on 12,000 cells (2.5 mm, about 4 microseconds per cell and step, 53 % in the pressure solve).
//   runout_bench_vof [--full] [--end T] [--courant C] [--correctors N] [--outer N] [--transpose harmonic|explicit|off]
//                    [--coupling piso|consistent] [--convection upwind|limited_linear]
//                    [--coulomb-pressure total|excess] [--wall-viscosity face|cell]
//                                          (default: 5 mm cells; --full: 2.5 mm, the dissertation's;
//                                          --transpose: how the viscous stress's transpose part is taken
//                                          (default: the scenario's, harmonic);
//                                          --coupling: the pressure coupling, lab.pressure_coupling;
//                                          --convection: the momentum's convection, lab.momentum_convection;
//                                          --coulomb-pressure: the Coulomb viscosity's pressure, lab.coulomb_pressure;
//                                          --wall-viscosity: the walls' viscosity, lab.wall_viscosity;
//                                          --outer: outer correctors per step, lab.outer_correctors)
//   runout_bench_vof --b10 [--check] [--jobs N]  B10: column collapse for aspect ratios 0.5-6 (2.5 mm cells,
//                                          scenarios/lab/b10-column-a*.json), normalised runout, rest
//                                          time and the exponents of its growth
//   runout_bench_vof --b1|--b2-inclined|--b3|--b4|--b5|--b8 [--check]
//                                          B1, B2 at 10/20/30 deg, B3, B4, B5, B8 from their scenario files at the files'
//                                          resolution (the full variants): the figures validation.md
//                                          names, beside the measured ones where it gives them;
//                                          --check: exit 1 unless the described behaviour holds
//                                          (bench/vof_cases.cpp)
//   runout_bench_vof --b9 [--full] [--check]  B9: the static and the failing heap (2.5 mm, --full: 1.25 mm);
//                                          --check: exit 1 unless both meet the issue's figures
//   runout_bench_vof [--full] --check      also check the issue's B2 acceptance figures (exit 1 if one fails)
//   runout_bench_vof --b6 [--full] [--check] [--jobs N]  B6: the shock at the closed end for the seven
//                                          set-ups at 1 cm (--full: 5 mm), its position over time and speed
//                                          upstream; --check: exit 1 unless each forms a deposit whose edge
//                                          moves upstream at a constant speed
//   runout_bench_vof --b7 [--full] [--check] [--jobs N]  B7: the wide chute with each obstacle at 5 mm
//                                          (--full: 2.5 mm, 1.34 million cells), depth figures and cost;
//                                          --check: exit 1 unless the described behaviour holds
//                                          --jobs N (B6, B7, B10): N set-ups at a time, each in a process of its
//                                          own (0: as many as cores; default 1, so that the wall times are
//                                          each run's alone)
//   runout_bench_vof --b7-nest [--check] [--jobs N]  B7 through a nest: the cylinder at 5 mm, the whole chute
//                                          in 3D against the 3D run on x >= 0.2 m fed by the depth-averaged run
//                                          of the chute; --check: exit 1 unless the nest conserves and agrees
//   runout_bench_vof --region              cost per step against the material region: the same failing
//                                          heap in channels 0.3-2.4 m long, with the active region and
//                                          with every cell computed
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/vof_cases.hpp"
#include "bench/vof_common.hpp"

using runout::bench::field;
using runout::bench::run_in_temp;
using runout::bench::series;

// B9 (validation.md B9) from scenarios/lab/b9-heap-{static,failing}.json: the heap flatter than phi
// must stay at rest (below 1 mm/s after 1 s), the steeper one relax to within 3 deg of phi (32 deg);
// 2.5 mm cells as the files have them, --full: 1.25 mm.
static int b9(bool full, bool check) {
  std::printf("| heap | cells | steps | wall [s] | peak speed [m/s] | speed at the end [m/s] | surface angle (80 %% to 20 %% of the height) "
              "[deg] | wanted | |\n|---|---:|---:|---:|---:|---:|---:|---|---|\n");
  int failed = 0;
  runout::bench::Checks inv("B9, the invariants");
  for (const char* name : {"static", "failing"}) {
    auto r = runout::bench::lab_scenario(std::string("b9-heap-") + name);
    auto* lab = r.scenario.mutable_lab();
    if (full) {
      lab->set_nx(2 * lab->nx());
      lab->set_ny(2 * lab->ny());
    }
    lab->set_write_interval_s(0);
    const auto ran = run_in_temp(r);
    const std::string& j = ran.json;
    const bool is_static = std::string(name) == "static";
    const double speed = field(j, "final_speed_m_s"), angle = field(j, "mean_surface_angle_deg");
    const bool ok = is_static ? speed < 1e-3 : std::abs(angle - 32) <= 3;
    failed += !ok;
    runout::bench::invariants(inv, std::string("B9 ") + name, ran);
    inv(std::abs(field(j, "volume_relative_error")) <= 1e-6, std::string("B9 ") + name + ": volume conserved to 1e-6");
    std::printf("| %s | %d | %ld | %.1f | %.4f | %.2e | %.1f | %s | %s |\n", name, ran.sum.nx * ran.sum.ny, ran.sum.steps, ran.sum.seconds_run,
                field(j, "peak_speed_m_s"), speed, angle, is_static ? "below 1 mm/s at 1 s" : "32 +- 3 deg", ok ? "met" : "NOT MET");
    std::fflush(stdout);
  }
  if (!check) return 0;
  failed += inv.report();
  std::printf("\n%s\n", failed ? "B9: NOT MET" : "B9: met");
  return failed ? 1 : 0;
}

// The same 50 deg heap (6 cm wide, 7 cm high, PVC) failing at the closed left end of channels of
// growing length (5 mm cells, 10 cm high, open top and right end), to 0.5 s: the active region keeps
// the cost per step with the material, every cell computed makes it grow with the channel.
static int region() {
  std::printf("| channel [m] | cells | active cells (mean) | wall, active region [s] | wall, every cell [s] | "
              "us per step, active region | us per step, every cell | ratio |\n|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (double len : {0.3, 0.6, 1.2, 2.4}) {
    double wall[2] = {0, 0}, per_step[2] = {0, 0}, active = 0;
    int cells = 0;
    for (int mode = 0; mode < 2; ++mode) {
      auto sc = runout::jobs::parse_scenario_json(
          R"({"engine": "vof", "lab": {"boundaries": [{"side": "top", "kind": "atmosphere"}, {"side": "right", "kind": "atmosphere"}],
              "fill": [{"polygon_xy": [0, 0, 0.06, 0, 0, 0.072]}], "y_max": 0.1, "ny": 20, "end_time_s": 0.5, "write_interval_s": 0}})");
      auto* lab = sc.mutable_lab();
      lab->set_x_max(len);
      lab->set_nx(int(std::lround(len / 0.005)));
      lab->set_active_layers(mode == 0 ? 0 : -1);
      auto r = runout::jobs::resolve_scenario(sc, ".");
      const auto ran = run_in_temp(r);
      const auto& sum = ran.sum;
      wall[mode] = sum.seconds_run;
      per_step[mode] = 1e6 * sum.seconds_run / double(sum.steps);
      if (mode == 0) active = field(ran.json, "active_cells_mean");
      cells = sum.nx * sum.ny;
    }
    std::printf("| %.1f | %d | %.0f | %.2f | %.2f | %.0f | %.0f | %.2f |\n", len, cells, active, wall[0], wall[1], per_step[0], per_step[1],
                per_step[1] / per_step[0]);
  }
  return 0;
}

// B6 (validation.md B6): the flow fed at x = -2 m runs into the closed end at x = 0; the shock's
// position over time and its speed upstream for the seven set-ups.
static int b6(bool full, bool check, int jobs) {
  int failed = 0;
  runout::bench::Checks inv("B6, the invariants");
  std::printf("| set-up | inflow speed [m/s] | cells | steps | wall [s] | shock formed [s] | shock from the wall at 1.5 / 2.5 / 3.5 s [m] | "
              "speed upstream [m/s] | deposit at the wall [m] |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  const std::vector<std::string> names = {"pvc-40deg-5cm", "pvc-40deg-10cm", "pvc-40deg-15cm", "pvc-50deg-5cm",
                                          "pvc-50deg-10cm", "pvc-50deg-15cm", "sand-50deg-10cm"};
  std::vector<runout::jobs::ResolvedScenario> rs;
  for (const auto& name : names) {
    auto r = runout::bench::lab_scenario("b6-shock-" + name);
    auto* lab = r.scenario.mutable_lab();
    if (!full) {  // 1 cm cells
      lab->set_nx(200);
      lab->set_ny(50);
      lab->mutable_fill(0)->set_x_max(-1.99);
    }
    lab->set_write_interval_s(0);
    rs.push_back(std::move(r));
  }
  runout::bench::run_all(rs, jobs, [&](std::size_t k, const runout::bench::Ran& ran) {
    const char* name = names[k].c_str();
    const auto* lab = &rs[k].scenario.lab();
    const auto& sum = ran.sum;
    const std::string& j = ran.json;
    const auto t = series(j, "t_s"), xs = series(j, "shock_x_m");
    auto at = [&](double when) {
      for (std::size_t q = 0; q < t.size() && q < xs.size(); ++q)
        if (t[q] >= when - 1e-9) return -xs[q];  // the end wall is at x = 0
      return double(NAN);
    };
    std::printf("| %s | %.3f | %.0f | %ld | %.0f | %.2f | %.2f / %.2f / %.2f | %.3f | %.3f |\n", name, lab->boundaries(0).inflow_u0(),
                field(j, "cells"), sum.steps, sum.seconds_run, field(j, "shock_formed_s"), at(1.5), at(2.5), at(3.5),
                field(j, "shock_speed_upstream_m_s"), field(j, "deposit_height_m"));
    std::fflush(stdout);
    if (check) {
      // validation.md B6's behaviour: a deposit forms at the end wall, deeper than the inflow, and the
      // bore at its upstream edge moves upstream at a constant speed (the speeds over 1.5-2.5 s and
      // 2.5-3.5 s within 30 % of each other).
      const double h0 = lab->boundaries(0).inflow_height(), v1 = at(2.5) - at(1.5), v2 = at(3.5) - at(2.5);
      const bool ok = field(j, "shock_formed_s") > 0 && field(j, "shock_speed_upstream_m_s") > 0 && v1 > 0 && v2 > 0 &&
                      std::abs(v2 / v1 - 1) <= 0.3 && field(j, "deposit_height_m") > h0;
      if (!ok) std::printf("NOT MET (%s): a deposit deeper than the inflow whose bore moves upstream at a constant speed\n", name);
      failed += !ok;
      runout::bench::invariants(inv, std::string("B6 ") + name, ran);
    }
  });
  if (check) failed += inv.report();
  if (check) std::printf("\n%s\n", failed ? "B6: NOT MET" : "B6: met for every set-up");
  return failed ? 1 : 0;
}

static int usage() {
  std::fprintf(stderr,
               "usage: runout_bench_vof [--full] [--end T] [--courant C] [--correctors N] [--outer N] [--transpose harmonic|explicit|off] "
               "[--coupling piso|consistent] [--convection upwind|limited_linear] [--coulomb-pressure total|excess] [--wall-viscosity face|cell] [--check] | --b1|--b2-inclined|--b3|--b4|--b5|--b8 "
               "[--check] | --b6|--b7 [--full] [--check] [--jobs N] | --b7-nest [--check] [--jobs N] | --b10 [--check] [--jobs N] | --b9 [--full] [--check] | --region\n");
  return 2;
}

// One laboratory case: --bN [--full] [--check] [--jobs N]; --full only where the case has a
// coarser default.
static int one_case(const std::string& mode, int argc, char** argv) {
  const bool takes_full = mode == "--b6" || mode == "--b7" || mode == "--b9";
  const bool takes_jobs = mode == "--b6" || mode == "--b7" || mode == "--b7-nest" || mode == "--b10";
  bool full = false, check = false;
  int jobs = 1;
  for (int k = 2; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--check") check = true;
    else if (a == "--full" && takes_full) full = true;
    else if (a == "--jobs" && takes_jobs && k + 1 < argc) {
      char* end = nullptr;
      jobs = int(std::strtol(argv[++k], &end, 10));
      if (*end || jobs < 0) return usage();
    } else return usage();
  }
  if (mode == "--b1") return runout::bench::lab_b1(check);
  if (mode == "--b2-inclined") return runout::bench::lab_b2_inclined(check);
  if (mode == "--b3") return runout::bench::lab_b3(check);
  if (mode == "--b4") return runout::bench::lab_b4(check);
  if (mode == "--b5") return runout::bench::lab_b5(check);
  if (mode == "--b6") return b6(full, check, jobs);
  if (mode == "--b7") return runout::bench::lab_b7(full, check, jobs);
  if (mode == "--b7-nest") return runout::bench::lab_b7_nest(check, jobs);
  if (mode == "--b8") return runout::bench::lab_b8(check);
  if (mode == "--b9") return b9(full, check);
  if (mode == "--b10") return runout::bench::lab_b10(check, jobs);
  return usage();
}

// The default: B2 at 0 deg (coarse, or --full at the scenario's resolution) with the options of the
// VOF engine to compare, its table beside the dissertation's and, with --check, its acceptance figures.
static int b2_collapse(int argc, char** argv) {
  bool full = false, check = false;
  double end = 1.0, courant = 0;
  int correctors = 0, outer = 0;
  std::string transpose, coupling, convection, coulomb_pressure, wall_viscosity;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--full") full = true;
    else if (a == "--check") check = true;
    else if (a == "--end" && k + 1 < argc) end = std::atof(argv[++k]);
    else if (a == "--courant" && k + 1 < argc) courant = std::atof(argv[++k]);
    else if (a == "--correctors" && k + 1 < argc) correctors = std::atoi(argv[++k]);
    else if (a == "--outer" && k + 1 < argc) outer = std::atoi(argv[++k]);
    else if (a == "--transpose" && k + 1 < argc) transpose = argv[++k];
    else if (a == "--coupling" && k + 1 < argc) coupling = argv[++k];
    else if (a == "--convection" && k + 1 < argc) convection = argv[++k];
    else if (a == "--coulomb-pressure" && k + 1 < argc) coulomb_pressure = argv[++k];
    else if (a == "--wall-viscosity" && k + 1 < argc) wall_viscosity = argv[++k];
    else return usage();
  }
  auto r = runout::bench::lab_scenario("b2-collapse-0deg");
  auto* lab = r.scenario.mutable_lab();
  if (!full) {
    lab->set_nx(100);
    lab->set_ny(30);
  }
  lab->set_end_time_s(end);
  lab->set_write_interval_s(0);
  if (courant > 0) lab->set_max_courant(courant);
  if (correctors > 0) lab->set_correctors(correctors);
  if (outer > 0) lab->set_outer_correctors(outer);
  if (!transpose.empty() || !coupling.empty() || !convection.empty() || !coulomb_pressure.empty() || !wall_viscosity.empty() || outer > 0) {
    if (!transpose.empty()) lab->set_viscous_transpose(transpose);
    if (!wall_viscosity.empty()) lab->set_wall_viscosity(wall_viscosity);
    if (!coulomb_pressure.empty()) lab->set_coulomb_pressure(coulomb_pressure);
    if (!convection.empty()) lab->set_momentum_convection(convection);
    if (!coupling.empty()) lab->set_pressure_coupling(coupling);
    try {
      r = runout::jobs::resolve_scenario(r.scenario, std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab");  // validates the name
    } catch (const std::exception& e) {
      std::fprintf(stderr, "runout_bench_vof: %s\n", e.what());
      return 2;
    }
    lab = r.scenario.mutable_lab();
  }
  const auto ran = run_in_temp(r);
  const auto& sum = ran.sum;
  const std::string& j = ran.json;
  const double cells = double(sum.nx) * sum.ny, pressure = field(j, "pressure"), solve = field(j, "pressure_solve");
  std::printf("| figure | this run | dissertation (interFoam) |\n|---|---:|---:|\n");
  std::printf("| cells | %.0f | 12000 |\n", cells);
  std::printf("| steps to t = %.2f s | %ld | 1677 (to 1 s) |\n", sum.t, sum.steps);
  std::printf("| wall time of the solve | %.1f s | 80 s (to 1 s) |\n", sum.seconds_run);
  std::printf("| microseconds per cell and step | %.2f | about 4 |\n", 1e6 * sum.seconds_run / sum.steps / cells);
  std::printf("| cells in the active region, mean | %.0f | (every cell) |\n", field(j, "active_cells_mean"));
  std::printf("| microseconds per active cell and step | %.2f | |\n", field(j, "microseconds_per_active_cell_step"));
  std::printf("| share of time in the pressure correctors (assembly, solve, fluxes) | %.0f %% | |\n", 100 * pressure / sum.seconds_run);
  std::printf("| share of time in the pressure solves (KSPSolve, preconditioner set-up included) | %.0f %% | 53 %% |\n",
              100 * solve / sum.seconds_run);
  std::printf("| peak speed, its time | %.3f m/s at %.3f s | about 1.1 m/s at 0.15 s |\n", field(j, "peak_speed_m_s"),
              field(j, "peak_speed_time_s"));
  std::printf("| front, upper surface angle | %.3f m, %.1f deg | 0.19-0.20 m, about 33 deg |\n", field(j, "front_x_m"),
              field(j, "upper_surface_angle_deg"));
  std::printf("| mean surface angle (80 %% to 20 %% of the height) | %.1f deg | |\n", field(j, "mean_surface_angle_deg"));
  std::printf("| at rest (below 1 cm/s) from | %.3f s | about 0.6 s |\n", field(j, "rest_time_s"));
  std::printf("| relative volume change (outflow at the open end) | %.2e | |\n", sum.volume_error);
  if (!check) return 0;
  // The issue's acceptance figures for B2 at 0 deg: within 10 % of the dissertation's method, the
  // front within 2 cells of 0.19-0.20 m.
  const double dx = 0.5 / lab->nx();
  const double pk = field(j, "peak_speed_m_s"), tp = field(j, "peak_speed_time_s"), rest = field(j, "rest_time_s"),
               up = field(j, "upper_surface_angle_deg"), fr = field(j, "front_x_m");
  runout::bench::Checks c("B2 at 0 deg");
  runout::bench::invariants(c, "B2", ran);
  c(std::abs(pk - 1.1) <= 0.11, "peak speed within 10 % of 1.1 m/s");
  c(std::abs(tp - 0.15) <= 0.015, "its time within 10 % of 0.15 s");
  c(std::abs(rest - 0.6) <= 0.06, "at rest within 10 % of 0.6 s");
  c(std::abs(up - 33) <= 3.3, "upper surface within 10 % of 33 deg");
  c(fr >= 0.19 - 2 * dx && fr <= 0.20 + 2 * dx, "front within 2 cells of 0.19-0.20 m");
  return c.report();
}

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode.size() > 2 && mode.compare(0, 3, "--b") == 0) return one_case(mode, argc, argv);
  if (mode == "--region") return argc == 2 ? region() : usage();
  return b2_collapse(argc, argv);
}
