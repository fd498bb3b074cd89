#pragma once
// The two-phase mixture (granular phase 1, air 2) in a cell or on a face with phase fraction
// alpha, clipped to [0, 1]: its density, its dynamic viscosity from the granular phase's kinematic
// viscosity nu1 and the air's, and the mass flux from the granular and the total volume flux.
#include <algorithm>

#include "engine/vof/config.hpp"

namespace runout::engine::vof {

struct Mixture {
  double rho1, rho2, nu2;
  explicit Mixture(const VofConfig& c) : rho1(c.rho1), rho2(c.rho2), nu2(c.nu2) {}

  /// rho = alpha rho1 + (1 - alpha) rho2
  double rho(double alpha) const {
    const double al = std::clamp(alpha, 0.0, 1.0);
    return al * rho1 + (1 - al) * rho2;
  }
  /// mu = alpha rho1 nu1 + (1 - alpha) rho2 nu2
  double mu(double alpha, double nu1) const {
    const double al = std::clamp(alpha, 0.0, 1.0);
    return al * rho1 * nu1 + (1 - al) * rho2 * nu2;
  }
  /// The mass flux rho_phi = alpha_phi (rho1 - rho2) + phi rho2 of the granular flux alpha_phi and
  /// the volume flux phi.
  double rho_flux(double alpha_phi, double phi) const { return alpha_phi * (rho1 - rho2) + phi * rho2; }
};

}  // namespace runout::engine::vof
