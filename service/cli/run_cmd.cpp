// `runout run SCENARIO.json --out DIR`: one scenario, locally, with a progress line.
#include <CLI/CLI.hpp>
#include <omp.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "jobs/drivers/run.hpp"
#include "jobs/drivers/vof_support.hpp"
#include "service/cli/commands.hpp"
#include "service/cli/output_dir.hpp"
#include "service/cli/run_ensemble.hpp"
#include "jobs/ensemble/variations.hpp"

namespace runout::cli {
namespace fs = std::filesystem;

namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void on_interrupt(int) { g_interrupted = true; }

// The summary of a finished run on standard output.
void print_summary(const jobs::RunSummary& sum, bool vof, const fs::path& dest) {
  if (vof) {
    std::printf("mesh        %d x %d cells of %.4g m (plane, channel coordinates)\n", sum.nx, sum.ny, sum.dx);
    std::printf("run         %ld steps to t = %.3f s, %.2f s wall (solve %.2f, write %.2f)\n", sum.steps, sum.t,
                sum.seconds_prepare + sum.seconds_run + sum.seconds_write, sum.seconds_run, sum.seconds_write);
    if (std::isnan(sum.volume_error))  // an inflow brings material in: the run has no conservation figure of its own
      std::printf("granular    %.6g m3 initial, %.6g m3 final (material came in through a boundary: no relative error)\n",
                  sum.volume_initial, sum.volume_final);
    else
      std::printf("granular    %.6g m3 initial, %.6g m3 final (relative error %.1e)\n", sum.volume_initial, sum.volume_final,
                  sum.volume_error);
    std::printf("flow        peak speed %.3f m/s, front at x = %.4f m, deposit height %.4f m (run.json has the rest)\n",
                sum.max_speed, sum.runout_m, sum.max_depth);
    std::printf("results in  %s:", dest.string().c_str());
    for (const auto& f : sum.files) std::printf(" %s", f.c_str());
    std::printf("\n");
    return;
  }
  for (const auto& n : sum.notes) std::cerr << "note: " << n << "\n";
  std::printf("grid        %d x %d cells of %.1f m in %s\n", sum.nx, sum.ny, sum.dx, sum.crs.c_str());
  std::printf("release     %.0f m2, %.0f m3\n", sum.release_area_m2, sum.release_volume_m3);
  std::printf("run         %ld steps to t = %.1f s (stop: %s), %.2f s wall (prepare %.2f, solve %.2f, write %.2f)\n",
              sum.steps, sum.t, sum.stop.c_str(), sum.seconds_prepare + sum.seconds_run + sum.seconds_write,
              sum.seconds_prepare, sum.seconds_run, sum.seconds_write);
  std::printf("volume      %.6g m3 initial, %.6g m3 final, %.6g m3 left the grid", sum.volume_initial, sum.volume_final,
              sum.volume_outflow);
  if (sum.volume_detrained > 0) std::printf(", %.6g m3 left in resistance areas", sum.volume_detrained);
  if (sum.volume_entrained > 0) std::printf(", %.6g m3 entrained", sum.volume_entrained);
  std::printf(" (error %.1e)\n", sum.volume_error);
  for (const auto& q : sum.dams) {
    std::printf("dam         %s: %.0f m high, deepest flow on it %.2f m", q.name.c_str(), q.height_max_m, q.max_depth_m);
    if (q.lines) std::printf(", %.6g m3 passed it", q.overflow_m3);
    std::printf("\n");
  }
  std::printf("hazard      affected area %.0f m2, %s, max speed %.1f m/s, max depth %.2f m\n", sum.affected_area_m2,
              jobs::runout_phrase(sum).c_str(), sum.max_speed, sum.max_depth);
  std::printf("results in  %s:", dest.string().c_str());
  for (const auto& f : sum.files) std::printf(" %s", f.c_str());
  std::printf("\n");
}

constexpr const char* kRunHelp =
    "Run a scenario (JSON form of runout.v1.Scenario, see README) and write the hazard rasters (COG\n"
    "GeoTIFF), the runout outline (GeoJSON in WGS84, GeoPackage) and the run record (run.json) into DIR.\n"
    "Results appear only when the run succeeded. A progress line goes to standard error unless --quiet.";

// The command's arguments.
struct RunArgs {
  std::string scenario, out, iseesnow, checkpoint, restart, threads;
  bool force = false, quiet = false;
  std::string state_dir, workers;  // ensembles
  bool members = false, no_terrain_cache = false;
};

void add_run_options(CLI::App& app, RunArgs& a) {
  prepare(app);
  app.add_option("SCENARIO.json", a.scenario, "The scenario file (required)");
  app.add_option("--out", a.out,
                 "Result directory (required). It must not exist; an existing DIR is replaced only with --force and "
                 "only when it holds a previous result (runout's run.json), once the new one is complete; another "
                 "folder, a file, a link, or the current directory (or one that holds it) is never replaced")
      ->type_name("DIR");
  app.add_flag("--force", a.force, "Replace DIR when it holds a previous result (see --out)");
  app.add_flag("--quiet", a.quiet, "No progress line and no summary");
  app.add_option("--threads", a.threads, "OpenMP threads (a positive integer; default: all cores)")->type_name("N");
  app.add_option("--iseesnow", a.iseesnow,
                 "Also write the ISeeSnow benchmark files (peak thickness/velocity ESRI ASCII on the DEM's grid, result "
                 "CSV) for this simulation id (01IdealizedTopo, 02RealTopo, 03CoulombOnly)")
      ->type_name("SIMULATION_ID");
  app.add_option("--checkpoint", a.checkpoint,
                 "Write the run's state to FILE when the run is interrupted (Ctrl-C, SIGTERM) and, for VOF runs (engine "
                 "\"vof\"), every lab.checkpoint_interval_s (on the DEM: vof.checkpoint_interval_s). VOF runs: the monitors (on the "
                 "DEM: the hazard maps) travel in FILE, the frames so far in "
                 "FILE.fields.h5. Depth-averaged runs: the solver's whole state and hazard maps travel in FILE, the time "
                 "series so far in FILE.timeseries.h5")
      ->type_name("FILE");
  app.add_option("--restart", a.restart,
                 "Continue from a --checkpoint FILE of the same scenario exactly as the run would have gone on (run.json "
                 "and fields.h5 are the whole run's; depth-averaged runs: the uninterrupted run's outputs, bit for bit)")
      ->type_name("FILE");
  app.add_option("--state-dir", a.state_dir,
                 "Ensembles (scenarios with variations): the local job system's folder (job store, members' results, logs); "
                 "default $RUNOUT_STATE_DIR, else $XDG_CACHE_HOME/runout, else ~/.cache/runout. Members computed before in it answer "
                 "from their results, and an interrupted ensemble continues there")
      ->type_name("DIR");
  app.add_option("--workers", a.workers, "Ensembles: cores to use (a positive integer; default: all)")->type_name("N");
  app.add_flag("--members", a.members, "Ensembles: also write each member's results into DIR/members/member_<k>");
  app.add_flag("--no-terrain-cache", a.no_terrain_cache,
               "Ensembles: every member prepares its grid (warp, clip) itself instead of sharing the prepared grid in the state "
               "directory's terrain cache (for measurements)");
}

// Runs the resolved scenario into `tmp`; kOk, or the exit code of the failure (its message on
// standard error; `newline` ends the progress line first).
int execute(const jobs::ResolvedScenario& resolved, const fs::path& tmp, const jobs::RunOptions& opt, bool newline,
            jobs::RunSummary& sum) {
  auto fail = [&](const std::string& message, int code) {
    if (newline) std::fprintf(stderr, "\n");
    std::cerr << "runout run: " << message << "\n";
    return code;
  };
  try {
    sum = jobs::run_scenario(resolved, tmp.string(), opt);
  } catch (const jobs::ScenarioError& e) {
    return fail(e.what(), kBadInput);
  } catch (const terrain::TerrainError& e) {
    return fail(e.what(), kBadInput);
  } catch (const std::invalid_argument& e) {  // the engine's checks of its input
    return fail(e.what(), kBadInput);
  } catch (const std::exception& e) {
    return fail(std::string("failed: ") + e.what(), kInternal);
  }
  return kOk;
}

// The options' own checks: --iseesnow's id, --checkpoint and --restart (made absolute), --threads
// and the two required ones. Returns an exit code, or -1 when they hold.
int check_run_args(const CLI::App& app, RunArgs& a) {
  if (app.count("--iseesnow") && (a.iseesnow.empty() || a.iseesnow.find_first_of("_/\\ .") != std::string::npos)) {
    std::cerr << "runout run: --iseesnow '" << a.iseesnow
              << "': the simulation id names files and may not be empty or hold '_', '/', '\\', '.' or spaces"
                 " (the benchmark's ids: 01IdealizedTopo, 02RealTopo, 03CoulombOnly)\n";
    return kUsage;
  }
  for (auto* f : {&a.checkpoint, &a.restart}) {
    if (app.count(f == &a.checkpoint ? "--checkpoint" : "--restart") && f->empty())
      return usage_error("runout run", std::string(f == &a.checkpoint ? "--checkpoint" : "--restart") + " needs a file");
    if (!f->empty()) *f = fs::absolute(*f).string();
  }
  if (app.count("--threads")) {
    const auto n = positive_int(a.threads);
    if (!n) return usage_error("runout run", "--threads takes a positive integer, got '" + a.threads + "'");
    omp_set_num_threads(*n);
  }
  if (a.scenario.empty() || a.out.empty()) {
    return usage_error("runout run",
                       "usage: runout run SCENARIO.json --out DIR [--force] [--quiet] [--threads N] [--iseesnow "
                       "SIMULATION_ID] [--checkpoint FILE] [--restart FILE] (see runout run --help)");
  }
  return -1;
}

// The options of one kind of run only: single runs' and ensembles'. Returns an exit code, or -1.
int check_run_kind(const CLI::App& app, const RunArgs& a, bool ensemble, int& workers) {
  if (ensemble && (!a.checkpoint.empty() || !a.restart.empty() || !a.iseesnow.empty()))
    return usage_error("runout run", "--checkpoint, --restart and --iseesnow are for single runs; an ensemble keeps its members' "
                                     "checkpoints in its state directory (--state-dir)");
  if (!ensemble && (app.count("--state-dir") || app.count("--workers") || a.members || a.no_terrain_cache))
    return usage_error("runout run",
                       "--state-dir, --workers, --members and --no-terrain-cache are for ensembles (a scenario with variations)");
  if (app.count("--workers")) {
    const auto n = positive_int(a.workers);
    if (!n) return usage_error("runout run", "--workers takes a positive integer, got '" + a.workers + "'");
    workers = *n;
  }
  return -1;
}

// One run into the staged folder, with a progress line; the folder becomes DIR when complete.
int run_single(const jobs::ResolvedScenario& resolved, const RunArgs& a, StagedOutput& staged, const fs::path& dest) {
  const auto wall0 = std::chrono::steady_clock::now();
  const bool tty = isatty(fileno(stderr));
  jobs::RunOptions opt;
  opt.iseesnow_id = a.iseesnow;
  opt.checkpoint_path = a.checkpoint;
  opt.restart_path = a.restart;
  const double t_end = resolved.end_time_s();
  opt.progress = [&](const engine::Progress& p) {
    if (!a.quiet) {
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
      const double left = p.t > 0 ? wall * (t_end - p.t) / p.t : 0.0;
      std::fprintf(stderr, "%st = %7.2f s  dt = %.4f s  volume = %.4g m3  max speed = %6.2f m/s  active = %5.1f %%  time left <= %.0f s%s",
                   tty ? "\r" : "", p.t, p.dt, p.mass, p.max_speed, 100 * p.active_fraction, left, tty ? "   " : "\n");
      std::fflush(stderr);
    }
    return !g_interrupted.load();
  };
  jobs::RunSummary sum;
  if (const int rc = execute(resolved, staged.path(), opt, !a.quiet && tty, sum); rc != kOk) return rc;
  if (!a.quiet && tty) std::fprintf(stderr, "\n");
  if (sum.stop == "cancelled") {
    std::cerr << "runout run: cancelled at t = " << sum.t << " s; no results written\n";
    if (!a.checkpoint.empty())
      std::cerr << "runout run: checkpoint at t = " << sum.t << " s in " << a.checkpoint << " (continue with --restart " << a.checkpoint
                << ")\n";
    return kCancelled;
  }
  if (!staged.publish()) {
    std::cerr << "runout run: " << staged.error() << "\n";
    return kOutput;
  }
  if (!staged.note().empty()) std::cerr << "runout run: note: " << staged.note() << "\n";
  if (!a.quiet) print_summary(sum, resolved.engine == jobs::kVofLabEngine, dest);
  return kOk;
}

// An ensemble into the staged folder; the folder becomes DIR when complete.
int run_ensemble_into(const jobs::ResolvedScenario& resolved, const RunArgs& a, int workers, StagedOutput& staged, const fs::path& dest) {
  EnsembleRun er{staged.path().string(), a.state_dir, workers, a.quiet, bool(isatty(fileno(stderr))), a.members, !a.no_terrain_cache,
                 [] { return g_interrupted.load(); }};
  RunSummaryOut es;
  if (const int rc = run_ensemble(resolved, er, es); rc != kOk) return rc;
  if (!staged.publish()) {
    std::cerr << "runout run: " << staged.error() << "\n";
    return kOutput;
  }
  if (!a.quiet)
    std::printf("ensemble    %d members in %.1f s (job %s, state %s)\nresults in  %s\n", es.members, es.seconds, es.job.c_str(),
                es.state_dir.c_str(), dest.string().c_str());
  return kOk;
}

// A rank other than 0 of a run split over MPI ranks (`mpirun -n N runout run ...`): it takes its
// part of the 3D engine's steps and runs the same set-up and outputs into a private folder, which
// it removes; rank 0 writes DIR (docs/design/parallel.md). Its checks are rank 0's, but DIR is not
// its to check.
int run_other_rank(const jobs::ResolvedScenario& resolved, const RunArgs& a, int rank) {
  const jobs::RankScratch scratch(rank);
  if (!scratch.error().empty()) {
    std::cerr << "runout run (rank " << rank << "): " << scratch.error() << "\n";
    return kOutput;
  }
  jobs::RunOptions opt;
  opt.iseesnow_id = a.iseesnow;
  if (!a.checkpoint.empty()) opt.checkpoint_path = scratch.checkpoint_path();
  opt.restart_path = a.restart;
  opt.progress = [](const engine::Progress&) { return !g_interrupted.load(); };
  jobs::RunSummary sum;
  const int rc = execute(resolved, scratch.out_dir(), opt, false, sum);
  return rc != kOk ? rc : sum.stop == "cancelled" ? kCancelled : kOk;
}

// Rank 0's (or the only process's) run: DIR checked, staged and published.
int run_checked(const jobs::ResolvedScenario& resolved, const RunArgs& a, const fs::path& dest, bool ensemble, int workers) {
  {  // A previous result that --force replaces must not hold what this run reads or writes.
    std::vector<std::string> used = resolved.input_files;
    for (const auto& f : {fs::absolute(a.scenario).string(), a.checkpoint, a.restart}) used.push_back(f);
    if (const auto f = input_inside(dest, used); !f.empty()) {
      std::cerr << "runout run: output directory '" << a.out << "' holds '" << f
                << "', which this run needs: --force would delete it; choose another --out\n";
      return kOutput;
    }
  }
  // Results go to a temporary sibling directory first and appear under DIR only when complete.
  StagedOutput staged(dest, a.force);
  if (!staged.ok()) {
    std::cerr << "runout run: " << staged.error() << "\n";
    return kOutput;
  }
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
  return ensemble ? run_ensemble_into(resolved, a, workers, staged, dest) : run_single(resolved, a, staged, dest);
}

}  // namespace

