// runout compare: two finished runs on the same grid side by side (validation.md C1 and C2: the 3D
// engine against the depth-averaged one): the regression's figures of each, their differences, and
// the difference map of the maximum depth.
#include <CLI/CLI.hpp>

#include <algorithm>
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

// The rows of the scenarios' points of interest (run.json's results.points_of_interest), matched
// by name: each point's maximum depth, speed and pressure in both runs. A point in one run only gets
// its row with "-" for the other.
std::vector<jobs::RegressionRow> point_rows(const fs::path& run, const fs::path& other) {
  const auto a = jobs::read_run_record((run / "run.json").string()), b = jobs::read_run_record((other / "run.json").string());
  std::vector<jobs::RegressionRow> rows;
  auto find = [](const v1::RunRecord& r, const std::string& name) -> const v1::PointReport* {
    for (const auto& p : r.results().points_of_interest())
      if (p.name() == name) return &p;
    return nullptr;
  };
  std::vector<std::string> names;
  for (const auto* r : {&a, &b})
    for (const auto& p : r->results().points_of_interest())
      if (std::find(names.begin(), names.end(), p.name()) == names.end()) names.push_back(p.name());
  for (const auto& name : names) {
    const auto *pa = find(a, name), *pb = find(b, name);
    auto row = [&](const char* what, const char* unit, double (v1::PointReport::*get)() const) {
      const double va = pa ? (pa->*get)() : NAN, vb = pb ? (pb->*get)() : NAN;
      rows.push_back({name + ": " + what, unit, vb, va, va - vb, 0, true});  // reference: OTHER, value: RUN
    };
    row("maximum depth", "m", &v1::PointReport::max_depth_m);
    row("maximum speed", "m/s", &v1::PointReport::max_speed_m_s);
    row("maximum pressure", "kPa", &v1::PointReport::max_pressure_kpa);
  }
  return rows;
}

}  // namespace

int compare(const std::vector<std::string>& args) {
  std::string run, other, out;
  CLI::App app{"Compare two finished runs on the same grid (e.g. the 3D and the depth-averaged engine's): runout, affected\n"
               "area, maximum depth and speed, the scenarios' points of interest (by name: their maximum depth, speed and\n"
               "pressure), and the difference map of the maximum depth (RUN minus OTHER). Writes compare.md, diff.tif\n"
               "and diff.png into --out.",
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
    auto o = jobs::compare_run(a, ref, (fs::path(run) / "max_depth.tif").string(), other, out);
    // The scenarios' own points instead of the regression's In den Arelen farmhouse.
    o.rows.erase(std::remove_if(o.rows.begin(), o.rows.end(), [](const jobs::RegressionRow& r) { return r.name.rfind("farmhouse", 0) == 0; }),
                 o.rows.end());
    for (auto& r : point_rows(run, other)) o.rows.push_back(std::move(r));
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
