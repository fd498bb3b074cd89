#pragma once
// The mu(I) rheology as the granular phase's viscosity: nu = mu(I) p / (rho1 |strain rate|) with
// I = d |strain rate| / sqrt(p / rho_s), clipped to [nu_min, nu_max] like the Coulomb viscosity
// (which is the limit mu_2 = mu_s: then both give the same bits). The law and its regularisation:
// mu_i_law.hpp. Two rows: "mu_i" (regularised at low I) and "mu_i_unregularised".
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "engine/vof/models/granular_viscosity.hpp"
#include "engine/vof/models/mu_i_law.hpp"

namespace runout::engine::vof {

class MuIViscosity final : public GranularViscosity {
 public:
  MuIViscosity(const VofConfig& c, bool regularised)
      : law_(c.mu_i, c.rho1, regularised), d_(c.mu_i.grain_diameter), rho_s_(c.mu_i.grain_density), rho1_(c.rho1),
        nu_min_(c.nu_min), nu_max_(c.nu_max) {}

  double nu(double p, double sr) const override {
    const double s = std::max(sr, 1e-300);
    const double mu = !law_.constant() && p > 0 ? law_.friction(d_ * s / std::sqrt(p / rho_s_)) : law_.mu_s();
    const double nu = mu * p / (rho1_ * s);
    return std::clamp(std::isfinite(nu) ? nu : nu_max_, nu_min_, nu_max_);
  }

 private:
  MuILaw law_;
  double d_, rho_s_, rho1_, nu_min_, nu_max_;
};

namespace models {

/// mu(I)'s checks: mu_2 >= mu_s, rho_s >= rho1 (the solid fraction at most 1), then the law's own
/// (MuILaw: its parameters and, regularised, the join of its branches, named as mu_2's).
inline ModelProblem check_mu_i(const VofConfig& c, bool regularised) {
  auto num = [](double v) {
    std::ostringstream o;
    o << v;
    return o.str();
  };
  const auto& m = c.mu_i;
  if (!(m.mu_2 >= m.mu_s)) return {"mu_2", "must be at least mu_s (" + num(m.mu_s) + "), got " + num(m.mu_2)};
  if (!(m.grain_density >= c.rho1))
    return {"grain_density_kg_m3", "must be at least the material's density " + num(c.rho1) + " kg/m3, got " + num(m.grain_density)};
  try {
    const MuILaw law(m, c.rho1, regularised);
    (void)law;
  } catch (const VofError& e) {
    return {"mu_2", e.what()};
  }
  return {};
}

/// The parameters of both rows (VofConfig::MuI; its defaults the glass beads of Jop et al. 2006).
inline constexpr std::array<ModelParameter, 6> kMuIParameters{{
    {"mu_s", "mu_s", "μs", "", 0, 5, true, false, "static friction coefficient (I -> 0)",
     [](VofConfig& c) -> double& { return c.mu_i.mu_s; }},
    {"mu_2", "mu_2", "μ₂", "", 0, 5, true, false, "limiting friction coefficient, at least mu_s (I -> infinity)",
     [](VofConfig& c) -> double& { return c.mu_i.mu_2; }},
    {"mu_i0", "I_0", "I₀", "", 0, 10, true, false, "the inertial number where mu is halfway from mu_s to mu_2",
     [](VofConfig& c) -> double& { return c.mu_i.i0; }},
    {"grain_diameter_m", "d", "d", "m", 0, 0.1, true, false, "grain diameter",
     [](VofConfig& c) -> double& { return c.mu_i.grain_diameter; }},
    {"grain_density_kg_m3", "rho_s", "ρs", "kg/m3", 100, 20000, false, false,
     "grain density, at least the material's density (their ratio is the solid fraction)",
     [](VofConfig& c) -> double& { return c.mu_i.grain_density; }},
}};

inline constexpr GranularViscosityModel mu_i{
    "mu_i",
    "μ(I) viscosity",
    "nu = mu(I) p / (rho \\|strain rate\\|), mu = mu_s + (mu_2 - mu_s) / (I_0 / I + 1), I = d \\|strain rate\\| / sqrt(p / rho_s) "
    "(Jop, Forterre & Pouliquen 2006), below I_1 the regularised sqrt(alpha / ln(A / I)) (Barker & Gray 2017)",
    kMuIParameters,
    [](const VofConfig& c) { return check_mu_i(c, true); },
    [](const VofConfig& c) -> std::unique_ptr<GranularViscosity> { return std::make_unique<MuIViscosity>(c, true); }};

inline constexpr GranularViscosityModel mu_i_unregularised{
    "mu_i_unregularised",
    "μ(I) viscosity, unregularised",
    "as `mu_i` without the regularisation: the law as it stands at every I (ill posed at low I; for comparison)",
    kMuIParameters,
    [](const VofConfig& c) { return check_mu_i(c, false); },
    [](const VofConfig& c) -> std::unique_ptr<GranularViscosity> { return std::make_unique<MuIViscosity>(c, false); }};

}  // namespace models

}  // namespace runout::engine::vof
