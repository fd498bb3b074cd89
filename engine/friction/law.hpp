#pragma once
// A basal friction law of the depth-averaged engines: its name, its parameters and its resistance.
//
// Every law gives the basal shear stress as
//   tau_b = mu * N + rho * g * |u|^2 * inv_xi
// with N the basal normal stress (on curved terrain with its centrifugal part, Savage & Hutter
// 1991). A law computes its coefficients once from its parameters before a run (BasalFriction), so
// that the kernels stay branch-free. mu is either a constant (Coulomb, Voellmy) or a function of
// the flow, mu(h, Fr) with Fr = |u| / sqrt(g_n h) (Pouliquen-Forterre, mu(I)): one family,
//   mu(h, Fr) = mu + dmu F / (a h + F) + dstart (1 - min(Fr / beta_s, 1)^kappa),
//   F = max(Fr + gamma, beta),
// whose numbers the law fills in (flow_mu evaluates it). The engines apply the first term of tau_b as
// a bounded impulse (apply_friction) and the second implicitly (turbulent_factor); which form of mu
// a kernel computes is a template parameter (MuForm), so a constant mu costs nothing more.
//
// A new law: one header beside coulomb.hpp (a FrictionLaw with its name, the caption the maps print,
// its equation, its parameter rows with their map labels and units, its coefficients and checks) and
// one line in registry.hpp (tests/unit/test_flow_friction.cpp runs an example law that is not in the
// table through both engines); a law outside the family above also needs
// its term in the kernels (engine/sh1d.cpp, engine/sh2d/kernels.hpp).
#include <array>
#include <cmath>
#include <limits>
#include <string_view>

namespace runout::engine {

/// The parameters the laws read (SI, angles in radians); a law reads those it lists.
struct FrictionParams {
  double delta = 0.0;   ///< bed friction angle [rad] (Coulomb)
  double mu = 0.0;      ///< Voellmy dry-friction coefficient [-]
  double xi = 1.0e300;  ///< Voellmy turbulent-friction coefficient [m/s^2]
  // Pouliquen-Forterre
  double delta1 = 0.0;  ///< delta_1: the lowest friction angle of steady flow [rad]
  double delta2 = 0.0;  ///< delta_2: the friction angle of thin layers [rad]
  double delta3 = std::numeric_limits<double>::quiet_NaN();  ///< delta_3 of mu_start [rad]; NaN: delta_1
  double pf_beta = 0.0;    ///< beta of the flow rule Fr = beta h / h_stop - gamma [-]
  double pf_length = 0.0;  ///< L, the length of h_stop [m]
  double pf_gamma = 0.0;   ///< gamma of the flow rule [-]
  // mu(I)
  double mu_s = 0.0;            ///< friction coefficient as I -> 0 [-]
  double mu_2 = 0.0;            ///< friction coefficient as I -> infinity [-]
  double mu_i0 = 0.0;           ///< I_0 [-]
  double grain_diameter = 0.0;  ///< d [m]
  double grain_density = 0.0;   ///< rho_s [kg/m^3]
  double density = 300.0;       ///< bulk density rho [kg/m^3]: pressure outputs; mu(I)'s phi = rho / rho_s
};

/// How a kernel computes mu: a constant, mu(h, Fr), or mu(h, Fr) with the start/stop term (dstart != 0).
enum class MuForm { constant, flow, hysteresis };

/// The coefficients of tau_b = mu N + rho g |u|^2 inv_xi.
struct BasalFriction {
  double mu = 0.0;      ///< Coulomb coefficient [-]; of a flow-dependent law its lowest (tan delta_1, mu_s)
  double inv_xi = 0.0;  ///< 1/xi [s^2/m]; 0: no turbulent drag
  // mu(h, Fr) (law.hpp's header): unused while `flow` is false. A flow-dependent law has no
  // turbulent term (inv_xi = 0): the 2D kernels of mu(h, Fr) leave Voellmy's drag out.
  bool flow = false;
  double dmu = 0.0;     ///< tan delta_2 - tan delta_1, mu_2 - mu_s [-]
  double a = 0.0;       ///< beta / L, 2 I_0 sqrt(phi) / (5 d) [1/m]
  double gamma = 0.0;   ///< [-]
  double beta = 0.0;    ///< Fr + gamma below beta takes the static branch; 0: none [-]
  double dstart = 0.0;  ///< tan delta_3 - tan delta_1: mu_start - mu_stop [-]
  double beta_s = 0.0;  ///< beta - gamma: below this Fr the start/stop term acts [-]
  static constexpr double kappa = 1e-3;  ///< the start/stop term's exponent (Pouliquen & Forterre 2002)

