#pragma once
// Verification cases A1-A7 (docs/validation/verification.md): each sets up the depth-averaged solvers against an
// exact solution or an invariant, runs them at one or more resolutions and returns rows of figures
// with a pass/fail against explicit tolerances. Pure numerics: no files, no printing; the CLI
// (`runout verify`) and the tests format and assert the rows.
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "engine/limiters.hpp"

namespace runout::engine::verification {

struct Metric {
  std::string name;
  double value;
  double limit = std::numeric_limits<double>::quiet_NaN();  ///< NaN: reported, not checked
  bool upper = true;  ///< value must be <= limit (true) or >= limit (false)
  bool ok() const { return std::isnan(limit) || (upper ? value <= limit : value >= limit); }
};

struct Row {
  std::string case_id;   ///< "A1", ...
  std::string variant;   ///< e.g. "1d-minmod", "2d-minmod"
  long cells = 0;
  double dx = 0;         ///< cell size along the slope [m]
  std::vector<Metric> metrics;
  double order = std::numeric_limits<double>::quiet_NaN();  ///< observed order vs the next coarser row
  double wall_s = 0;
  double cell_updates = 0;  ///< cells computed, summed over steps (throughput = cell_updates / wall_s)
  bool pass() const {
    for (const auto& m : metrics)
      if (!m.ok()) return false;
    return true;
  }
  const Metric* metric(const std::string& n) const {
    for (const auto& m : metrics)
      if (m.name == n) return &m;
    return nullptr;
  }
};

struct Options {
  Limiter limiter = Limiter::minmod;
  bool full = false;                ///< add the finest resolutions
  std::vector<double> resolutions;  ///< override the case's cell sizes [m] (or cells across, A2)
};

/// The case identifiers in order: A1 ... A7, STRESS, V1 ... V7 (the VOF engine, vof_cases.hpp).
std::vector<std::string> case_ids();
/// One-line description of a case.
std::string describe(const std::string& id);
/// Run one case. Throws std::invalid_argument for an unknown id (listing the valid ones).
std::vector<Row> run_case(const std::string& id, const Options& opt);

}  // namespace runout::engine::verification
