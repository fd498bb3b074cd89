// runout compare: two finished runs on the same grid side by side (validation.md C1 and C2: the 3D
// engine against the depth-averaged one): the regression's figures of each, their differences, and
// the difference map of the maximum depth.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "jobs/formats/run_record.hpp"
#include "jobs/regression/regression.hpp"
#include "service/cli/commands.hpp"

namespace fs = std::filesystem;

namespace runout::cli {

namespace {

// "vof at 30 m" from a run's record.
std::string describe(const fs::path& dir) {
  const auto rec = jobs::read_run_record((dir / "run.json").string());
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s, %.0f m", rec.engine().c_str(), rec.grid().cell_size_m());
  return buf;
}

std::string number(double v) {
  if (std::isnan(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

int compare(const std::vector<std::string>& args) {
  std::string run, other, out;
  CLI::App app{"Compare two finished runs on the same grid (e.g. the 3D and the depth-averaged engine's): runout, affected\n"
               "area, maximum depth and speed, the In den Arelen farmhouse where it lies on the grid, and the difference\n"
               "map of the maximum depth (RUN minus OTHER). Writes compare.md, diff.tif and diff.png into --out.",
               "runout compare"};
  prepare(app);
  app.add_option("RUN", run, "A result folder (run.json, max_depth.tif)")->required()->type_name("DIR");
  app.add_option("OTHER", other, "The result folder it is compared with")->required()->type_name("DIR");
  app.add_option("--out", out, "Folder for compare.md, diff.tif, diff.png (created)")->required()->type_name("DIR");
  if (const int rc = parse_args(app, args); rc >= 0) return rc;
  try {
    const auto a = jobs::measure_run(run, true);
    jobs::RegressionReference ref;
    ref.figures = jobs::measure_run(other, true);
    fs::create_directories(out);
    const auto o = jobs::compare_run(a, ref, (fs::path(run) / "max_depth.tif").string(), other, out);
    const std::string da = describe(run), db = describe(other);
    std::ofstream md(fs::path(out) / "compare.md");
    md << "# " << run << " (" << da << ") against " << other << " (" << db << ")\n\n";
    md << "| figure | unit | " << db << " | " << da << " | difference |\n|---|---|---:|---:|---:|\n";
    std::printf("%-46s %14s %14s %14s\n", "", db.c_str(), da.c_str(), "difference");
    for (const auto& r : o.rows) {
      if (r.name.rfind("max-depth map", 0) == 0) {  // the regression's wording: the run against its reference
        md << "| max-depth map: largest abs(difference) where either exceeds 0.1 m | m |  |  | " << number(r.value) << " |\n";
        std::printf("  %-46s %14s %14s %14s\n", "max-depth map: largest abs(difference)", "", "", number(r.value).c_str());
        continue;
      }
      md << "| " << r.name << " | " << r.unit << " | " << number(r.reference) << " | " << number(r.value) << " | " << number(r.difference)
         << " |\n";
      std::printf("  %-46s %14s %14s %14s\n", r.name.c_str(), number(r.reference).c_str(), number(r.value).c_str(),
                  number(r.difference).c_str());
    }
    if (!o.note.empty()) md << "\n" << o.note << "\n";
    md << "\n![difference of the maximum depth](diff.png)\n";
    if (!md) throw std::runtime_error("cannot write " + (fs::path(out) / "compare.md").string());
    std::printf("comparison in %s\n", (fs::path(out) / "compare.md").string().c_str());
    return kOk;
  } catch (const std::exception& e) {
    std::cerr << "runout compare: " << e.what() << "\n";
    return kBadInput;
  }
}

}  // namespace runout::cli
