#pragma once
// Bounds on a scenario's text: every string field has a length limit and no control characters, so
// that a mistaken or hostile file cannot make a run slow, huge or ambiguous (a NUL byte cuts a path
// short in the C libraries that open it). docs/user/scenarios.md, Valid ranges, states the limits.
#include <cstddef>
#include <string>

#include <google/protobuf/message.h>

namespace runout::jobs {

/// The longest path a scenario may name (bytes): Linux's PATH_MAX.
inline constexpr std::size_t kMaxPathBytes = 4096;
/// The longest CRS (fields "crs" and "*_crs": a code, a PROJ string or WKT).
inline constexpr std::size_t kMaxCrsBytes = 10000;
/// The longest other text field (a name, a keyword, a source).
inline constexpr std::size_t kMaxTextBytes = 1000;
/// The longest request id of a submission.
inline constexpr std::size_t kMaxRequestIdBytes = 200;

/// Throws ScenarioError naming the first string field (as "releases[1].path") that is longer than
/// its limit (paths: fields whose name ends in "path" or is "thickness_raster"; CRSs; other text) or
/// holds a control
/// character (U+0000 to U+001F, U+007F).
void check_text_limits(const google::protobuf::Message& m);

/// The problem with one text value ("" when it is fine), for fields outside a scenario (a request id).
std::string text_problem(const std::string& value, std::size_t max_bytes);

}  // namespace runout::jobs
