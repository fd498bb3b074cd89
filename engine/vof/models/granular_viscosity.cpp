// make_granular_viscosity (granular_viscosity.hpp): the model VofConfig::rheology names, from the rows of
// registry.hpp.
#include "engine/vof/models/registry.hpp"

namespace runout::engine::vof {

std::unique_ptr<GranularViscosity> make_granular_viscosity(const VofConfig& cfg) {
  const GranularViscosityModel* model = find_granular_viscosity(cfg.rheology);
  if (!model) {
    std::string valid;
    for (const auto& name : granular_viscosity_names()) valid += (valid.empty() ? "" : ", ") + name;
    throw VofError("rheology: unknown '" + cfg.rheology + "' (valid: " + valid + ")");
  }
  if (const ModelProblem p = model->check(cfg))
    throw VofError("rheology " + cfg.rheology + ": " + std::string(p.field) + " " + p.what);
  return model->make(cfg);
}

}  // namespace runout::engine::vof
