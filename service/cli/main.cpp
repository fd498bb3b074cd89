// runout: hazard mapping for rapid granular flows. Thin command-line front end over the libraries.
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "service/cli/commands.hpp"

namespace {

const char* kHelp = R"(runout - hazard mapping for rapid granular flows (depth-averaged Savage-Hutter engine)

usage: runout <command> [options]

commands:
  run SCENARIO.json --out DIR [--force] [--quiet] [--threads N] [--iseesnow SIMULATION_ID]
        Run a scenario (JSON form of runout.v1.Scenario, see README) and write the hazard rasters
        (COG GeoTIFF), the runout outline (GeoJSON in WGS84, GeoPackage) and the run record (run.json)
        into DIR. Results appear only when the run succeeded; an existing DIR is replaced only with
        --force. A progress line goes to standard error unless --quiet. --iseesnow also writes the
        ISeeSnow benchmark files (peak thickness/velocity ESRI ASCII on the DEM's grid, result CSV).
  verify [CASE...] [--full] [--resolutions R1,R2,...] [--limiter NAME] [--csv] [--threads N]
        Run the verification cases against exact solutions and invariants and print a table
        (or CSV). Cases: A1 A2 A3 A4 A5 A6 A7 STRESS (default: all). --full adds the finest
        resolutions. --resolutions overrides a case's cell sizes in metres (A2: cells across the cap).
        Limiters: minmod (default), vanleer, superbee.
  version
        Print the program version and the versions of the libraries it links.
  help
        Print this text.

exit codes:
  0  success (verify: every checked figure within its tolerance)
  1  verify: at least one figure outside its tolerance
  2  bad command line (unknown command, option or name)
  3  internal error
  4  run: invalid scenario or input data (the message names the field or file)
  5  run: output directory exists (use --force) or cannot be written
  6  run: cancelled (interrupt)
)";

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "help" || args[0] == "--help" || args[0] == "-h") {
    std::cout << kHelp;
    return args.empty() ? runout::cli::kUsage : runout::cli::kOk;
  }
  const std::string cmd = args[0];
  args.erase(args.begin());
  try {
    if (cmd == "run") return runout::cli::run(args);
    if (cmd == "verify") return runout::cli::verify(args);
    if (cmd == "version" || cmd == "--version") return runout::cli::version(args);
    std::cerr << "runout: unknown command '" << cmd << "' (valid: run, verify, version, help)\n";
    return runout::cli::kUsage;
  } catch (const std::exception& e) {
    std::cerr << "runout: internal error: " << e.what() << "\n";
    return runout::cli::kInternal;
  }
}
