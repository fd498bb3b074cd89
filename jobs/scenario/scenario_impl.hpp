#pragma once
// Inside jobs/scenario: what the resolvers of both engines share.
#include <google/protobuf/message.h>

#include <algorithm>
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
/// An interval of frames or checkpoints: at least the end time / kMaxFramesPerRun, or (where
/// `zero_is_none`) 0 for none.
inline void check_output_interval(const std::string& field, double interval, const std::string& end_field, double end_time,
                                  bool zero_is_none) {
  const double least = end_time / kMaxFramesPerRun;
  if ((interval > 0 || !zero_is_none) && interval < least)
    bad(field, "at least " + end_field + " / " + json_number(kMaxFramesPerRun) + " (" + json_number(least) + " s: a run writes at most " +
                   json_number(kMaxFramesPerRun) + ")" + (zero_is_none ? ", or 0 for none" : "") + "; got " + json_number(interval) + " s");
}
/// A frame interval left unset takes its default, or end time / kMaxFramesPerRun where that is
/// longer (`given`: the value before the defaults were filled in).
inline double default_frame_interval(double given, double filled, double end_time) {
  return given == 0 ? std::max(filled, end_time / kMaxFramesPerRun) : filled;
}

/// Engine "vof": the lab block completed and checked (lab.cpp).
ResolvedScenario resolve_lab(v1::Scenario s);

}  // namespace runout::jobs
