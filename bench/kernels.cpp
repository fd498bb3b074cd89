// Google Benchmark micro-benchmarks of the engines' building blocks (the depth-averaged engine's
// limiters and steps, the VOF engine's granular viscosities):
//   runout_bench_kernels [--benchmark_filter=...]
// The figures that matter for users are in runout_bench_sh (work-precision, throughput).
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "engine/limiters.hpp"
#include "engine/sh2d.hpp"
#include "engine/vof/models/registry.hpp"

using namespace runout::engine;

namespace {

void BM_Limiter(benchmark::State& state) {
  const auto lim = static_cast<Limiter>(state.range(0));
  std::vector<double> w(4096);
  for (std::size_t k = 0; k < w.size(); ++k) w[k] = std::sin(0.01 * double(k)) + 0.1 * std::sin(0.7 * double(k));
  for (auto _ : state) {
    double s = 0;
    for (std::size_t k = 1; k + 1 < w.size(); ++k) s += limited_slope(lim, w[k] - w[k - 1], w[k + 1] - w[k]);
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(w.size() - 2));
  state.SetLabel(std::string(name_of(kLimiterNames, lim)));
}
BENCHMARK(BM_Limiter)->Arg(0)->Arg(1)->Arg(2);

// The VOF engine's granular viscosity per cell (what its momentum equation evaluates once per cell
// and step), over pressures and strain rates spanning a flow: resting to fast, shallow to deep.
void BM_GranularViscosity(benchmark::State& state) {
  vof::VofConfig c;
  c.rho1 = 1470;
  c.rheology = std::string(vof::kGranularViscosityModels[std::size_t(state.range(0))]->name);
  const auto model = vof::make_granular_viscosity(c);
  std::vector<double> p(4096), sr(4096);
  for (std::size_t k = 0; k < p.size(); ++k) {
    p[k] = 1000 * (0.5 + 0.5 * std::sin(0.013 * double(k)));
    sr[k] = std::pow(10.0, -4 + 6 * (0.5 + 0.5 * std::sin(0.7 * double(k))));
  }
  for (auto _ : state) {
    double s = 0;
    for (std::size_t k = 0; k < p.size(); ++k) s += model->nu(p[k], sr[k]);
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(p.size()));
  state.SetLabel(c.rheology);
}
BENCHMARK(BM_GranularViscosity)->Arg(0)->Arg(1)->Arg(2);

// Forty steps of the 2D solver on a fully wet n x n grid on a rough 35 degree slope (set-up included).
void BM_Sh2dSteps(benchmark::State& state) {
  const int n = int(state.range(0));
  Terrain2D t;
  t.nx = t.ny = n;
  t.dx = t.dy = 5.0;
  t.z.resize(t.cells());
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      t.z[std::size_t(j) * n + i] = -0.7 * i * 5.0 + 2.0 * std::sin(0.05 * i) * std::cos(0.03 * j);
  const auto init = state_from_normal_depth(t, std::vector<double>(t.cells(), 2.0));
  Sh2dConfig cfg;
  cfg.material.delta = 25 * M_PI / 180;
  cfg.time.t_end = 1e9;
  cfg.time.max_steps = 40;
  double updates = 0;
  for (auto _ : state) {
    const auto r = run_sh2d(t, cfg, init);
    updates += r.diag.cell_updates;
    benchmark::DoNotOptimize(r.diag.volume_final);
  }
  state.counters["cell_updates_per_s"] = benchmark::Counter(updates, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Sh2dSteps)->Arg(128)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
