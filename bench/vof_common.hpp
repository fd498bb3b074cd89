// Shared by the VOF benchmarks (vof.cpp, vof_cases.cpp): reading run.json (the run record) and running a scenario
// in a temporary directory.
#pragma once

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <utility>
#include <vector>

#include <google/protobuf/util/json_util.h>

#include "jobs/drivers/run.hpp"
#include "jobs/formats/run_record.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::bench {

// run.json's text parsed as the run record (an empty record when the run failed).
inline runout::v1::RunRecord record(const std::string& json) {
  runout::v1::RunRecord r;
  google::protobuf::util::JsonParseOptions o;
  o.ignore_unknown_fields = true;
  if (!json.empty() && !google::protobuf::util::JsonStringToMessage(json, &r, o).ok()) return {};
  return r;
}

// Which part of the record field() reads: the whole record, station k (its index), or none.
constexpr std::size_t kWholeRecord = std::string::npos - 1;
constexpr std::size_t kNoStation = std::string::npos;

// A number of the record by its field name (jobs::figure_by_name; NaN when missing or not
// computed), of the whole record or of one station.
inline double field(const std::string& json, const std::string& key, std::size_t station = kWholeRecord) {
  const auto r = record(json);
  if (station == kWholeRecord) return runout::jobs::figure_by_name(r, key);
  if (station >= std::size_t(r.stations_size())) return NAN;
  return runout::jobs::figure_by_name(r.stations(int(station)), key);
}

// A list of numbers of the record by its field name ("NaN" entries as NaN).
inline std::vector<double> series(const std::string& json, const std::string& key) {
  return runout::jobs::series_by_name(record(json), key);
}

// The scenario file scenarios/lab/NAME.json of this source tree.
inline runout::jobs::ResolvedScenario lab_scenario(const std::string& name) {
  return runout::jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab/" + name + ".json");
}

// Run a scenario in a temporary directory; its summary and run.json, or the error that ended it
// (then json is empty and every figure reads as NaN). With the environment variable
// RUNOUT_BENCH_KEEP=DIR the run directory is kept instead, as DIR/NAME (NAME the scenario file's
// stem, then NAME-2, NAME-3, ... for later runs of the same file), with its figures and fields.
struct Ran {
  runout::jobs::RunSummary sum;
  std::string json;
  std::string error;
};
inline std::filesystem::path kept_run_dir(const std::string& keep, const runout::jobs::ResolvedScenario& r) {
  namespace fs = std::filesystem;
  fs::create_directories(keep);
  const std::string stem = r.source.empty() ? std::string("run") : fs::path(r.source).stem().string();
  for (int k = 1;; ++k) {
    const fs::path p = fs::path(keep) / (k == 1 ? stem : stem + "-" + std::to_string(k));
    if (fs::create_directory(p)) return p;  // false when it exists: the next name (parallel runs too)
  }
}
inline Ran run_in_temp(const runout::jobs::ResolvedScenario& r) {
  namespace fs = std::filesystem;
  const char* keep = std::getenv("RUNOUT_BENCH_KEEP");
  const bool kept = keep != nullptr && *keep != 0;
  const fs::path out =
      kept ? kept_run_dir(keep, r) : fs::temp_directory_path() / ("runout-bench-vof-" + std::to_string(getpid()));
  struct Remove {
    fs::path p;
    ~Remove() {
      std::error_code ec;
      if (!p.empty()) fs::remove_all(p, ec);
    }
  } remove{kept ? fs::path() : out};
  fs::create_directories(out);
  Ran ran;
  try {
    ran.sum = runout::jobs::run_scenario(r, out.string());
  } catch (const std::exception& e) {
    ran.error = e.what();
    std::fprintf(stderr, "runout_bench_vof: the run failed: %s\n", e.what());
    return ran;
  }
  std::ifstream in(out / "run.json");
  std::stringstream ss;
  ss << in.rdbuf();
  ran.json = ss.str();
  return ran;
}

