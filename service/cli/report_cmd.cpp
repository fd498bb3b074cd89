// runout report: a finished run on terrain as one PDF for a hazard report (jobs/drivers/report.hpp).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "jobs/drivers/report.hpp"
#include "service/cli/commands.hpp"

namespace runout::cli {

int report(const std::vector<std::string>& args) {
  std::string run, out;
  jobs::ReportOptions opt;
  CLI::App app{"A finished run on terrain (a folder `runout run` or `runout fetch` wrote) as one PDF for a hazard report:\n"
               "the parameters in words with units, the mass balance, the results, the points of interest and the\n"
               "pressure zones as tables, each hazard map at a stated 1:N scale with a scale bar, labelled contours\n"
               "and its cells as a raster of --dpi, and the path profile; A4 or A3 landscape.",
               "runout report"};
  prepare(app);
  app.add_option("RUN", run, "The run's result folder (run.json, the hazard rasters, elevation.tif, release.tif)")->required()->type_name("DIR");
  app.add_option("--out", out, "The PDF to write (its folder must exist; an existing file is replaced)")->required()->type_name("FILE");
  app.add_option("--paper", opt.paper, "a4 or a3 (landscape)")->check(CLI::IsMember({"a4", "a3"}))->capture_default_str();
  app.add_option("--dpi", opt.dpi, "Resolution of the maps' rasters")->check(CLI::Range(72.0, 1200.0))->capture_default_str();
  if (const int rc = parse_args(app, args); rc >= 0) return rc;
  // Written beside, then moved into place: a failed report leaves no partial PDF and no file of the
  // user's replaced.
  const std::string part = out + ".part";
  try {
    const auto lay = jobs::write_run_report(run, part, opt);
    std::filesystem::rename(part, out);
    std::printf("report: %s, %d pages of %s (%.0f x %.0f pt)", out.c_str(), lay.pages, opt.paper.c_str(), lay.page_w, lay.page_h);
    if (!lay.maps.empty()) std::printf(", maps at 1:%d", lay.maps.front().scale);
    std::printf("\n");
    return kOk;
  } catch (const std::exception& e) {
    std::cerr << "runout report: " << e.what() << "\n";
    std::error_code ec;
    std::filesystem::remove(part, ec);
    return kBadInput;
  }
}

}  // namespace runout::cli
