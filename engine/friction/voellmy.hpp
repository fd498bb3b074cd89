#pragma once
// Voellmy friction (Voellmy 1955; Salm 1993): tau_b = mu * N + rho * g * |u|^2 / xi.
#include <cmath>

#include "engine/friction/law.hpp"

namespace runout::engine::friction {

inline constexpr FrictionLaw voellmy{
    "voellmy",
    "Voellmy",
    "tau_b = mu N + rho g \\|u\\|^2 / xi (Voellmy 1955; Salm 1993)",
    {{{"voellmy_mu", "mu", "μ", "", "dry-friction coefficient"}, {"voellmy_xi", "xi", "ξ", "m/s²", "turbulent-friction coefficient"}}},
    [](const FrictionParams& p) { return BasalFriction{p.mu, 1.0 / p.xi}; },
    [](const FrictionParams& p) -> const char* {
      if (!(p.mu >= 0.0 && std::isfinite(p.mu))) return "Voellmy mu must be >= 0";
      if (!(p.xi > 0.0)) return "Voellmy xi must be > 0 m/s^2";
      return "";
    }};

}  // namespace runout::engine::friction
