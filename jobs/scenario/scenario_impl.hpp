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

/// Engine "vof": the lab block completed and checked (lab.cpp).
ResolvedScenario resolve_lab(v1::Scenario s);

}  // namespace runout::jobs
