#pragma once
// The granular phase's viscosity model, selected by name (VofConfig::rheology), and the row that
// describes a model: its name, caption and equation, its parameter rows (the scenario's field, unit,
// valid range, default, what it is, and where VofConfig keeps it), its checks between parameters and
// its factory. models/registry.hpp holds the rows; the scenario's option tables and checks, the
// reference page and the maps read them there. Everything here is header-only and free of the
// solver's libraries, so that the scenario library reads the rows without linking the solver.
//
// A new model: one header in models/ with its class and its GranularViscosityModel row, and one line
// in registry.hpp's table (tests/unit/test_example_models.cpp adds an example model that is not in the
// table with add_granular_viscosity and runs it through the scenario's checks and the solver).
#include <array>
#include <memory>
#include <string>
#include <string_view>

#include "engine/vof/config.hpp"

namespace runout::engine::vof {

class GranularViscosity {
 public:
  virtual ~GranularViscosity() = default;
  /// The kinematic viscosity nu [m2/s] for the confining pressure p [Pa] and the strain rate
  /// |strain rate| = sqrt(2 D:D) [1/s].
  virtual double nu(double p, double strain_rate) const = 0;
};

/// A model's parameter: the scenario's field, how it is written and checked, where the engine keeps it.
struct ModelParameter {
  std::string_view field;   ///< the laboratory block's field, lab.<field>; e.g. "mu_s"
  std::string_view symbol;  ///< e.g. "mu_s"
  std::string_view label;   ///< the symbol on maps, e.g. "μs"
  std::string_view unit;    ///< as the option tables write it: "", "deg", "m", "kg/m3"
  double lo, hi;            ///< the valid range
  bool lo_open, hi_open;    ///< the range's ends excluded
  std::string_view doc;     ///< what it is, one line
  double& (*value)(VofConfig&);  ///< where VofConfig keeps it; VofConfig{}'s value is its default
  std::string_view material_field = {};  ///< the material block's field where it is not `field`

  std::string_view material_name() const { return material_field.empty() ? field : material_field; }
  double default_value() const {
    VofConfig c;
    return value(c);
  }
  bool in_range(double v) const { return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi); }
};

/// What a model's check found wrong: the parameter (its `field`) and the problem; empty: nothing.
struct ModelProblem {
  std::string_view field;
  std::string what;
  explicit operator bool() const { return !what.empty(); }
};

struct GranularViscosityModel {
  std::string_view name;      ///< VofConfig::rheology, the scenario's lab.rheology and material.rheology
  std::string_view caption;   ///< the model's name on maps, e.g. "Coulomb viscosity"
  std::string_view equation;  ///< nu in words and symbols, with the source (the reference page)
  std::array<ModelParameter, 6> parameters;  ///< those it reads (an empty field ends the list)
  /// The checks between its parameters and against the rest of the configuration (each parameter's
  /// range is its row's): an empty ModelProblem when the model can be made.
  ModelProblem (*check)(const VofConfig&);
  std::unique_ptr<GranularViscosity> (*make)(const VofConfig&);
};

/// The model VofConfig::rheology names (registry.hpp's rows and those added), after its check; an
/// unknown name or a failed check is a VofError naming the model and the parameter.
std::unique_ptr<GranularViscosity> make_granular_viscosity(const VofConfig& cfg);

}  // namespace runout::engine::vof
