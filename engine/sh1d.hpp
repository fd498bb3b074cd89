#pragma once
// One-dimensional Savage-Hutter equations along a curved channel (Savage & Hutter 1991;
// dissertation eqs. 3.47-3.48, dimensional form), arc length xi along the bed, depth h normal
// to the bed, depth-averaged velocity u along it:
//
//   dh/dt + d(h u)/dxi = 0
//   d(h u)/dt + d(h u^2 + beta h^2 / 2)/dxi
//       = h g sin(zeta) - sgn(u) [ h mu (g cos(zeta) + kappa u^2) + g u^2 / xi_V ],
//   beta = K g cos(zeta),
//
// zeta(xi) the local inclination (positive where the bed falls in +xi), kappa = -dzeta/dxi the
// bed curvature (positive where the channel flattens: concave), mu = tan(delta) (Coulomb), the
// Voellmy mu, or mu(h, Fr) with Fr = |u| / sqrt(g_n h), g_n = (g cos(zeta) + kappa u^2)_+ the same
// normal load (Pouliquen-Forterre, mu(I); engine/friction/law.hpp), and 1/xi_V = 0 but for Voellmy
// (Voellmy's drag is a stress, independent of the depth; it is integrated implicitly,
// engine/rheology.hpp turbulent_factor). K = 1 or K_act/pass from phi and delta by the sign of du/dxi
// (delta = atan of the law's lowest mu).
//
// Scheme: the NOC (non-oscillatory central) predictor-corrector of Tai et al. (2002) and the
// dissertation's section 4.2 with a TVD slope limiter (minmod by default): predictor (4.78) to
// t + dt/2 with the flux Jacobian applied to the limited slopes, then the staggered corrector
// (4.73) onto the cells [x_i, x_i+1]. The staggered solution is averaged back onto the fixed cells
// by the limited piecewise-linear reconstruction of Jiang, Levy, Lin, Osher & Tadmor (1998), so
// that every step returns to the same grid (needed for hazard maps and boundary conditions).
// Coulomb friction is applied as a bounded impulse (engine/rheology.hpp apply_friction): it stops
// material and holds it at rest, but never reverses its velocity. Its mu comes from the state at t in
// the predictor and from the half-step state in the corrector, as its load does.
// Time step: dt = cfl * dx / max(|u| + sqrt(beta h)), cfl <= 0.5 (dissertation eq. 4.90).
#include <functional>
#include <vector>

#include "engine/limiters.hpp"
#include "engine/rheology.hpp"
#include "engine/run_control.hpp"

namespace runout::engine {

/// Geometry of a channel: cell i has its centre at xi = x0 + (i + 1/2) dx.
struct Channel1D {
  int n = 0;
  double dx = 1.0;
  double x0 = 0.0;
  std::vector<double> zeta;   ///< inclination at cell centres [rad]
  std::vector<double> kappa;  ///< curvature at cell centres [1/m]

  double centre(int i) const { return x0 + (i + 0.5) * dx; }
  static Channel1D uniform(int n, double dx, double x0, double zeta);
  /// Inclination given as a function of arc length; curvature from -dzeta/dxi (centred differences).
  static Channel1D from_profile(int n, double dx, double x0, const std::function<double(double)>& zeta);
};

enum class Boundary1D { wall, outflow, inflow };
inline constexpr NameTable<Boundary1D, 3> kBoundary1DNames{
    {{"wall", Boundary1D::wall}, {"outflow", Boundary1D::outflow}, {"inflow", Boundary1D::inflow}}};

/// Inflow hydrograph: depth and velocity at the inflow boundary, linear in time between the given
/// points and constant outside them.
struct Hydrograph {
  std::vector<double> t, h, u;
  void at(double time, double& h_out, double& u_out) const;
};

/// A gauge at arc length `xi` inside the channel: at the start and after every step, `record` gets the
/// time and the depth and velocity there, linear between the cell centres around it (the end cells'
/// values beyond their centres). No gauge while `record` is empty.
struct Gauge1D {
  double xi = 0;
  std::function<void(double t, double h, double u)> record;
};

struct Sh1dConfig {
  Material material;
  Limiter limiter = Limiter::minmod;
  TimeControl time;
  Boundary1D left = Boundary1D::outflow, right = Boundary1D::outflow;
  Hydrograph inflow;        ///< used by a boundary of type inflow
  double gravity = 9.81;
  double dry_depth = 1e-8;  ///< below this depth the velocity is taken as zero [m]
  bool curvature = true;    ///< include the centrifugal normal load kappa u^2
  Gauge1D gauge;            ///< optional
};

struct Sh1dState {
  std::vector<double> h, m;  ///< depth [m] and discharge h*u [m^2/s] per cell
};

struct Sh1dResult {
  Sh1dState state;
  std::vector<double> max_depth, max_speed;
  double t = 0;
  long steps = 0;
  StopReason stop = StopReason::end_time;
  double mass_initial = 0, mass_final = 0;  ///< integral of h over the channel [m^2]
  double boundary_exchange = 0;  ///< mass gained through inflow minus lost through outflow [m^2]
  long positivity_clips = 0;     ///< staggered depths below zero that were set to zero
  double positivity_mass = 0;    ///< mass those clips added [m^2]
  double wall_seconds = 0;
};

/// Run the 1D solver from `initial` until the end time or the stopping rule. Throws
/// std::invalid_argument on inconsistent input (sizes, parameters).
Sh1dResult run_sh1d(const Channel1D& channel, const Sh1dConfig& config, Sh1dState initial);

}  // namespace runout::engine
