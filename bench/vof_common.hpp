// Shared by the VOF benchmarks (vof.cpp, vof_cases.cpp): reading run.json and running a scenario
// in a temporary directory.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "jobs/run.hpp"
#include "jobs/scenario.hpp"

namespace runout::bench {

// A number from run.json ("key": value; null or missing as NaN), searched from `from` on.
inline double field(const std::string& json, const std::string& key, std::size_t from = 0) {
  const auto k = json.find("\"" + key + "\": ", from);
  if (k == std::string::npos || json.compare(k + key.size() + 4, 4, "null") == 0) return NAN;
  return std::atof(json.c_str() + k + key.size() + 4);
}

// A number array from run.json ("key": [a, b, null, ...]; null as NaN).
inline std::vector<double> series(const std::string& json, const std::string& key) {
  std::vector<double> v;
  auto k = json.find("\"" + key + "\": [");
  if (k == std::string::npos) return v;
  k += key.size() + 5;
  const auto e = json.find(']', k);
  while (k < e) {
    while (k < e && (json[k] == ' ' || json[k] == ',')) ++k;
    if (k >= e) break;
    v.push_back(json.compare(k, 4, "null") == 0 ? NAN : std::atof(json.c_str() + k));
    k = json.find_first_of(",]", k);
  }
  return v;
}

// The scenario file scenarios/lab/NAME.json of this source tree.
inline runout::jobs::ResolvedScenario lab_scenario(const std::string& name) {
  return runout::jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab/" + name + ".json");
}

// Run a scenario in a temporary directory; its summary and run.json.
struct Ran {
  runout::jobs::RunSummary sum;
  std::string json;
};
inline Ran run_in_temp(const runout::jobs::ResolvedScenario& r) {
  namespace fs = std::filesystem;
  const fs::path out = fs::temp_directory_path() / ("runout-bench-vof-" + std::to_string(getpid()));
  fs::create_directories(out);
  Ran ran;
  ran.sum = runout::jobs::run_scenario(r, out.string());
  std::ifstream in(out / "run.json");
  std::stringstream ss;
  ss << in.rdbuf();
  ran.json = ss.str();
  fs::remove_all(out);
  return ran;
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

}  // namespace runout::bench
