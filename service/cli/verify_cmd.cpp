// `runout verify`: run the verification cases and print a table or CSV.
#include <CLI/CLI.hpp>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "engine/verification/cases.hpp"
#include "service/cli/commands.hpp"

namespace runout::cli {
namespace {

namespace ver = runout::engine::verification;

std::string fmt(double v) {
  if (std::isnan(v)) return "";
  char b[32];
  if (v != 0 && (std::abs(v) < 1e-3 || std::abs(v) >= 1e6)) std::snprintf(b, sizeof b, "%.3e", v);
  else std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

bool parse_list(const std::string& s, std::vector<double>& out) {
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t pos = 0;
      const double v = std::stod(item, &pos);
      if (pos != item.size() || !(v > 0)) return false;
      out.push_back(v);
    } catch (...) {
      return false;
    }
  }
  return !out.empty();
}

}  // namespace

int verify(const std::vector<std::string>& args) {
  ver::Options opt;
  bool csv = false;
  std::vector<std::string> names, cases;
  std::string resolutions, limiter, threads;
  const auto valid = ver::case_ids();
  std::string list;
  for (const auto& v : valid) list += (list.empty() ? "" : ", ") + v;
  CLI::App app{"Run the verification cases against exact solutions and invariants and print a table (or CSV).\n"
               "Exit 1 when a figure lies outside its tolerance.",
               "runout verify"};
  prepare(app);
  app.add_option("CASE", names, "Cases to run (default: all): " + list)->type_name("CASE...");
  app.add_flag("--full", opt.full, "Add the finest resolutions");
  app.add_option("--resolutions", resolutions,
                 "Override a case's cell sizes in metres, positive numbers separated by commas (A2: cells across the "
                 "cap)")
      ->type_name("R1,R2,...");
  app.add_option("--limiter", limiter, "Slope limiter: minmod (default), vanleer, superbee")->type_name("NAME");
  app.add_flag("--csv", csv, "Print CSV instead of the table (no progress lines)");
  app.add_option("--threads", threads, "OpenMP threads (a positive integer; default: all cores)")->type_name("N");
  if (const int rc = parse_args(app, args); rc >= 0) return rc;
  if (app.count("--resolutions") && !parse_list(resolutions, opt.resolutions))
    return usage_error("runout verify", "--resolutions takes positive numbers separated by commas, got '" + resolutions + "'");
  if (app.count("--limiter")) {
    try {
      opt.limiter = engine::parse_name(engine::kLimiterNames, "limiter", limiter);
    } catch (const std::exception& e) {
      return usage_error("runout verify", e.what());
    }
  }
  if (app.count("--threads")) {
    const auto n = positive_int(threads);
    if (!n) return usage_error("runout verify", "--threads takes a positive integer, got '" + threads + "'");
    omp_set_num_threads(*n);
  }
  for (const auto& a : names) {
    std::string id = a;
    for (auto& c : id) c = char(std::toupper(static_cast<unsigned char>(c)));
    bool known = false;
    for (const auto& v : valid) known = known || v == id;
    if (!known) return usage_error("runout verify", "unknown case '" + a + "' (valid: " + list + ")");
    cases.push_back(id);
  }
  if (cases.empty()) cases = valid;

  std::vector<ver::Row> rows;
  double total = 0;
  for (const auto& id : cases) {
    if (!csv) std::cerr << "running " << id << ": " << ver::describe(id) << " ..." << std::endl;
    auto r = ver::run_case(id, opt);
    for (auto& row : r) {
      total += row.wall_s;
      rows.push_back(std::move(row));
    }
  }
  bool all_pass = true;
  for (const auto& r : rows) all_pass = all_pass && r.pass();

  if (csv) {
    std::vector<std::string> names;
    std::set<std::string> seen;
    for (const auto& r : rows)
      for (const auto& m : r.metrics)
        if (seen.insert(m.name).second) names.push_back(m.name);
    std::cout << "case,variant,cells,dx";
    for (const auto& n : names) std::cout << "," << n;
    std::cout << ",order,wall_s,status\n";
    for (const auto& r : rows) {
      std::cout << r.case_id << "," << r.variant << "," << r.cells << "," << fmt(r.dx);
      for (const auto& n : names) {
        const auto* m = r.metric(n);
        std::cout << "," << (m ? fmt(m->value) : "");
      }
      std::cout << "," << fmt(r.order) << "," << fmt(r.wall_s) << "," << (r.pass() ? "pass" : "fail") << "\n";
    }
  } else {
    std::printf("%-7s %-26s %9s %7s %7s %8s %-6s  %s\n", "case", "variant", "cells", "dx[m]", "order", "wall_s",
                "status", "figures (value [limit])");
    for (const auto& r : rows) {
      std::string figs;
      for (const auto& m : r.metrics) {
        figs += m.name + "=" + fmt(m.value);
        if (!std::isnan(m.limit)) figs += std::string(" [") + (m.upper ? "<=" : ">=") + fmt(m.limit) + "]";
        if (!m.ok()) figs += " FAIL";
        figs += "  ";
      }
      std::printf("%-7s %-26s %9ld %7s %7s %8.2f %-6s  %s\n", r.case_id.c_str(), r.variant.c_str(), r.cells,
                  fmt(r.dx).c_str(), fmt(r.order).c_str(), r.wall_s, r.pass() ? "pass" : "FAIL", figs.c_str());
    }
    std::printf("\n%zu rows, %s, %.1f s of solver time\n", rows.size(), all_pass ? "all pass" : "FAILURES", total);
  }
  return all_pass ? kOk : kFailed;
}

}  // namespace runout::cli
