#pragma once
// Basal friction and earth pressure of the depth-averaged model.
//
// The friction laws (Coulomb, Voellmy, Pouliquen-Forterre, mu(I)) are entries of
// engine/friction/registry.hpp; each gives tau_b = mu * N + rho * g * |u|^2 * inv_xi with N the basal
// normal stress, which on curved terrain includes the centrifugal part rho * h * kappa * |u|^2
// (Savage & Hutter 1991, dissertation eq. 3.48), and mu constant or mu(h, Fr) (engine/friction/law.hpp).
//
// Earth-pressure coefficient (Savage & Hutter 1989, dissertation eq. 3.36), active where the flow
// extends (du/dx >= 0), passive where it is compressed:
//   K_act/pass = 2 / cos^2(phi) * [1 -/+ sqrt(1 - cos^2(phi) / cos^2(delta))] - 1,
// cross-slope (Hutter et al. 1993):
//   K_y = 1/2 [K_x + 1 -/+ sqrt((K_x - 1)^2 + 4 tan^2(delta))].
// It requires delta <= phi. The mode "unity" uses K = 1 (hydrostatic), as most exact solutions do.
// Angles are radians here; user input in degrees is converted at the boundary of the program.
#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/friction/registry.hpp"
#include "engine/names.hpp"

namespace runout::engine {

enum class EarthPressure { unity, active_passive };
inline constexpr NameTable<EarthPressure, 2> kEarthPressureNames{
    {{"unity", EarthPressure::unity}, {"active-passive", EarthPressure::active_passive}}};

/// The flowing material: its friction law (engine/friction/registry.hpp) with that law's parameters
/// and the bulk density (FrictionParams), and the earth pressure.
struct Material : FrictionParams {
  const FrictionLaw* rheology = &friction::coulomb;
  double phi = 0.0;        ///< internal friction angle [rad] (earth pressure)
  EarthPressure earth_pressure = EarthPressure::unity;

  /// The law's coefficients, computed once before a run.
  BasalFriction friction() const { return rheology->coefficients(*this); }
  /// Basal Coulomb coefficient: tan(delta) for Coulomb, mu for Voellmy, the lowest one (tan delta_1,
  /// mu_s) for a flow-dependent law; the earth pressure's delta is its arc tangent.
  double coulomb_coefficient() const { return friction().mu; }
  /// 1/xi, zero for pure Coulomb friction.
  double inv_xi() const { return friction().inv_xi; }

  /// Throws std::invalid_argument naming the offending parameter.
  void validate() const {
    auto bad = [](const std::string& m) { throw std::invalid_argument("material: " + m); };
    if (rheology == nullptr) bad("no friction law");
    if (const std::string why = rheology->check(*this); !why.empty()) bad(why);
    if (earth_pressure == EarthPressure::active_passive) {
      if (!(phi > 0.0 && phi < M_PI / 2)) bad("internal friction angle phi must lie in (0, 90) degrees");
      if (std::atan(coulomb_coefficient()) > phi + 1e-12)
        bad("earth-pressure mode active-passive needs bed friction <= internal friction (delta <= phi)");
    }
    if (!(density > 0.0)) bad("density must be > 0");
  }
};

/// A Pouliquen-Forterre material: delta_1, delta_2, delta_3 [rad] (NaN: delta_1), beta, L [m], gamma.
inline Material pouliquen_forterre_material(double delta1, double delta2, double delta3, double beta, double length,
                                            double gamma) {
  Material m;
  m.rheology = &friction::pouliquen_forterre;
  m.delta1 = delta1;
  m.delta2 = delta2;
  m.delta3 = delta3;
  m.pf_beta = beta;
  m.pf_length = length;
  m.pf_gamma = gamma;
  return m;
}

/// A mu(I) material: mu_s, mu_2, I_0, grain diameter [m], grain density and bulk density [kg/m^3].
inline Material mu_i_material(double mu_s, double mu_2, double i0, double diameter, double grain_density, double density) {
  Material m;
  m.rheology = &friction::mu_i;
  m.mu_s = mu_s;
  m.mu_2 = mu_2;
  m.mu_i0 = i0;
  m.grain_diameter = diameter;
  m.grain_density = grain_density;
  m.density = density;
  return m;
}

/// K_x active (extension) or passive (compression) from phi and delta [rad].
inline double k_x(double phi, double delta, bool active) {
  const double c2p = std::cos(phi) * std::cos(phi);
  const double c2d = std::cos(delta) * std::cos(delta);
  const double root = std::sqrt(std::max(0.0, 1.0 - c2p / c2d));
  return 2.0 / c2p * (1.0 + (active ? -root : root)) - 1.0;
}

/// K_y from K_x and delta; active (extension across the slope) takes the minus sign.
inline double k_y(double kx, double delta, bool active) {
  const double t = std::tan(delta);
  const double root = std::sqrt((kx - 1.0) * (kx - 1.0) + 4.0 * t * t);
  return 0.5 * (kx + 1.0 + (active ? -root : root));
}

/// Apply a friction impulse of magnitude `impulse` (>= 0) against momentum (mx, my) of 3D
/// magnitude m3 (>= |(mx,my)|): the momentum shrinks towards zero and never reverses. Returns true
/// when the material is brought exactly to rest.
inline bool apply_friction(double& mx, double& my, double m3, double impulse) {
  if (m3 <= impulse) {
    mx = 0.0;
    my = 0.0;
    return true;
  }
  const double f = 1.0 - impulse / m3;
  mx *= f;
  my *= f;
  return false;
}

/// Voellmy's turbulent drag g |u|^2 / xi (per unit area, over density) integrated implicitly over a
/// time span `dt` for material of normal depth h: du/dt = -g u^2 / (xi h) gives
/// u_new = 2 u / (1 + sqrt(1 + 4 a u)), a = dt g / (xi h). Returns u_new / u (1 without drag), which is
/// stable for any dt and thin layers (an explicit step is not: thin films would accelerate freely).
inline double turbulent_factor(double speed, double h, double g_inv_xi_dt) {
  const double a = g_inv_xi_dt / h;
  return 2.0 / (1.0 + std::sqrt(1.0 + 4.0 * a * speed));
}

}  // namespace runout::engine