int run(const std::vector<std::string>& args) {
  RunArgs a;
  CLI::App app{kRunHelp, "runout run"};
  add_run_options(app, a);
  if (const int rc = parse_args(app, args); rc >= 0) return rc;
  if (const int rc = check_run_args(app, a); rc >= 0) return rc;
  // DIR: absent, or with --force a previous result (output_dir.hpp); never anything else.
  const fs::path dest = output_path(a.out);
  if (const auto why = check_output_dir(dest, a.force, a.out); !why.empty()) {
    std::cerr << "runout run: " << why << "\n";
    return kOutput;
  }
  jobs::ResolvedScenario resolved;
  try {
    resolved = jobs::load_scenario(a.scenario);
  } catch (const jobs::ScenarioError& e) {
    std::cerr << "runout run: " << e.what() << "\n";
    return kBadInput;
  }
  const bool ensemble = jobs::ensemble::is_ensemble(resolved.scenario);
  int workers = 0;
  if (const int rc = check_run_kind(app, a, ensemble, workers); rc >= 0) return rc;
  const auto launch = jobs::launch_ranks();
  if (const int want = resolved.scenario.ranks(); want > 1 && want != launch.size && launch.rank == 0)
    std::cerr << "runout run: note: the scenario's ranks is " << want << ", this run has " << launch.size
              << " (runout run splits over the processes its launcher starts: mpirun -n " << want << " runout run ...)\n";
  if (launch.size > 1) {
    if (ensemble) {
      std::cerr << "runout run: an ensemble runs its members on this machine's cores itself (--workers); mpirun -n N is for one 3D run\n";
      return kUsage;
    }
    std::signal(SIGINT, on_interrupt);
    std::signal(SIGTERM, on_interrupt);
    const int rc = launch.rank > 0 ? run_other_rank(resolved, a, launch.rank) : run_checked(resolved, a, dest, ensemble, workers);
    jobs::finish_mpi(rc == kCancelled ? 0 : rc);  // (a cancel stops every rank at the same step)
    return rc;
  }
  const int rc = run_checked(resolved, a, dest, ensemble, workers);
  jobs::finish_mpi(0);  // a 3D run started MPI through PETSc: a launcher (mpirun -n 1) wants it finalised
  return rc;
}

}  // namespace runout::cli
