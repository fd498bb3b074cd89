#pragma once
// The granular phase's viscosity model, selected by name (VofConfig::rheology). A model is one
// class in its own file behind this interface, plus its entry in models/registry.cpp.
#include <memory>
#include <string>
#include <vector>

#include "engine/vof/config.hpp"

namespace runout::engine::vof {

class GranularViscosity {
 public:
  virtual ~GranularViscosity() = default;
  /// The kinematic viscosity nu [m2/s] for the confining pressure p [Pa] and the strain rate
  /// |strain rate| = sqrt(2 D:D) [1/s].
  virtual double nu(double p, double strain_rate) const = 0;
};

/// The model VofConfig::rheology names; an unknown name is a VofError listing the valid ones.
std::unique_ptr<GranularViscosity> make_granular_viscosity(const VofConfig& cfg);

}  // namespace runout::engine::vof
