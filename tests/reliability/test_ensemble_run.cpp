// `runout run` on an ensemble, end to end through the local job system: the products, an answer from
// the members computed before, and an ensemble interrupted (SIGTERM) and run again that gives the
// aggregate of an uninterrupted one, bit for bit.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <algorithm>
#include <thread>

#include "tests/support/server_process.hpp"
#include "tests/support/temp_dir.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kBin = runout::test_support::runout_binary();
const std::string kScenario = std::string(RUNOUT_SOURCE_DIR) + "/tests/data/arelen-ensemble-30m.json";

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

int run(const std::string& out, const std::string& state) {
  const std::string cmd = kBin + " run " + kScenario + " --out " + out + " --state-dir " + state + " --workers 2 --quiet";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

// Every raster and the runout table of two aggregates are the same bytes.
void expect_same_aggregate(const fs::path& a, const fs::path& b) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(a)) {
    const auto ext = e.path().extension();
    if (ext != ".tif" && ext != ".csv") continue;
    ++n;
    EXPECT_EQ(read_file(e.path()), read_file(b / e.path().filename())) << e.path().filename();
  }
  EXPECT_EQ(n, 4 + 9 + 1);  // probabilities (depth, speed, two pressures), percentiles, runout table
}

}  // namespace

TEST(EnsembleRun, WritesTheAggregateAndAnswersAgainFromTheMembers) {
  runout::test_support::TempDir tmp;
  const fs::path out = tmp.p / "a", again = tmp.p / "b", state = tmp.p / "state";
  ASSERT_EQ(run(out.string(), state.string()), 0);
  for (const char* f : {"run.json", "probability_depth_0.1m.tif", "probability_depth_0.1m.qml", "probability_pressure_30kPa.tif",
                        "max_depth_p50.tif", "max_pressure_p95.tif", "runout_distribution.csv", "runout_histogram.png",
                        "map_probability_depth_0.1m.png"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const std::string csv = read_file(out / "runout_distribution.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5) << csv;  // a header and four members
  EXPECT_NE(read_file(out / "run.json").find("\"kind\": \"ensemble\""), std::string::npos);
  // The same ensemble again: its aggregate is there already.
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(run(again.string(), state.string()), 0);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  expect_same_aggregate(out, again);
}

TEST(EnsembleRun, AnInterruptedEnsembleContinuesToTheSameAggregate) {
  runout::test_support::TempDir tmp;
  const fs::path whole = tmp.p / "whole", resumed = tmp.p / "resumed";
  ASSERT_EQ(run(whole.string(), (tmp.p / "s1").string()), 0);
  // Interrupt the ensemble once its first member has finished (its results are in place).
  const fs::path state = tmp.p / "s2";
  const pid_t pid = fork();
  if (pid == 0) {
    execl(kBin.c_str(), kBin.c_str(), "run", kScenario.c_str(), "--out", resumed.c_str(), "--state-dir", state.c_str(), "--workers", "1",
          "--quiet", (char*)nullptr);
    _exit(127);
  }
  auto finished = [&] {
    int n = 0;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(state / "results", ec))
      n += e.path().filename().string().find(".tmp-") == std::string::npos;
    return n;
  };
  const auto t0 = std::chrono::steady_clock::now();
  while (finished() < 1 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_GE(finished(), 1);
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 6);  // cancelled: no result
  EXPECT_FALSE(fs::exists(resumed));
  ASSERT_LT(finished(), 4) << "the ensemble finished before it could be interrupted";
  ASSERT_EQ(run(resumed.string(), state.string()), 0);
  expect_same_aggregate(whole, resumed);
}

// `runout run` on the bundled zoning (three return periods) through the local job system: the zones,
// their polygons and map, each scenario's pressure map beside them, and the record of kind "zoning".
TEST(EnsembleRun, AZoningWritesTheZonesAndEachScenariosMap) {
  runout::test_support::TempDir tmp;
  const fs::path out = tmp.p / "zones";
  const std::string cmd = kBin + " run " + std::string(RUNOUT_SOURCE_DIR) + "/scenarios/in-den-arelen-zoning.json --out " + out.string() +
                          " --state-dir " + (tmp.p / "state").string() + " --workers 2 --quiet";
  const int rc = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(rc) && WEXITSTATUS(rc) == 0) << cmd;
  for (const char* f : {"zones.tif", "zones.qml", "zones.gpkg", "zones.geojson", "map_zones.png", "map_max_pressure_30y.png",
                        "map_max_pressure_100y.png", "map_max_pressure_300y.png", "max_depth_300y.tif", "run.json"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const std::string rec = read_file(out / "run.json");
  EXPECT_NE(rec.find("\"kind\": \"zoning\""), std::string::npos);
  EXPECT_NE(rec.find("\"guideline\": \"BFF & EISLF (1984)"), std::string::npos);
}
