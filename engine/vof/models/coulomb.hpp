#pragma once
// The Coulomb viscosity of the granular phase (listing B.1): nu = tan(phi) p / (rho1 |strain rate|),
// clipped to [nu_min, nu_max]; where the strain rate vanishes, nu_max.
#include <algorithm>
#include <cmath>
#include <string>

#include "engine/vof/models/granular_viscosity.hpp"

namespace runout::engine::vof {

class CoulombViscosity final : public GranularViscosity {
 public:
  explicit CoulombViscosity(const VofConfig& c)
      : tan_phi_(std::tan(c.phi_deg * 3.14159265358979323846 / 180)), rho1_(c.rho1), nu_min_(c.nu_min), nu_max_(c.nu_max) {}
  double nu(double p, double sr) const override {
    const double nu = tan_phi_ * p / (rho1_ * std::max(sr, 1e-300));
    return std::clamp(std::isfinite(nu) ? nu : nu_max_, nu_min_, nu_max_);
  }

 private:
  double tan_phi_, rho1_, nu_min_, nu_max_;
};

namespace models {

inline constexpr GranularViscosityModel coulomb{
    "coulomb",
    "Coulomb viscosity",
    "nu = tan(phi) p / (rho \\|strain rate\\|), clipped to [nu_min, nu_max] (the dissertation's listing B.1)",
    {{{"phi_deg", "phi", "φ", "deg", 0, 80, true, true, "internal friction angle",
       [](VofConfig& c) -> double& { return c.phi_deg; }, "internal_friction_deg"}}},
    [](const VofConfig& c) -> ModelProblem {
      if (c.phi_deg > 0 && c.phi_deg < 90) return {};
      return {"phi_deg", "must lie in (0, 90) deg (got " + std::to_string(c.phi_deg) + ")"};
    },
    [](const VofConfig& c) -> std::unique_ptr<GranularViscosity> { return std::make_unique<CoulombViscosity>(c); }};

}  // namespace models

}  // namespace runout::engine::vof
