// The run driver: the scenario's engine set-up from the registry, the one loop, the results.
#include "jobs/drivers/run.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "jobs/drivers/engine_run.hpp"

namespace runout::jobs {

namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

std::string runout_phrase(const RunSummary& sum) {
  char b[200];
  if (std::isfinite(sum.path_runout_m))
    std::snprintf(b, sizeof b, "runout %.0f m along the path (%s)", sum.path_runout_m, sum.path_criterion.c_str());
  else
    std::snprintf(b, sizeof b, "runout %.0f m from the release centroid", sum.runout_m);
  return b;
}

RunSummary run_scenario(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const EngineRow& row = engine_row(s.engine);
  const std::unique_ptr<EngineRun> run = row.prepare(s, out_dir, opt);
  RunTimes times;
  times.prepare = since(t0);
  engine::LoopSchedule schedule = run->schedule();
  schedule.progress_every = opt.progress_every;
  engine::LoopHooks hooks = run->hooks();
  hooks.progress = opt.progress;
  if (opt.checkpoint_path.empty()) hooks.checkpoint = nullptr;
  const auto t1 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  const engine::StopReason stop = engine::run_steps(run->engine(), schedule, run->loop, hooks, run->continued);
  times.cpu = double(std::clock() - cpu0) / CLOCKS_PER_SEC;
  times.run = since(t1);
  return run->finish(stop, times);
}

}  // namespace runout::jobs
