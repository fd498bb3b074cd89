#pragma once
// Lenient JSON that protobuf's parser accepts but a scenario must not hold: a key given twice (the
// later would win) and a single value where a list is needed (taken as a one-element list).
#include <string>

namespace runout::jobs {

/// Throws ScenarioError naming the field of a duplicate key or of a single value given for a list.
/// Call it on text that protobuf's parser has accepted (it gives up quietly on anything else).
void check_json_shape(const std::string& json);

}  // namespace runout::jobs
