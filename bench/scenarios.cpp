// End-to-end benchmark of the bundled scenarios: wall time and peak memory of `runout run` for each,
// at its native resolution. Each scenario runs in a child process so that its peak resident memory
// is its own.
//   runout_bench_scenarios [--repeat N] [SCENARIO.json ...]   (default: every scenarios/*.json but the
//   ensembles, which runout_bench_ensemble measures; N = 3)
// Prints the median wall time of N runs and its range; peak memory is the largest of the N.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "jobs/drivers/run.hpp"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  std::vector<std::string> files;
  int repeat = 3;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--repeat" && k + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++k]));
    } else if (a.rfind("--", 0) == 0) {
      std::fprintf(stderr, "usage: runout_bench_scenarios [--repeat N] [SCENARIO.json ...]\n");
      return 2;
    } else {
      files.push_back(a);
    }
  }
  if (files.empty()) {
    for (const auto& e : fs::directory_iterator(fs::path(RUNOUT_SOURCE_DIR) / "scenarios"))
      if (e.path().extension() == ".json" && e.path().stem().string().find("ensemble") == std::string::npos)
        files.push_back(e.path().string());  // ensembles: runout_bench_ensemble
    std::sort(files.begin(), files.end());
  }
  std::printf("| scenario | cells | cell size [m] | steps | simulated [s] | wall, median [s] | wall, range [s] | peak memory [MiB] | affected area [km2] | runout [m] | max speed [m/s] |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|\n");
  int failures = 0;
  for (const auto& f : files) {
    std::vector<double> walls;
    long maxrss = 0;
    char buf[512] = {0};
    bool failed = false;
    for (int rep = 0; rep < repeat; ++rep) {
      const fs::path out = fs::temp_directory_path() / ("runout-bench-" + std::to_string(getpid()));
      fs::remove_all(out);
      fs::create_directories(out);
      int pipefd[2];
      if (pipe(pipefd) != 0) return 3;
      const auto t0 = std::chrono::steady_clock::now();
      const pid_t pid = fork();
      if (pid == 0) {
        close(pipefd[0]);
        try {
          const auto r = runout::jobs::load_scenario(f);
          const auto s = runout::jobs::run_scenario(r, out.string());
          char line[512];
          const int n = std::snprintf(line, sizeof line, "%d %.1f %ld %.1f %.3f %.0f %.1f", s.nx * s.ny, s.dx, s.steps, s.t,
                                      s.affected_area_m2 / 1e6, s.runout_m, s.max_speed);
          if (write(pipefd[1], line, std::size_t(n)) < 0) _exit(4);
          _exit(0);
        } catch (const std::exception& e) {
          std::fprintf(stderr, "%s: %s\n", f.c_str(), e.what());
          _exit(1);
        }
      }
      close(pipefd[1]);
      int status = 0;
      rusage ru{};
      wait4(pid, &status, 0, &ru);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::fill(std::begin(buf), std::end(buf), '\0');
      const ssize_t got = read(pipefd[0], buf, sizeof buf - 1);
      close(pipefd[0]);
      fs::remove_all(out);
      if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || got <= 0) {
        failed = true;
        break;
      }
      walls.push_back(wall);
      maxrss = std::max(maxrss, long(ru.ru_maxrss));
    }
    if (failed) {
      std::printf("| %s | failed | | | | | | | | | |\n", fs::path(f).stem().c_str());
      ++failures;
      continue;
    }
    std::sort(walls.begin(), walls.end());
    const double wall = walls[walls.size() / 2];
    long cells = 0, steps = 0;
    double dx = 0, t = 0, area = 0, runout = 0, vmax = 0;
    std::sscanf(buf, "%ld %lf %ld %lf %lf %lf %lf", &cells, &dx, &steps, &t, &area, &runout, &vmax);
    std::printf("| %s | %ld | %.1f | %ld | %.1f | %.2f | %.2f-%.2f | %.0f | %.3f | %.0f | %.1f |\n", fs::path(f).stem().c_str(), cells,
                dx, steps, t, wall, walls.front(), walls.back(), maxrss / 1024.0, area, runout, vmax);
  }
  return failures ? 1 : 0;
}
