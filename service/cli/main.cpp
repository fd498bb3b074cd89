// runout: hazard mapping for rapid granular flows. Thin command-line front end over the libraries.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <exception>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "jobs/drivers/worker_task.hpp"
#include "service/cli/commands.hpp"

namespace {

const char* kHelp = R"(runout - hazard mapping for rapid granular flows: a depth-averaged Savage-Hutter engine
(engine "depth-averaged") for runout, depth, speed and pressure maps, and a 3D two-phase VOF engine
(engine "vof") on the DEM and on laboratory set-ups

usage: runout <command> [options]      (runout <command> --help: the command's options in detail)

commands:
  run SCENARIO.json --out DIR [--force] [--quiet] [--threads N] [--iseesnow SIMULATION_ID]
        [--checkpoint FILE] [--restart FILE] [--state-dir DIR] [--workers N] [--members] [--no-terrain-cache]
        Run a scenario (JSON form of runout.v1.Scenario, see README) and write the hazard rasters
        (COG GeoTIFF), the runout outline (GeoJSON in WGS84, GeoPackage) and the run record (run.json)
        into DIR. Results appear only when the run succeeded. An existing DIR is replaced only with
        --force and only when it holds a previous result (runout's run.json), once the new one is
        complete; another folder, a file, a link, or the current directory (or one that holds it) is
        never replaced. A progress line goes to standard error unless --quiet. --iseesnow also writes the
        ISeeSnow benchmark files (peak thickness/velocity ESRI ASCII on the DEM's grid, result CSV).
        --checkpoint writes the run's state to FILE when the run is interrupted (Ctrl-C, SIGTERM)
        and, for VOF runs (engine "vof"), every lab.checkpoint_interval_s; --restart continues from
        such a file of the same scenario exactly as the run would have gone on. VOF runs: the
        monitors travel in FILE, the frames so far in FILE.fields.h5, so run.json and fields.h5 are
        the whole run's. Depth-averaged runs: the solver's whole state and hazard maps travel in
        FILE, the time series so far in FILE.timeseries.h5; the continued run's outputs are the
        uninterrupted run's, bit for bit (docs/design/depth-averaged.md). A scenario with variations
        (an ensemble) or zoning (zones from scenarios by return period) runs its members on this
        machine's cores through the local job system (--state-dir DIR, --workers N; --members also
        copies each member's results) and writes the aggregate into DIR.
  verify [CASE...] [--full] [--resolutions R1,R2,...] [--limiter NAME] [--csv] [--threads N]
        Run the verification cases against exact solutions and invariants and print a table
        (or CSV). Cases: A1-A7 and STRESS (depth-averaged engine), V1-V7 (VOF engine); default: all.
        --full adds the finest resolutions. --resolutions overrides a case's cell sizes in metres
        (A2: cells across the cap).
        Limiters: minmod (default), vanleer, superbee.
  serve [--recover] [--config FILE] [--listen HOST:PORT] [--state-dir DIR] [--data-root DIR]... [--tokens FILE]
        [--tls-cert FILE --tls-key FILE] [--workers N] [--threads-per-run N] [--log-file FILE] [--backend local|slurm]
        Run the gRPC batch server (runout.v1.Runout, health checking, reflection) until SIGINT or
        SIGTERM; options override the JSON configuration file (deploy/README.md lists every key).
        Each job runs in a worker process of its own; jobs left running by a killed server are
        queued again at the next start. One server per state directory (a second one exits).
        --recover rebuilds a missing, empty or damaged job store from the job records, logs and
        results, then starts (docs/user/operations.md).
  submit SCENARIO.json [--wait] [--quiet] [--request-id ID] [--server-paths]
        Upload the scenario's input files and queue it; prints the job id and state. --wait follows
        the job to its end (progress on standard error). --server-paths sends the input paths as
        they are, for files inside the server's data roots.
  status [JOB] [--state STATE]...
        One job in detail (state history, error), or the list of this client's jobs and their disk use.
  watch JOB
        Follow a job's progress until it ends.
  cancel JOB
        Cancel a queued or running job.
  fetch JOB --out DIR [--force] [--members]
        Download a job's results (checksums verified) into DIR; for a failed job, its log. DIR as for
        run: --force replaces a previous result or a previous fetch of a failed job (job.log alone).
  health
        Ask the server's standard health service (no token needed); exit 0 when serving.
  regress [--server HOST:PORT] [--out DIR] [--scenario FILE] [--reference DIR] [--accept --reason TEXT]
        The In den Arelen regression: run the scenario through the service (an embedded server on
        127.0.0.1 unless --server), compare with the accepted reference, write report.md with the
        map and a difference map; exit 1 on a regression. --accept makes this run the reference.
  compare RUN OTHER --out DIR
        Two finished runs on the same grid side by side (e.g. the 3D engine's and the depth-averaged
        one's): runout, affected area, maximum depth and speed, the scenarios' points of interest;
        compare.md with the table, and the difference map of the maximum depth.
  report RUN --out FILE.pdf [--paper a4|a3] [--dpi N]
        A finished run on terrain as one PDF for a hazard report: the parameters in words, the mass
        balance, the results, the points of interest and zones as tables, each map at a stated 1:N
        scale (300 dpi rasters), the path profile.
  worker
        (Started by the server, not by hand.) Run one job handed over on standard input and report
        on standard output (service/proto/runout/v1/worker.proto; docs/user/operations.md).
  version
        Print the program version and the versions of the libraries it links.
  help [COMMAND]
        Print this text, or COMMAND's options (as runout COMMAND --help).

  The client commands (submit, status, watch, cancel, fetch, health, regress) take
  --server HOST:PORT (default $RUNOUT_SERVER or 127.0.0.1:50051), --token TOKEN or --token-file FILE
  (default $RUNOUT_TOKEN), and --tls-ca FILE or --tls for a server with TLS.

exit codes:
  0  success (verify: every checked figure within its tolerance)
  1  verify: at least one figure outside its tolerance
  2  bad command line (unknown command, option or name)
  3  internal error
  4  invalid scenario or input data (the message names the field or file); unknown job
  5  run, fetch: output directory exists (use --force), is not a previous result or cannot be written
  6  run: cancelled (interrupt); submit --wait, watch: the job was cancelled
  7  the server cannot be reached or refused the call (unknown token, queue limit, ...)
  8  submit --wait, watch, fetch: the job failed (its error is printed)
)";

}  // namespace

namespace runout::cli {
namespace {

// CLI11's formatter with the option descriptions wrapped at 100 columns.
class WrappingFormatter : public CLI::Formatter {
 public:
  std::string make_option_desc(const CLI::Option* opt) const override {
    const std::string& text = opt->get_description();
    const std::size_t width = 100 - get_column_width();
    std::string out, line, word;
    std::istringstream words(text);
    while (words >> word) {
      if (!line.empty() && line.size() + 1 + word.size() > width) {
        out += line + "\n";
        line.clear();
      }
      line += (line.empty() ? "" : " ") + word;
    }
    return out + line;
  }
};

}  // namespace

void prepare(CLI::App& app) {
  app.formatter(std::make_shared<WrappingFormatter>());
  // As before CLI11: an option given twice takes its last value (--data-root, --state collect all).
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.get_formatter()->column_width(32);
  app.set_help_flag("-h,--help", "Print this command's options and exit");
}

std::optional<int> positive_int(const std::string& v) {
  try {
    std::size_t used = 0;
    const int n = std::stoi(v, &used);
    if (used == v.size() && n >= 1) return n;
  } catch (...) {
  }
  return std::nullopt;
}

int usage_error(const std::string& name, const std::string& message) {
  std::cerr << name << ": " << message << "\n";
  return kUsage;
}

int parse_args(CLI::App& app, const std::vector<std::string>& args) {
  const std::string name = app.get_name();
  // Unknown words are reported here, in one shape, rather than by CLI11's ExtrasError.
  app.allow_extras();
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return kOk;
  } catch (const CLI::ParseError& e) {
    return usage_error(name, e.what());
  }
  for (const auto& a : app.remaining()) {
    if (a.size() > 1 && a[0] == '-')
      return usage_error(name, "unknown option '" + a + "' (see " + name + " --help)");
    return usage_error(name, "unexpected argument '" + a + "' (see " + name + " --help)");
  }
  return -1;
}

namespace {

// `runout worker`: no options; standard input and output are the worker protocol's, so nothing is
// printed on standard output unless --help is asked for by hand.
int worker(const std::vector<std::string>& args) {
  CLI::App app{"(Started by the server, not by hand.) Run one job handed over on standard input and report on\n"
               "standard output (service/proto/runout/v1/worker.proto; docs/user/operations.md). Takes no options.",
               "runout worker"};
  prepare(app);
  if (const int rc = parse_args(app, args); rc >= 0) return rc;
  return runout::jobs::worker_main(0, 1);
}

}  // namespace
}  // namespace runout::cli

int main(int argc, char** argv) {
  namespace cli = runout::cli;
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 2 && args[0] == "help" && args[1] != "help") {
    args = {args[1], "--help"};  // runout help COMMAND: as runout COMMAND --help
  } else if (args.empty() || args[0] == "help" || args[0] == "--help" || args[0] == "-h") {
    if (args.size() > 1) {
      std::cerr << "runout help: takes at most one command (runout help COMMAND: that command's options)\n";
      return cli::kUsage;
    }
    std::cout << kHelp;
    return args.empty() ? cli::kUsage : cli::kOk;
  }
  const std::string cmd = args[0];
  args.erase(args.begin());
  using Command = int (*)(const std::vector<std::string>&);
  const std::pair<const char*, Command> commands[] = {
      {"run", cli::run},       {"verify", cli::verify}, {"serve", cli::serve},   {"submit", cli::submit},
      {"status", cli::status}, {"watch", cli::watch},   {"cancel", cli::cancel}, {"fetch", cli::fetch},
      {"health", cli::health}, {"regress", cli::regress}, {"compare", cli::compare}, {"report", cli::report}, {"version", cli::version}, {"--version", cli::version},
      {"worker", cli::worker}};
  try {
    for (const auto& [name, fn] : commands)
      if (cmd == name) return fn(args);
    std::cerr << "runout: unknown command '" << cmd
              << "' (valid: run, verify, serve, submit, status, watch, cancel, fetch, health, regress, compare, report, version, help)\n";
    return cli::kUsage;
  } catch (const std::exception& e) {
    std::cerr << "runout: internal error: " << e.what() << "\n";
    return cli::kInternal;
  }
}
