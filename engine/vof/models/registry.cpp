// The granular viscosity models by name. A new model: its file in models/ defining its factory,
// and one entry here (the factory's declaration and its row).
#include <array>
#include <string_view>

#include "engine/vof/error.hpp"
#include "engine/vof/models/granular_viscosity.hpp"

namespace runout::engine::vof {

std::unique_ptr<GranularViscosity> make_coulomb_viscosity(const VofConfig&);
std::unique_ptr<GranularViscosity> make_mu_i_viscosity(const VofConfig&);
std::unique_ptr<GranularViscosity> make_mu_i_unregularised_viscosity(const VofConfig&);

namespace {

struct Entry {
  std::string_view name;
  std::unique_ptr<GranularViscosity> (*make)(const VofConfig&);
};

constexpr std::array kModels = {
    Entry{"coulomb", make_coulomb_viscosity},
    Entry{"mu_i", make_mu_i_viscosity},
    Entry{"mu_i_unregularised", make_mu_i_unregularised_viscosity},
};

}  // namespace

std::vector<std::string> granular_viscosity_names() {
  std::vector<std::string> names;
  for (const auto& e : kModels) names.emplace_back(e.name);
  return names;
}

std::unique_ptr<GranularViscosity> make_granular_viscosity(const VofConfig& cfg) {
  for (const auto& e : kModels)
    if (e.name == cfg.rheology) return e.make(cfg);
  std::string valid;
  for (const auto& e : kModels) valid += (valid.empty() ? "" : ", ") + std::string(e.name);
  throw VofError("rheology: unknown '" + cfg.rheology + "' (valid: " + valid + ")");
}

}  // namespace runout::engine::vof
