#pragma once
// The granular viscosity models, found by name: one line per model. The scenario's choices, option
// tables and checks, the reference page and the maps read these rows (header-only: the scenario
// library does not link the solver).
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "engine/vof/error.hpp"
#include "engine/vof/models/coulomb.hpp"
#include "engine/vof/models/mu_i.hpp"

namespace runout::engine::vof {

inline constexpr std::array<const GranularViscosityModel*, 3> kGranularViscosityModels{
    &models::coulomb,
    &models::mu_i,
    &models::mu_i_unregularised,
};

namespace detail {
inline std::vector<const GranularViscosityModel*>& granular_viscosity_rows() {
  static std::vector<const GranularViscosityModel*> rows(kGranularViscosityModels.begin(), kGranularViscosityModels.end());
  return rows;
}
}  // namespace detail

/// Every model: the table's rows, then those added.
inline const std::vector<const GranularViscosityModel*>& granular_viscosity_models() { return detail::granular_viscosity_rows(); }

/// Adds a model outside the table (a test's example, a program's own model) to every reader of the
/// rows; call it before the rows are read (at start-up: the scenario's option tables read them once).
/// Returns true; a name already taken is a VofError.
inline bool add_granular_viscosity(const GranularViscosityModel& model) {
  for (const auto* m : granular_viscosity_models())
    if (m->name == model.name) throw VofError("rheology: a model '" + std::string(model.name) + "' is already registered");
  detail::granular_viscosity_rows().push_back(&model);
  return true;
}

/// The models' names, in the rows' order.
inline std::vector<std::string> granular_viscosity_names() {
  std::vector<std::string> names;
  for (const auto* m : granular_viscosity_models()) names.emplace_back(m->name);
  return names;
}

/// The model called `name`, or null.
inline const GranularViscosityModel* find_granular_viscosity(std::string_view name) {
  for (const auto* m : granular_viscosity_models())
    if (m->name == name) return m;
  return nullptr;
}

}  // namespace runout::engine::vof
