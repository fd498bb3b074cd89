#pragma once
// The VOF engine's error: a configuration, mesh or checkpoint it cannot take, or a solve that
// fails (the message names what is wrong).
#include <stdexcept>

namespace runout::engine::vof {

struct VofError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace runout::engine::vof
