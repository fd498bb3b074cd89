// `runout verify`: run the verification cases and print a table or CSV.
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
  std::vector<std::string> cases;
  const auto valid = ver::case_ids();
  for (std::size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    auto value = [&](const char* flag) -> const std::string* {
      if (k + 1 >= args.size()) {
        std::cerr << "runout verify: " << flag << " needs a value\n";
        return nullptr;
      }
      return &args[++k];
    };
    if (a == "--full") {
      opt.full = true;
    } else if (a == "--csv") {
      csv = true;
    } else if (a == "--resolutions") {
      const std::string* v = value("--resolutions");
      if (!v) return kUsage;
      if (!parse_list(*v, opt.resolutions)) {
        std::cerr << "runout verify: --resolutions takes positive numbers separated by commas, got '" << *v << "'\n";
        return kUsage;
      }
    } else if (a == "--limiter") {
      const std::string* v = value("--limiter");
      if (!v) return kUsage;
      try {
        opt.limiter = engine::parse_name(engine::kLimiterNames, "limiter", *v);
      } catch (const std::exception& e) {
        std::cerr << "runout verify: " << e.what() << "\n";
        return kUsage;
      }
    } else if (a == "--threads") {
      const std::string* v = value("--threads");
      if (!v) return kUsage;
      int n = 0;
      try {
        n = std::stoi(*v);
      } catch (...) {
      }
      if (n < 1) {
        std::cerr << "runout verify: --threads takes a positive integer, got '" << *v << "'\n";
        return kUsage;
      }
      omp_set_num_threads(n);
    } else if (!a.empty() && a[0] == '-') {
      std::cerr << "runout verify: unknown option '" << a << "' (see runout help)\n";
      return kUsage;
    } else {
      std::string id = a;
      for (auto& c : id) c = char(std::toupper(static_cast<unsigned char>(c)));
      bool known = false;
      for (const auto& v : valid) known = known || v == id;
      if (!known) {
        std::string list;
        for (const auto& v : valid) list += (list.empty() ? "" : ", ") + v;
        std::cerr << "runout verify: unknown case '" << a << "' (valid: " << list << ")\n";
        return kUsage;
      }
      cases.push_back(id);
    }
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