// In a child of run_all: one run, its record (.json) and its summary (.meta) for the parent.
inline int write_child_result(const runout::jobs::ResolvedScenario& r, const std::filesystem::path& json_path,
                              const std::filesystem::path& meta_path) {
  int rc = 0;
  try {
    const Ran ran = run_in_temp(r);
    std::string error = ran.error;
    std::replace(error.begin(), error.end(), '\n', ' ');
    std::ofstream(json_path) << ran.json;
    std::ofstream meta(meta_path);
    meta.precision(17);
    const auto& u = ran.sum;
    meta << u.stop << "\n";
    for (double x : {double(u.steps), u.seconds_run, u.t, double(u.nx), double(u.ny), u.runout_m, u.max_speed, u.max_depth,
                     u.volume_initial, u.volume_final, u.volume_error})
      meta << x << "\n";
    meta << error << "\n";
  } catch (...) {
    rc = 1;
  }
  return rc;
}

// In run_all: the result of a child that ended with `status`, from the files it wrote.
inline Ran read_child_result(int status, const std::filesystem::path& json_path, const std::filesystem::path& meta_path) {
  Ran ran;
  std::ifstream meta(meta_path);
  std::string stop;
  std::vector<std::string> v(11);
  bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && std::getline(meta, stop);
  for (auto& x : v) ok = ok && std::getline(meta, x);
  if (ok) {
    auto num = [&](int q) { return std::strtod(v[std::size_t(q)].c_str(), nullptr); };
    auto& u = ran.sum;
    u.stop = stop;
    u.steps = long(num(0)), u.seconds_run = num(1), u.t = num(2), u.nx = int(num(3)), u.ny = int(num(4));
    u.runout_m = num(5), u.max_speed = num(6), u.max_depth = num(7), u.volume_initial = num(8), u.volume_final = num(9),
    u.volume_error = num(10);
    std::getline(meta, ran.error);
    std::ifstream in(json_path);
    std::stringstream ss;
    ss << in.rdbuf();
    ran.json = ss.str();
  } else {
    ran.error = WIFSIGNALED(status) ? "the run's process ended with signal " + std::to_string(WTERMSIG(status))
                                    : "the run's process ended with status " + std::to_string(WEXITSTATUS(status));
    std::fprintf(stderr, "runout_bench_vof: %s\n", ran.error.c_str());
  }
  return ran;
}

