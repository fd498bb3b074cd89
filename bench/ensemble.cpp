// End-to-end benchmark of an ensemble through `runout run` (the local job system, every core): the
// wall time, members per minute, and where the members' time goes (terrain preparation, solve,
// writing), without and with the terrain cache, side by side in one run.
//   runout_bench_ensemble [--scenario ENSEMBLE.json] [--workers N]
//   (default: scenarios/in-den-arelen-ensemble.json, 100 members at 10 m; N: every core)
// Each mode starts from an empty state directory, so no member answers from an earlier result.
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "jobs/formats/run_record.hpp"

namespace fs = std::filesystem;

namespace {

struct Figures {
  double wall = 0, prepare = 0, solve = 0, write = 0;
  int members = 0;
};

std::string text_of(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

Figures run(const std::string& scenario, const std::string& workers, bool cache, const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string cmd = std::string(RUNOUT_BIN) + " run " + scenario + " --out " + (dir / "out").string() + " --state-dir " +
                    (dir / "state").string() + " --quiet" + (workers.empty() ? "" : " --workers " + workers) +
                    (cache ? "" : " --no-terrain-cache");
  const auto t0 = std::chrono::steady_clock::now();
  const int rc = std::system(cmd.c_str());
  Figures f;
  f.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!WIFEXITED(rc) || WEXITSTATUS(rc) != 0) {
    std::fprintf(stderr, "runout_bench_ensemble: '%s' failed\n", cmd.c_str());
    std::exit(1);
  }
  for (const auto& e : fs::directory_iterator(dir / "state" / "results")) {
    const auto rec = e.path() / "run.json";
    if (!fs::exists(rec) || text_of(rec).find("\"kind\": \"ensemble\"") != std::string::npos) continue;
    const auto r = runout::jobs::read_run_record(rec.string());
    f.prepare += r.timings_s().prepare();
    f.solve += r.timings_s().run();
    f.write += r.timings_s().write();
    ++f.members;
  }
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenario = std::string(RUNOUT_SOURCE_DIR) + "/scenarios/in-den-arelen-ensemble.json", workers;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--scenario" && k + 1 < argc) scenario = argv[++k];
    else if (a == "--workers" && k + 1 < argc) workers = argv[++k];
    else {
      std::fprintf(stderr, "usage: runout_bench_ensemble [--scenario ENSEMBLE.json] [--workers N]\n");
      return 2;
    }
  }
  const fs::path tmp = fs::temp_directory_path() / ("runout-bench-ensemble-" + std::to_string(getpid()));
  const int cores = int(sysconf(_SC_NPROCESSORS_ONLN));
  std::printf("ensemble %s, %s workers (%d cores)\n\n", fs::path(scenario).filename().c_str(), workers.empty() ? "all" : workers.c_str(),
              cores);
  std::printf("| terrain cache | members | wall [s] | members per minute | preparation [s, sum] | solve [s, sum] | write [s, sum] | "
              "preparation share | other per member [s] |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const bool cache : {false, true}) {
    const Figures f = run(scenario, workers, cache, tmp / (cache ? "cache" : "none"));
    const int w = workers.empty() ? cores : std::atoi(workers.c_str());
    const double busy = f.prepare + f.solve + f.write;
    // What a member costs besides its own run: its worker process, the scheduler, the aggregate.
    const double other = f.members ? (f.wall * std::min(w, f.members) - busy) / f.members : 0;
    std::printf("| %s | %d | %.1f | %.1f | %.2f | %.1f | %.2f | %.1f %% | %.2f |\n", cache ? "on" : "off", f.members, f.wall,
                60.0 * f.members / f.wall, f.prepare, f.solve, f.write, 100 * f.prepare / busy, other);
    std::fflush(stdout);
  }
  fs::remove_all(tmp);
  return 0;
}
