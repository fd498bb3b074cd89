// runout regress: the nightly In den Arelen regression through the service (validation.md C1).
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "jobs/regression/regression.hpp"
#include "jobs/scenario/scenario.hpp"
#include "service/cli/commands.hpp"
#include "service/client/client.hpp"
#include "service/server/server.hpp"

namespace fs = std::filesystem;

namespace runout::cli {

namespace {

// A job of the service that ended, and the wall time from submission to its results downloaded.
struct ServiceRun {
  v1::Job fin;
  double wall = 0;
};

// Submits the scenario (its inputs uploaded), follows the job and downloads its results into
// `results`; nothing (and the reason on standard error) when the job did not succeed.
std::optional<ServiceRun> run_through_service(const service::ClientOptions& opt, const std::string& scenario,
                                              const fs::path& results) {
  std::error_code ec;
  const auto t0 = std::chrono::steady_clock::now();
  service::Client client(opt);
  std::ifstream in(scenario);
  if (!in) throw jobs::ScenarioError("cannot read scenario '" + scenario + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  auto s = jobs::parse_scenario_json(ss.str());
  s = service::upload_inputs(client, s, fs::absolute(scenario).parent_path().string());
  const auto job = client.submit(s, "");
  std::fprintf(stderr, "runout regress: job %s on %s\n", job.id().c_str(), opt.server.c_str());
  const auto fin = client.watch(job.id());
  if (fin.state() != v1::SUCCEEDED) {
    std::cerr << "runout regress: the job " << service::state_word(fin.state()) << (fin.error().empty() ? "" : ": " + fin.error())
              << "\n";
    return std::nullopt;
  }
  fs::remove_all(results, ec);
  fs::create_directories(results);
  const auto listing = client.results(job.id());
  for (const auto& f : listing.files()) client.download(job.id(), f.name(), (results / f.name()).string());
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return ServiceRun{fin, wall};
}

}  // namespace

int regress(const std::vector<std::string>& args) {
  service::ClientOptions opt;
  Connection conn;
  bool accept = false;
  std::string out, reason, scenario = std::string(RUNOUT_SOURCE_DIR) + "/scenarios/in-den-arelen.json",
                           reference = std::string(RUNOUT_SOURCE_DIR) + "/regression/in-den-arelen";
  CLI::App app{"The In den Arelen regression: run the scenario through the service (an embedded server on 127.0.0.1\n"
               "unless --server), compare with the accepted reference, write report.md with the map and a difference\n"
               "map. Exit 1 on a regression.",
               "runout regress"};
  prepare(app);
  add_connection_options(app, opt, conn, false);
  app.add_option("--out", out, "Report folder (default runs/regress-YYYYMMDD-HHMMSS)")->type_name("DIR");
  app.add_option("--scenario", scenario, "The scenario (default: scenarios/in-den-arelen.json of the source tree)")->type_name("FILE");
  app.add_option("--reference", reference, "The accepted reference (default: regression/in-den-arelen of the source tree)")->type_name("DIR");
  app.add_flag("--accept", accept, "Make this run the reference (needs --reason)");
  app.add_option("--reason", reason, "Why this run becomes the reference (recorded with it)")->type_name("TEXT");
  if (const int rc = parse_args(app, args); rc >= 0) return rc;
  if (const int rc = finish_connection_options(app, opt, conn); rc >= 0) return rc;
  const bool remote = app.count("--server") > 0;
  if (accept && reason.empty()) {
    std::cerr << "runout regress: --accept needs --reason TEXT (why this run becomes the reference)\n";
    return kUsage;
  }
  if (out.empty()) {
    char b[64];
    const std::time_t now = std::time(nullptr);
    std::strftime(b, sizeof b, "runs/regress-%Y%m%d-%H%M%S", std::gmtime(&now));
    out = b;
  }
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) {
    std::cerr << "runout regress: cannot create '" << out << "': " << ec.message() << "\n";
    return kOutput;
  }

  // The service: the given server, or one started here on a free loopback port.
  std::unique_ptr<service::Server> embedded;
  const fs::path state = fs::path(out) / ".service-state";
  try {
    if (!remote) {
      v1::ServerConfig cfg;
      cfg.set_listen("127.0.0.1:0");
      cfg.set_state_dir(state.string());
      cfg.set_log_file((fs::path(out) / "server.log").string());
      embedded = std::make_unique<service::Server>(cfg);
      embedded->start();
      opt.server = embedded->address();
    }
    const fs::path results = fs::path(out) / "run";
    const auto run = run_through_service(opt, scenario, results);
    if (!run) return kFailed;
    const auto& fin = run->fin;
    const double wall = run->wall;
    fs::copy_file(results / "map.png", fs::path(out) / "map.png", fs::copy_options::overwrite_existing);
    if (embedded) {
      embedded->shutdown();
      embedded.reset();
      fs::remove_all(state, ec);
    }

    const auto figures = jobs::measure_run(results.string());
    if (accept) {
      jobs::accept_reference(reference, figures, (results / "max_depth.tif").string(), reason, fin.scenario_hash(), RUNOUT_VERSION);
      std::printf("accepted as the reference in %s: runout %.0f m, affected area %.0f m2, max depth %.2f m, max speed %.1f m/s, "
                  "farmhouse %s\n",
                  reference.c_str(), figures.runout_m, figures.affected_area_m2, figures.max_depth_m, figures.max_speed_m_s,
                  figures.farmhouse_distance_m == 0 ? "reached" : "not reached");
    }
    const auto ref = jobs::read_reference(reference);
    const auto o = jobs::compare_run(figures, ref, (results / "max_depth.tif").string(), reference, out);
    jobs::write_report(out, o, ref, fin.id(), fin.scenario_hash(), wall);
    for (const auto& r : o.rows)
      std::printf("%-48s %14.6g %14.6g  %s\n", r.name.c_str(), r.reference, r.value, r.ok ? "ok" : "FAIL");
    std::printf("%s: report in %s\n", o.ok ? "PASS" : "REGRESSION", (fs::path(out) / "report.md").string().c_str());
    return o.ok ? kOk : kFailed;
  } catch (const service::RpcError& e) {
    std::cerr << "runout regress: " << e.what() << "\n";
    return kService;
  } catch (const service::ConfigError& e) {
    std::cerr << "runout regress: embedded server: " << e.what() << "\n";
    return kInternal;
  } catch (const jobs::ScenarioError& e) {
    std::cerr << "runout regress: " << e.what() << "\n";
    return kBadInput;
  } catch (const std::exception& e) {
    std::cerr << "runout regress: " << e.what() << "\n";
    return kFailed;
  }
}

}  // namespace runout::cli
