#pragma once
// Coulomb friction (Savage & Hutter 1989): tau_b = tan(delta) * N.
#include <cmath>

#include "engine/friction/law.hpp"

namespace runout::engine::friction {

inline constexpr FrictionLaw coulomb{
    "coulomb",
    "Coulomb",
    "tau_b = tan(delta) N (Savage & Hutter 1989)",
    {{{"bed_friction_deg", "delta", "δ", "°", "bed friction angle"}, {}}},
    [](const FrictionParams& p) { return BasalFriction{std::tan(p.delta), 0.0}; },
    [](const FrictionParams& p) -> const char* {
      return p.delta >= 0.0 && p.delta < M_PI / 2 ? "" : "bed friction angle delta must lie in [0, 90) degrees";
    }};

}  // namespace runout::engine::friction