// Run scenarios as run_in_temp does, at most `jobs` at a time, each in a child process of its own,
// and hand each result to `done(k, ran)` in the given order as soon as it and all before it have
// finished (so tables fill in as the runs end). jobs 0: as many as the machine has cores; 1: one
// after the other in this process. The callers fork before anything starts PETSc, MPI or HDF5 in
// this process (they only load scenarios first). A child that dies (a signal, memory) gives a
// result with the error set. Of the summary, the children hand back the stop, steps, wall time,
// simulated time, cells, runout, peak speed and depth and the volumes; the rest is in run.json.
template <class Done>
void run_all(const std::vector<runout::jobs::ResolvedScenario>& rs, int jobs, Done done) {
  namespace fs = std::filesystem;
  if (jobs == 0) jobs = int(std::max(1u, std::thread::hardware_concurrency()));
  if (jobs <= 1 || rs.size() <= 1) {
    for (std::size_t k = 0; k < rs.size(); ++k) done(k, run_in_temp(rs[k]));
    return;
  }
  std::fflush(stdout);
  std::fflush(stderr);
  const fs::path dir = fs::temp_directory_path() / ("runout-bench-vof-all-" + std::to_string(getpid()));
  fs::create_directories(dir);
  auto file = [&](std::size_t k, const char* ext) { return dir / (std::to_string(k) + ext); };
  std::vector<Ran> out(rs.size());
  std::vector<bool> ready(rs.size(), false);
  std::size_t next = 0;  // the next result to hand on
  auto deliver = [&] {
    while (next < rs.size() && ready[next]) {
      done(next, out[next]);
      ++next;
    }
  };
  std::vector<std::pair<pid_t, std::size_t>> running;
  auto collect = [&](std::size_t q, int status) {
    const std::size_t k = running[q].second;
    running.erase(running.begin() + long(q));
    out[k] = read_child_result(status, file(k, ".json"), file(k, ".meta"));
    ready[k] = true;
  };
  // Wait for one of the running children; false when none can be waited for.
  auto wait_one = [&] {
    for (;;) {
      int status = 0;
      const pid_t pid = waitpid(-1, &status, 0);
      if (pid < 0) {
        if (errno == EINTR) continue;
        for (const auto& [p, k] : running) {  // lost (e.g. reaped elsewhere): no result
          out[k].error = "the run's process could not be waited for";
          ready[k] = true;
        }
        running.clear();
        return false;
      }
      for (std::size_t q = 0; q < running.size(); ++q)
        if (running[q].first == pid) {
          collect(q, status);
          return true;
        }
    }
  };
  for (std::size_t k = 0; k < rs.size(); ++k) {
    while (int(running.size()) >= jobs && wait_one()) deliver();
    const pid_t pid = fork();
    if (pid == 0) {
      const int rc = write_child_result(rs[k], file(k, ".json"), file(k, ".meta"));
      std::fflush(stdout);
      std::fflush(stderr);
      _exit(rc);
    }
    if (pid < 0) {
      out[k].error = "could not start a process for the run";
      ready[k] = true;
    } else {
      running.emplace_back(pid, k);
    }
    deliver();
  }
  while (!running.empty() && wait_one()) deliver();
  deliver();
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// A list of named checks, printed as "met" / "NOT MET" lines; failed() counts the misses.
class Checks {
 public:
  explicit Checks(std::string case_name) : name_(std::move(case_name)) {}
  void operator()(bool ok, const std::string& what) {
    lines_.push_back(std::string(ok ? "met" : "NOT MET") + ": " + what);
    failed_ += !ok;
  }
  // Prints the lines and the verdict; the exit status for the benchmark (1 if one failed).
  int report() const {
    std::printf("\n");
    for (const auto& l : lines_) std::printf("%s\n", l.c_str());
    std::printf("%s: %s\n", name_.c_str(), failed_ ? "NOT MET" : "met");
    return failed_ ? 1 : 0;
  }
  int failed() const { return failed_; }

 private:
  std::string name_;
  std::vector<std::string> lines_;
  int failed_ = 0;
};


// The invariants for a run (alpha within [0, 1] up to 1e-6, face fluxes divergence-free to
// the solver tolerance), and that it finished.
inline void invariants(Checks& c, const std::string& what, const Ran& ran) {
  const std::string& j = ran.json;
  c(ran.error.empty() && ran.sum.stop == "end-time",
    what + ": the run finished" + (ran.error.empty() ? std::string() : " (it failed: " + ran.error + ")"));
  c(field(j, "alpha_min") > -1e-6 && field(j, "alpha_max") < 1 + 1e-6, what + ": alpha within [0, 1] up to 1e-6");
  // Divergence-free to the solver tolerance: the largest cell's flux imbalance over the run against
  // the flow's velocity-gradient scale (peak speed over the smallest cell size), at most 1e-6: a
  // hundred times the last pressure solve's relative tolerance (1e-8), a bound of our choosing.
  // An absolute bound in 1/s would tighten with every refinement.
  double h = field(j, "dx_m");
  for (const char* k : {"dy_m", "dz_m"})
    if (std::isfinite(field(j, k))) h = std::min(h, field(j, k));
  const double div = field(j, "max_divergence_1_s"), scale = std::max(field(j, "peak_speed_m_s"), 1e-3) / h;
  char b[200];
  std::snprintf(b, sizeof b,
                ": face fluxes divergence-free to the solver tolerance (largest %.1e 1/s, %.1e of peak speed / cell size; at most 1e-6)", div,
                div / scale);
  c(div / scale <= 1e-6, what + b);
}

}  // namespace runout::bench
