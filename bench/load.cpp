// Load benchmark of the batch service (loopback only, bounded): a real `runout serve` process, 8
// concurrent clients (one token each) submit 200 small, distinct scenarios in all, each submission
// sent twice with the same request id as a client retry would; then every job is followed to its end.
// Prints submit latency p50/p99, throughput, the server's peak memory, and whether any job was lost
// or duplicated.
//   runout_bench_load [--clients N] [--jobs N] [--workers N]
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "jobs/scenario/scenario.hpp"
#include "jobs/system/state_dir.hpp"
#include "service/client/client.hpp"

namespace fs = std::filesystem;
using namespace runout;
using clk = std::chrono::steady_clock;

namespace {

long peak_rss_kib(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atol(line.c_str() + 6);
  return 0;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, std::size_t(q * double(v.size() - 1) + 0.5))];
}

// Starts `runout serve` on a free loopback port; its pid and address (from STATE/server.json).
pid_t start_server(const fs::path& dir, int workers, std::string& address) {
  const std::string scenarios = std::string(RUNOUT_SOURCE_DIR) + "/scenarios";
  const pid_t pid = fork();
  if (pid == 0) {
    if (!std::freopen("/dev/null", "w", stdout)) _exit(126);
    execl(RUNOUT_BIN, RUNOUT_BIN, "serve", "--listen", "127.0.0.1:0", "--state-dir", (dir / "state").c_str(), "--tokens",
          (dir / "tokens").c_str(), "--data-root", scenarios.c_str(), "--workers", std::to_string(workers).c_str(), "--log-file",
          (dir / "server.log").c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  for (int k = 0; k < 300 && !fs::exists(dir / "state/server.json"); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  if (const auto info = jobs::read_server_info((dir / "state").string())) address = info->listen();
  return pid;
}

// The small scenario: In den Arelen on a 90 m grid.
v1::Scenario base_scenario() {
  v1::Scenario base;
  std::ifstream in(std::string(RUNOUT_SOURCE_DIR) + "/tests/data/arelen-30m.json");
  std::stringstream ss;
  ss << in.rdbuf();
  base = jobs::parse_scenario_json(ss.str());
  base.mutable_dem()->set_path("data/arelen/davos_srtm3.tif");
  base.mutable_area_of_interest()->set_path("data/arelen/aoi.geojson");
  base.mutable_releases(0)->set_path("data/arelen/release.geojson");
  base.mutable_releases(0)->clear_thickness_attribute();
  base.mutable_grid()->set_resolution_m(90);
  base.mutable_numerics()->set_end_time_s(120);
  return base;
}

// What the clients saw while submitting.
struct Submitted {
  std::vector<double> latencies;                 // of the first sends [ms]
  std::vector<std::vector<std::string>> ids;     // per client
  int failures = 0, retried_same = 0;
};

// `clients` threads, one token each, submit `jobs_total` scenarios in all (each its own release
// thickness), each twice with the same request id.
Submitted submit_all(const std::string& address, const v1::Scenario& base, int clients, int jobs_total) {
  std::mutex mu;
  std::vector<double> latencies;
  std::vector<std::vector<std::string>> ids(clients);
  std::atomic<int> failures{0}, retried_same{0};
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c)
    threads.emplace_back([&, c] {
      service::ClientOptions o;
      o.server = address;
      o.token = "client-token-" + std::to_string(c);
      service::Client cl(o);
      for (int k = c; k < jobs_total; k += clients) {
        v1::Scenario s = base;
        s.mutable_releases(0)->set_thickness_m(1.0 + 0.001 * k);
        s.set_name("load " + std::to_string(k));
        const std::string rid = "load-" + std::to_string(k);
        try {
          const auto a = clk::now();
          const auto j = cl.submit(s, rid);
          const double ms = std::chrono::duration<double, std::milli>(clk::now() - a).count();
          const auto again = cl.submit(s, rid);  // a client retry
          {
            std::lock_guard lk(mu);
            latencies.push_back(ms);
          }
          if (again.id() == j.id()) ++retried_same;
          ids[c].push_back(j.id());
        } catch (const std::exception& e) {
          std::fprintf(stderr, "client %d: %s\n", c, e.what());
          ++failures;
        }
      }
    });
  for (auto& t : threads) t.join();
  return {latencies, ids, failures.load(), retried_same.load()};
}

// Follows every job to its end and lists each client's jobs: (succeeded, other, distinct ids, listed).
struct Followed {
  int succeeded = 0, other = 0;
  std::size_t distinct = 0, listed = 0;
};
Followed follow_all(const std::string& address, const std::vector<std::vector<std::string>>& ids, int clients) {
  int succeeded = 0, other = 0;
  std::set<std::string> distinct;
  std::size_t listed = 0;
  for (int c = 0; c < clients; ++c) {
    service::ClientOptions o;
    o.server = address;
    o.token = "client-token-" + std::to_string(c);
    service::Client cl(o);
    for (const auto& id : ids[c]) {
      distinct.insert(id);
      const auto j = cl.watch(id);
      (j.state() == v1::SUCCEEDED ? succeeded : other) += 1;
    }
    std::string token;
    do {
      const auto page = cl.list({}, 500, token);
      listed += std::size_t(page.jobs_size());
      token = page.next_page_token();
    } while (!token.empty());
  }
  return {succeeded, other, distinct.size(), listed};
}

}  // namespace

int main(int argc, char** argv) {
  int clients = 8, jobs_total = 200, workers = 2;
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string a = argv[k];
    const int v = std::atoi(argv[k + 1]);
    if (a == "--clients") clients = std::max(1, v);
    else if (a == "--jobs") jobs_total = std::max(1, v);
    else if (a == "--workers") workers = std::max(1, v);
    else {
      std::fprintf(stderr, "usage: runout_bench_load [--clients N] [--jobs N] [--workers N]\n");
      return 2;
    }
  }
  const fs::path dir = fs::temp_directory_path() / ("runout-bench-load-" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  {
    std::ofstream t(dir / "tokens");
    for (int c = 0; c < clients; ++c) t << "client-token-" << c << "\n";
  }
  std::string address;
  const pid_t pid = start_server(dir, workers, address);
  const long rss_idle = peak_rss_kib(pid);

  const v1::Scenario base = base_scenario();
  const auto t0 = clk::now();
  const Submitted sub = submit_all(address, base, clients, jobs_total);
  const auto& latencies = sub.latencies;
  const double submit_s = std::chrono::duration<double>(clk::now() - t0).count();

  const Followed fol = follow_all(address, sub.ids, clients);
  const int succeeded = fol.succeeded, other = fol.other;
  const std::size_t listed = fol.listed;
  const double total_s = std::chrono::duration<double>(clk::now() - t0).count();
  const long rss_peak = peak_rss_kib(pid);
  kill(pid, SIGTERM);
  int st = 0;
  waitpid(pid, &st, 0);
  fs::remove_all(dir);

  std::printf("| figure | value |\n|---|---:|\n");
  std::printf("| clients x submissions (each sent twice, same request id) | %d x %d |\n", clients, jobs_total / clients);
  std::printf("| server workers | %d |\n", workers);
  std::printf("| submit latency p50 | %.2f ms |\n", quantile(latencies, 0.5));
  std::printf("| submit latency p99 | %.2f ms |\n", quantile(latencies, 0.99));
  std::printf("| submissions per second (first sends) | %.0f |\n", double(latencies.size()) / submit_s);
  std::printf("| jobs run to the end per second | %.1f |\n", double(succeeded) / total_s);
  std::printf("| wall time, first submission to last job done | %.2f s |\n", total_s);
  std::printf("| server peak memory (idle / end) | %.0f / %.0f MiB |\n", rss_idle / 1024.0, rss_peak / 1024.0);
  std::printf("| jobs: submitted / distinct ids / listed / succeeded / other | %d / %zu / %zu / %d / %d |\n", jobs_total,
              fol.distinct, listed, succeeded, other);
  std::printf("| retries answered with the first job | %d of %d |\n", sub.retried_same, jobs_total);
  const bool ok = sub.failures == 0 && int(fol.distinct) == jobs_total && int(listed) == jobs_total && succeeded == jobs_total &&
                  sub.retried_same == jobs_total;
  std::printf("%s\n", ok ? "none lost, none duplicated" : "LOST OR DUPLICATED JOBS");
  return ok ? 0 : 1;
}
