#pragma once
// A basal friction law of the depth-averaged engines: its name, its parameters and its resistance.
//
// Every law gives the basal shear stress as
//   tau_b = mu * N + rho * g * |u|^2 * inv_xi
// with N the basal normal stress (on curved terrain with its centrifugal part, Savage & Hutter
// 1991), from two coefficients that the law computes once from its parameters before a run
// (BasalFriction). The engines apply the first term as a bounded impulse (apply_friction) and the
// second implicitly (turbulent_factor), so a law is resolved outside the time loop and the kernels
// stay branch-free. A law whose coefficients depend on the flow (mu(h, |u|), e.g.
// Pouliquen-Forterre) needs a new term in the kernels as well as its entry.
//
// A new law: one header beside coulomb.hpp (a FrictionLaw with its equation, parameters,
// coefficients and checks) and one line in registry.hpp.
#include <array>
#include <string_view>

namespace runout::engine {

/// The parameters the laws read (SI, angles in radians); a law reads those it lists.
struct FrictionParams {
  double delta = 0.0;   ///< bed friction angle [rad] (Coulomb)
  double mu = 0.0;      ///< Voellmy dry-friction coefficient [-]
  double xi = 1.0e300;  ///< Voellmy turbulent-friction coefficient [m/s^2]
};

/// The coefficients of tau_b = mu N + rho g |u|^2 inv_xi.
struct BasalFriction {
  double mu = 0.0;      ///< Coulomb coefficient [-]
  double inv_xi = 0.0;  ///< 1/xi [s^2/m]; 0: no turbulent drag

  /// tau_b [Pa] for basal normal stress `normal` [Pa], density [kg/m^3], gravity [m/s^2], speed [m/s].
  double resistance(double normal, double rho, double g, double speed) const {
    return mu * normal + rho * g * speed * speed * inv_xi;
  }
};

/// A parameter of a law: the scenario's field (in `material`), its symbol and what it is.
struct FrictionParameter {
  std::string_view field;   ///< e.g. "bed_friction_deg"
  std::string_view symbol;  ///< e.g. "delta"
  std::string_view doc;
};

struct FrictionLaw {
  std::string_view name;      ///< the scenario's material.rheology
  std::string_view equation;  ///< tau_b in words and symbols, with the source
  std::array<FrictionParameter, 2> parameters;  ///< those it needs (an empty field ends the list)
  BasalFriction (*coefficients)(const FrictionParams&);
  /// The parameters' physical limits: "" when valid, else what is wrong (naming the parameter).
  const char* (*check)(const FrictionParams&);
};

}  // namespace runout::engine
