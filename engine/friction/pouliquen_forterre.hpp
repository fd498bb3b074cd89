#pragma once
// Pouliquen-Forterre friction (Pouliquen & Forterre 2002, with the gamma of Forterre & Pouliquen
// 2003): mu(h, Fr) from the depth h_stop(theta) = L (tan d2 - tan theta) / (tan theta - tan d1) that
// a steady flow leaves behind, and its flow rule Fr = beta h / h_stop - gamma:
//   flowing (Fr >= beta - gamma): mu = tan d1 + (tan d2 - tan d1) / (beta h / (L (Fr + gamma)) + 1),
//   slower:  mu = (Fr / (beta - gamma))^kappa (mu_stop(h) - mu_start(h)) + mu_start(h), kappa = 1e-3,
//   mu_stop(h) = tan d1 + (tan d2 - tan d1) / (h / L + 1), mu_start(h) = mu_stop(h) + tan d3 - tan d1.
// The two branches meet at Fr = beta - gamma (there the flowing branch equals mu_stop(h)), so mu is
// continuous and a steady flow of any depth above h_stop takes the flowing branch; with gamma = 0 this
// is Pouliquen & Forterre's switch at Fr = beta. docs/design/depth-averaged.md has the derivation.
#include <cmath>

#include "engine/friction/law.hpp"

namespace runout::engine::friction {

inline constexpr FrictionLaw pouliquen_forterre{
    "pouliquen_forterre",
    "Pouliquen–Forterre",
    "tau_b = mu(h, Fr) N, mu = tan d1 + (tan d2 - tan d1) / (beta h / (L (Fr + gamma)) + 1) while Fr >= beta - gamma, "
    "rising to mu_start(h) = tan d3 + (tan d2 - tan d1) / (h / L + 1) at rest, Fr = \\|u\\| / sqrt(g_n h) "
    "(Pouliquen & Forterre 2002; Forterre & Pouliquen 2003)",
    {{{"bed_friction_1_deg", "delta_1", "δ₁", "°", "lowest friction angle of steady flow"},
      {"bed_friction_2_deg", "delta_2", "δ₂", "°", "friction angle of thin layers"},
      {"bed_friction_3_deg", "delta_3", "δ₃", "°", "friction angle of mu_start", "delta_1, no start/stop hysteresis"},
      {"pf_beta", "beta", "β", "", "slope of the flow rule Fr = beta h / h_stop - gamma"},
      {"pf_length_m", "L", "L", "m", "length of h_stop"},
      {"pf_gamma", "gamma", "γ", "", "offset of the flow rule", "0"}}},
    [](const FrictionParams& p) {
      const double t1 = std::tan(p.delta1), t3 = std::isnan(p.delta3) ? t1 : std::tan(p.delta3);
      return flow_friction(t1, std::tan(p.delta2) - t1, p.pf_beta / p.pf_length, p.pf_gamma, p.pf_beta, t3 - t1);
    },
    [](const FrictionParams& p) -> const char* {
      if (!(p.delta1 >= 0.0 && p.delta1 < p.delta2 && p.delta2 < M_PI / 2))
        return "pouliquen_forterre needs 0 <= bed_friction_1_deg < bed_friction_2_deg < 90 degrees (delta_1 < delta_2)";
      if (!std::isnan(p.delta3) && !(p.delta3 >= p.delta1 && p.delta3 < M_PI / 2))
        return "bed_friction_3_deg (delta_3) must lie in [bed_friction_1_deg, 90) degrees";
      if (!(p.pf_beta > 0.0 && std::isfinite(p.pf_beta))) return "pf_beta (beta) must be > 0";
      if (!(p.pf_length > 0.0 && std::isfinite(p.pf_length))) return "pf_length_m (L) must be > 0 m";
      if (!(p.pf_gamma >= 0.0 && p.pf_gamma < p.pf_beta)) return "pf_gamma (gamma) must lie in [0, pf_beta)";
      return "";
    }};

}  // namespace runout::engine::friction
