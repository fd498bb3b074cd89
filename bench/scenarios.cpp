// End-to-end benchmark of the bundled scenarios: wall time and peak memory of `runout run` for each,
// at its native resolution. Each scenario runs in a child process so that its peak resident memory
// is its own.
//   runout_bench_scenarios [SCENARIO.json ...]   (default: every scenarios/*.json)
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "jobs/run.hpp"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  std::vector<std::string> files(argv + 1, argv + argc);
  if (files.empty()) {
    for (const auto& e : fs::directory_iterator(fs::path(RUNOUT_SOURCE_DIR) / "scenarios"))
      if (e.path().extension() == ".json") files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
  }
  std::printf("| scenario | cells | cell size [m] | steps | simulated [s] | wall [s] | peak memory [MiB] | affected area [km2] | runout [m] | max speed [m/s] |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  int failures = 0;
  for (const auto& f : files) {
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
    char buf[512] = {0};
    const ssize_t got = read(pipefd[0], buf, sizeof buf - 1);
    close(pipefd[0]);
    fs::remove_all(out);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || got <= 0) {
      std::printf("| %s | failed | | | | | | | | |\n", fs::path(f).stem().c_str());
      ++failures;
      continue;
    }
    long cells = 0, steps = 0;
    double dx = 0, t = 0, area = 0, runout = 0, vmax = 0;
    std::sscanf(buf, "%ld %lf %ld %lf %lf %lf %lf", &cells, &dx, &steps, &t, &area, &runout, &vmax);
    std::printf("| %s | %ld | %.1f | %ld | %.1f | %.2f | %.0f | %.3f | %.0f | %.1f |\n", fs::path(f).stem().c_str(), cells, dx,
                steps, t, wall, ru.ru_maxrss / 1024.0, area, runout, vmax);
  }
  return failures ? 1 : 0;
}
