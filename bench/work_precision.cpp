// Work-precision and throughput benchmark of the depth-averaged solvers (docs/design/performance.md).
//
//   runout_bench_sh [--quick] [--repeat N] [--throughput-only] [--friction LAW] [--resistance] [--entrainment]
//
// 1. Work-precision: cases A1 (1D and 2D) and A3 (2D) at four resolutions for each limiter:
//    error, wall time, cell-updates per second.
// 2. Throughput: a full second-order step of the 2D solver on a fully wet 1000 x 1000 grid.
// 3. Skipping dry work: the same grid with a release that wets about 5 % of it, cost per step
//    relative to the fully wet grid.
// Figures are medians over --repeat runs (default 5), all measured in this one process.
// --throughput-only skips part 1 (for quick before/after comparisons of the 2D step). --friction
// runs parts 2 and 3 with another basal friction (friction_material: coulomb by default).
// --resistance puts the whole grid in a resistance area (drag c = 0.01 and detrainment K = 5 Pa, the
// band from 0 so that the drag acts and the detrainment is evaluated everywhere; the kernels are
// branch-free, so the cost does not depend on where either applies). --entrainment lays an erodible
// cover of 5 m (density 100 kg/m^3, e_b = 5000 J/kg: basal erosion) over the whole grid, more than the
// steps erode, so that the erosion acts in every wet cell.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "engine/verification/cases.hpp"

using namespace runout::engine;
namespace ver = runout::engine::verification;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

Terrain2D rough_slope(int n, double dx) {
  Terrain2D t;
  t.nx = t.ny = n;
  t.dx = t.dy = dx;
  t.z.resize(t.cells());
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = i * dx, y = j * dx;
      t.z[std::size_t(j) * n + i] = -0.7 * x - 0.2 * y + 3.0 * std::sin(0.013 * x) * std::cos(0.021 * y) +
                                    1e-4 * (x - 0.5 * n * dx) * (x - 0.5 * n * dx);
    }
  return t;
}

struct StepCost {
  double seconds_per_step, updates_per_second, active_fraction, ever_wet;
  long steps;
};

// The throughput runs' material: each friction law with parameters of a dense flow on the 5 m grid;
// pouliquen_forterre without, pouliquen_forterre_start with the start/stop term (its own kernel).
bool friction_material(const std::string& law, Material& m) {
  const double deg = M_PI / 180;
  m = Material{};
  m.delta = 25 * deg;
  if (law == "voellmy") {
    m.rheology = &friction::voellmy;
    m.mu = 0.25;
    m.xi = 2000;
  } else if (law == "pouliquen_forterre" || law == "pouliquen_forterre_start") {
    m = pouliquen_forterre_material(20 * deg, 32 * deg, (law == "pouliquen_forterre" ? 20 : 23) * deg, 0.136, 0.2, 0.05);
  } else if (law == "mu_i") {
    m = mu_i_material(0.38, 0.64, 0.279, 0.02, 2500, 1500);
  } else if (law != "coulomb") {
    return false;
  }
  return true;
}

StepCost measure(const Terrain2D& t, const Sh2dState& init, const Material& material, long steps, int repeat,
                 bool resistance, bool entrainment) {
  Sh2dConfig cfg;
  cfg.material = material;
  if (entrainment) {
    cfg.cover.depth.assign(t.cells(), 5.0);
    cfg.cover.density.assign(t.cells(), 100.0);
  }
  if (resistance) {
    cfg.resistance.c.assign(t.cells(), 0.01);
    cfg.resistance.k_det.assign(t.cells(), 5.0);
    cfg.resistance.speed_min = cfg.resistance.depth_min = 0;
    cfg.resistance.speed_max = cfg.resistance.depth_max = 1e9;
  }
  cfg.time.t_end = 1e9;
  cfg.time.max_steps = steps;
  std::vector<double> per_step, rate;
  Sh2dResult last;
  for (int r = 0; r < repeat; ++r) {
    last = run_sh2d(t, cfg, init);
    per_step.push_back(last.diag.loop_seconds / double(last.diag.steps));
    rate.push_back(last.diag.cell_updates / last.diag.loop_seconds);
  }
  double wet = 0;
  for (double h : last.hazard.max_depth) wet += h > 0.0;
  return {median(per_step), median(rate), last.diag.mean_active_fraction, wet / double(t.cells()), last.diag.steps};
}