  MuForm form() const { return !flow ? MuForm::constant : dstart != 0.0 ? MuForm::hysteresis : MuForm::flow; }
};

/// The coefficients of a flow-dependent law: mu, dmu, a, gamma, beta and dstart of law.hpp's family.
inline BasalFriction flow_friction(double mu, double dmu, double a, double gamma = 0.0, double beta = 0.0, double dstart = 0.0) {
  BasalFriction f;
  f.mu = mu;
  f.flow = true;
  f.dmu = dmu;
  f.a = a;
  f.gamma = gamma;
  f.beta = beta;
  f.dstart = dstart;
  f.beta_s = beta - gamma;
  return f;
}

/// mu(h, Fr) of a flow-dependent law without its start/stop term, and q = min(Fr / beta_s, 1) for it.
struct MuParts {
  double mu, q;
};
inline MuParts flow_mu_parts(const BasalFriction& f, double h, double speed, double gn) {
  const double s = std::sqrt(gn * h);  // Fr = speed / s; the ratio below is F / (a h + F), scaled by s
  const double x = speed + f.gamma * s, b = f.beta * s;
  const double F = x < b ? b : x;
  const double den = f.a * h * s + F;  // >= F >= 0
  const double bs = f.beta_s * s;
  return {f.mu + f.dmu * (F / (den > 1e-300 ? den : 1e-300)), (speed < bs ? speed : bs) / (bs > 1e-300 ? bs : 1e-300)};
}
/// q^kappa for q in [0, 1], the power only strictly between: it is exactly 0 and 1 at the ends.
inline double start_weight(double q) { return q > 0.0 && q < 1.0 ? std::pow(q, BasalFriction::kappa) : q; }
/// mu with the start/stop term, from flow_mu_parts' mu and the weight w = q^kappa.
inline double with_start(const BasalFriction& f, double mu, double w) { return mu + f.dstart * (1.0 - w); }

/// mu(h, Fr) of a flow-dependent law for normal depth h [m], speed [m/s] and normal load g_n [m/s^2]
/// (Fr = speed / sqrt(g_n h)), finite for every h, speed, g_n >= 0. Hysteresis: with the start/stop
/// term. Every kernel of both engines evaluates mu through these inline functions, in this order, so
/// that all give the same bits; with dmu = 0 and no start/stop term it returns mu exactly.
template <bool Hysteresis>
inline double flow_mu(const BasalFriction& f, double h, double speed, double gn) {
  const MuParts p = flow_mu_parts(f, h, speed, gn);
  if constexpr (Hysteresis) return with_start(f, p.mu, start_weight(p.q));
  else return p.mu;
}

/// A parameter of a law: the scenario's field (in `material`), its symbol, how maps print it and
/// what it is.
struct FrictionParameter {
  std::string_view field;   ///< e.g. "bed_friction_deg"
  std::string_view symbol;  ///< e.g. "delta"
  std::string_view label;   ///< the symbol on maps, e.g. "δ"
  std::string_view unit;    ///< the unit on maps, e.g. "°", "m/s²"; empty: none
  std::string_view doc;
  std::string_view unset = {};  ///< what an unset field means; empty: the field is required
};

struct FrictionLaw {
  std::string_view name;      ///< the scenario's material.rheology
  std::string_view caption;   ///< the law's name on maps, e.g. "Voellmy"
  std::string_view equation;  ///< tau_b in words and symbols, with the source
  std::array<FrictionParameter, 6> parameters;  ///< those it reads (an empty field ends the list)
  BasalFriction (*coefficients)(const FrictionParams&);
  /// The parameters' physical limits: "" when valid, else what is wrong (naming the parameter).
  const char* (*check)(const FrictionParams&);
};

}  // namespace runout::engine
