#pragma once
// mu(I) friction of the depth-averaged engines: the basal friction of the mu(I) rheology (Jop,
// Forterre & Pouliquen 2006), mu(I) = mu_s + (mu_2 - mu_s) / (I_0 / I + 1), with the basal inertial
// number of the Bagnold profile of a steady uniform layer, I = 5 d |u| / (2 h sqrt(phi g_n h)),
// phi = rho / rho_s the solid fraction. That is Pouliquen-Forterre's flowing branch with
// tan d1 = mu_s, tan d2 = mu_2, gamma = 0 and beta / L = 2 I_0 sqrt(phi) / (5 d), without a static
// branch (mu = mu_s at rest). docs/design/depth-averaged.md has the derivation.
#include <cmath>

#include "engine/friction/law.hpp"

namespace runout::engine::friction {

inline constexpr FrictionLaw mu_i{
    "mu_i",
    "μ(I)",
    "tau_b = mu(I) N, mu = mu_s + (mu_2 - mu_s) / (I_0 / I + 1), I = 5 d \\|u\\| / (2 h sqrt(phi g_n h)), "
    "phi = rho / rho_s (`material.density_kg_m3` / `grain_density_kg_m3`) (Jop, Forterre & Pouliquen 2006; "
    "depth-averaged with the Bagnold profile)",
    {{{"mu_s", "mu_s", "μs", "", "friction coefficient as I -> 0"},
      {"mu_2", "mu_2", "μ₂", "", "friction coefficient as I -> infinity"},
      {"mu_i0", "I_0", "I₀", "", "inertial number where mu is halfway from mu_s to mu_2"},
      {"grain_diameter_m", "d", "d", "m", "grain diameter"},
      {"grain_density_kg_m3", "rho_s", "ρs", "kg/m³", "grain density"}}},
    [](const FrictionParams& p) {  // a = beta / L = 2 I_0 sqrt(phi) / (5 d), no static branch
      return flow_friction(p.mu_s, p.mu_2 - p.mu_s, 2.0 * p.mu_i0 * std::sqrt(p.density / p.grain_density) / (5.0 * p.grain_diameter));
    },
    [](const FrictionParams& p) -> const char* {
      if (!(p.mu_s >= 0.0 && std::isfinite(p.mu_s))) return "mu_s must be >= 0";
      if (!(p.mu_2 >= p.mu_s && std::isfinite(p.mu_2))) return "mu_2 must be >= mu_s";
      if (!(p.mu_i0 > 0.0 && std::isfinite(p.mu_i0))) return "mu_i0 (I_0) must be > 0";
      if (!(p.grain_diameter > 0.0 && std::isfinite(p.grain_diameter))) return "grain_diameter_m (d) must be > 0 m";
      if (!(p.grain_density > 0.0 && std::isfinite(p.grain_density))) return "grain_density_kg_m3 (rho_s) must be > 0";
      if (!(p.density <= p.grain_density))
        return "density_kg_m3 must not exceed grain_density_kg_m3 (mu_i: their ratio is the solid fraction phi <= 1)";
      return "";
    }};

}  // namespace runout::engine::friction
