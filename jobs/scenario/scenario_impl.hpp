#pragma once
// Inside jobs/scenario: what the resolvers of both engines share.
#include <google/protobuf/message.h>

#include <sstream>
#include <string>

#include "jobs/scenario/scenario.hpp"

namespace runout::jobs {

// A number as messages and the reference print it (6 significant digits, as %g).
inline std::string num(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

inline double radians(double deg) { return deg * 3.14159265358979323846 / 180.0; }

[[noreturn]] inline void bad(const std::string& field, const std::string& problem) { throw ScenarioError(field + ": " + problem); }

/// Safety net after the field checks: no number anywhere in `m` may be NaN or infinite.
void require_finite(const google::protobuf::Message& m, const std::string& prefix);

/// At most this many frames (or checkpoints) over a run's simulated time.
inline constexpr double kMaxFramesPerRun = 1000;
/// An interval of frames or checkpoints: 0 (none) or at least the end time / kMaxFramesPerRun.
inline void check_output_interval(const std::string& field, double interval, const std::string& end_field, double end_time) {
  const double least = end_time / kMaxFramesPerRun;
  if (interval > 0 && interval < least)
    bad(field, "at least " + end_field + " / " + json_number(kMaxFramesPerRun) + " (" + json_number(least) +
                   " s: a run writes at most " + json_number(kMaxFramesPerRun) + "), or 0 for none; got " + json_number(interval) + " s");
}

/// Engine "vof": the lab block completed and checked (lab.cpp).
ResolvedScenario resolve_lab(v1::Scenario s);

}  // namespace runout::jobs