// Part 1: error, wall time and throughput of the verification cases A1 and A3.
void work_precision(bool quick) {
  std::printf("## Work-precision\n\n");
  std::printf("| case | variant | cells | dx [m] | error | order | wall [s] | Mcell-updates/s |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|---:|\n");
  for (const char* id : {"A1", "A3"}) {
    for (Limiter l : {Limiter::minmod, Limiter::vanleer, Limiter::superbee}) {
      ver::Options o;
      o.limiter = l;
      if (std::string(id) == "A1") o.resolutions = quick ? std::vector<double>{1, 0.5} : std::vector<double>{1, 0.5, 0.25, 0.125};
      else o.resolutions = quick ? std::vector<double>{4, 2} : std::vector<double>{4, 2, 1, 0.5};
      const auto rows = ver::run_case(id, o);
      for (const auto& r : rows) {
        const auto* e = r.metric("L1_rel_depth");
        std::printf("| %s | %s | %ld | %g | %.3e | %s | %.3f | %.1f |\n", id, r.variant.c_str(), r.cells, r.dx,
                    e ? e->value : NAN, std::isfinite(r.order) ? std::to_string(r.order).substr(0, 5).c_str() : "",
                    r.wall_s, r.cell_updates / r.wall_s / 1e6);
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, throughput_only = false, resistance = false, entrainment = false;
  int repeat = 5;
  std::string law = "coulomb";
  Material material;
  for (int k = 1; k < argc; ++k) {
    if (!std::strcmp(argv[k], "--quick")) {
      quick = true;
    } else if (!std::strcmp(argv[k], "--throughput-only")) {
      throughput_only = true;
    } else if (!std::strcmp(argv[k], "--repeat") && k + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++k]));
    } else if (!std::strcmp(argv[k], "--friction") && k + 1 < argc) {
      law = argv[++k];
    } else if (!std::strcmp(argv[k], "--resistance")) {
      resistance = true;
    } else if (!std::strcmp(argv[k], "--entrainment")) {
      entrainment = true;
    } else {
      std::fprintf(stderr,
                   "usage: runout_bench_sh [--quick] [--repeat N] [--throughput-only] [--friction LAW] [--resistance] [--entrainment]\n");
      return 2;
    }
  }
  if (!friction_material(law, material)) {
    std::fprintf(stderr, "unknown --friction '%s' (valid: coulomb, voellmy, pouliquen_forterre, pouliquen_forterre_start, mu_i)\n",
                 law.c_str());
    return 2;
  }
  if (quick) repeat = 1;
  std::printf("# runout depth-averaged engine benchmark, %d OpenMP threads, median of %d\n\n", omp_get_max_threads(),
              repeat);

  if (!throughput_only) work_precision(quick);

  const int n = quick ? 400 : 1000;
  const double dx = 5.0;
  const auto t = rough_slope(n, dx);
  // Fully wet: a 2 m layer everywhere, sliding.
  const auto wet = state_from_normal_depth(t, std::vector<double>(t.cells(), 2.0));
  // About 5 % ever wet: a release in the upper part of the slope.
  std::vector<double> h(t.cells(), 0.0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double di = (i - 0.12 * n) / (0.06 * n), dj = (j - 0.5 * n) / (0.08 * n);
      const double q = di * di + dj * dj;
      h[std::size_t(j) * n + i] = q < 1 ? 4.0 * (1 - q) : 0.0;
    }
  const auto part = state_from_normal_depth(t, h);
  const long steps = quick ? 20 : 60;
  const auto full = measure(t, wet, material, steps, repeat, resistance, entrainment);
  const auto small = measure(t, part, material, steps * 4, repeat, resistance, entrainment);
  std::printf("\n## Throughput (%d x %d grid, %ld steps, friction %s%s%s)\n\n", n, n, full.steps, law.c_str(),
              resistance ? ", a resistance area everywhere" : "", entrainment ? ", an erodible cover everywhere" : "");
  std::printf("| run | ever wet | mean active | ms/step | Mcell-updates/s (of active cells) | grid cells/s |\n");
  std::printf("|---|---:|---:|---:|---:|---:|\n");
  std::printf("| fully wet | %.1f %% | %.1f %% | %.2f | %.1f | %.1f M |\n", 100 * full.ever_wet, 100 * full.active_fraction,
              1e3 * full.seconds_per_step, full.updates_per_second / 1e6, double(t.cells()) / full.seconds_per_step / 1e6);
  std::printf("| partial release | %.1f %% | %.1f %% | %.2f | %.1f | %.1f M |\n", 100 * small.ever_wet,
              100 * small.active_fraction, 1e3 * small.seconds_per_step, small.updates_per_second / 1e6,
              double(t.cells()) / small.seconds_per_step / 1e6);
  std::printf("\ncost per step, partial / fully wet: %.3f (target <= 0.25)\n",
              small.seconds_per_step / full.seconds_per_step);
  std::printf("full second-order step, fully wet grid: %.1f M cell-updates/s (target >= 20)\n",
              full.updates_per_second / 1e6);
  return 0;
}
