// runout regress: the nightly In den Arelen regression through the service, with both engines
// (validation.md C1): each case's scenario against its accepted reference.
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

// A regression case: its name, scenario and accepted reference (in the source tree).
struct RegressionCase {
  std::string name, scenario, reference;
};

// Every engine's case, run one after the other by a plain `runout regress`.
std::vector<RegressionCase> bundled_cases() {
  const std::string src = RUNOUT_SOURCE_DIR;
  return {{"in-den-arelen", src + "/scenarios/in-den-arelen.json", src + "/regression/in-den-arelen"},
          {"in-den-arelen-3d", src + "/scenarios/in-den-arelen-3d-regress.json", src + "/regression/in-den-arelen-3d"}};
}

// One case through the service into `out`: the comparison (and the acceptance); true when it passed.
bool run_case(const service::ClientOptions& opt, const RegressionCase& c, const fs::path& out, bool accept, const std::string& reason) {
  fs::create_directories(out);
  const fs::path results = out / "run";
  const auto run = run_through_service(opt, c.scenario, results);
  if (!run) return false;
  const auto& fin = run->fin;
  fs::copy_file(results / "map_max_depth.png", out / "map.png", fs::copy_options::overwrite_existing);
  const auto figures = jobs::measure_run(results.string());
  if (accept) {
    jobs::accept_reference(c.reference, figures, (results / "max_depth.tif").string(), reason, fin.scenario_hash(), RUNOUT_VERSION);
    std::printf("%s: accepted as the reference in %s: runout %.0f m, affected area %.0f m2, max depth %.2f m, max speed %.1f m/s, "
                "farmhouse %s\n",
                c.name.c_str(), c.reference.c_str(), figures.runout_m, figures.affected_area_m2, figures.max_depth_m, figures.max_speed_m_s,
                figures.farmhouse_distance_m == 0 ? "reached" : "not reached");
  }
  const auto ref = jobs::read_reference(c.reference);
  const auto o = jobs::compare_run(figures, ref, (results / "max_depth.tif").string(), c.reference, out.string());
  jobs::write_report(out.string(), o, ref, fin.id(), fin.scenario_hash(), run->wall);
  std::printf("%s (%.0f s)\n", c.name.c_str(), run->wall);
  for (const auto& r : o.rows) std::printf("  %-46s %14.6g %14.6g  %s\n", r.name.c_str(), r.reference, r.value, r.ok ? "ok" : "FAIL");
  std::printf("%s: report in %s\n", o.ok ? "PASS" : "REGRESSION", (out / "report.md").string().c_str());
  return o.ok;
}

}  // namespace

int regress(const std::vector<std::string>& args) {
  service::ClientOptions opt;
  Connection conn;
  bool accept = false;
  std::string out, reason, scenario, reference, only;
  CLI::App app{"The In den Arelen regression with both engines: each case's scenario through the service (an embedded\n"
               "server on 127.0.0.1 unless --server), compared with its accepted reference; report.md with the map and a\n"
               "difference map per case. Exit 1 on a regression.",
               "runout regress"};
  prepare(app);
  add_connection_options(app, opt, conn, false);
  app.add_option("--out", out, "Report folder (default runs/regress-YYYYMMDD-HHMMSS); one folder per case inside it")->type_name("DIR");
  app.add_option("--case", only, "Run only this case: in-den-arelen (depth-averaged) or in-den-arelen-3d (the 3D engine at 90 m)")
      ->type_name("NAME");
  app.add_option("--scenario", scenario, "One case of this scenario instead (its report directly in --out)")->type_name("FILE");
  app.add_option("--reference", reference, "One case against this reference instead (default: the first case's)")->type_name("DIR");
  app.add_flag("--accept", accept, "Make this run the reference (needs --reason, and --case or --reference)");
  app.add_option("--reason", reason, "Why this run becomes the reference (recorded with it)")->type_name("TEXT");
  if (const int rc = parse_args(app, args); rc >= 0) return rc;
  if (const int rc = finish_connection_options(app, opt, conn); rc >= 0) return rc;
  const bool remote = app.count("--server") > 0;
  if (accept && reason.empty()) {
    std::cerr << "runout regress: --accept needs --reason TEXT (why this run becomes the reference)\n";
    return kUsage;
  }
  // The cases: one given by --scenario/--reference (reported into --out itself), or the bundled ones
  // (each into --out/NAME).
  std::vector<RegressionCase> cases = bundled_cases();
  const bool single = !scenario.empty() || !reference.empty();
  if (single) {
    cases = {{"custom", scenario.empty() ? cases[0].scenario : scenario, reference.empty() ? cases[0].reference : reference}};
  } else if (!only.empty()) {
    std::vector<RegressionCase> picked;
    for (const auto& c : cases)
      if (c.name == only) picked.push_back(c);
    if (picked.empty()) {
      std::cerr << "runout regress: --case: unknown '" << only << "' (valid: in-den-arelen, in-den-arelen-3d)\n";
      return kUsage;
    }
    cases = picked;
  }
  if (accept && cases.size() > 1) {
    std::cerr << "runout regress: --accept takes one case: name it with --case\n";
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
    bool ok = true;
    for (const auto& c : cases) ok = run_case(opt, c, single ? fs::path(out) : fs::path(out) / c.name, accept, reason) && ok;
    if (embedded) {
      embedded->shutdown();
      embedded.reset();
      fs::remove_all(state, ec);
    }
    return ok ? kOk : kFailed;
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
