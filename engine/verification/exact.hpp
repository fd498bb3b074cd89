#pragma once
// Exact and semi-exact solutions of the Savage-Hutter equations used for verification
// (docs/validation/verification.md; cases A1, A2, A3, A5 of the validation plan). Slope coordinates:
// x along the slope (downhill positive), depth h normal to it, zeta inclination, delta bed
// friction angle, K earth-pressure coefficient, g gravity. Angles in radians.
namespace runout::engine::exact {

/// A1: dam break on an inclined plane with Coulomb friction (Mangeney, Heinrich & Roche 2000).
/// Reservoir h0 for x <= 0 at t = 0, dry beyond; K = 1; needs tan(zeta) > tan(delta).
struct DamBreak {
  double zeta, delta, h0, g = 9.81;
  double c0() const;
  double m() const;
  double front(double t) const;                      ///< x_f = 2 c0 t + m t^2 / 2
  void at(double x, double t, double& h, double& u) const;
};

/// A2: parabolic cap (Savage & Hutter 1989 similarity solution, 1D).
struct ParabolicCap {
  double zeta, delta, K = 1.0, L0, H0, x0 = 0.0, g = 9.81;
  double accel() const;        ///< g (sin zeta - tan delta cos zeta)
  double time_of(double s) const;  ///< t at which L = s L0 (closed form)
  double half_length(double t) const;
  double spreading_rate(double t) const;  ///< L'(t)
  double centre(double t) const;
  void at(double x, double t, double& h, double& u) const;
};

/// A3: elliptic cap in 2D (Hutter, Siegel, Savage & Nohguchi 1993), similarity ODEs integrated with
/// RK4 (series start for tau < 0.1).
struct EllipticCap {
  double zeta, delta, Kx = 1.0, Ky = 1.0, Lx, Ly, H, g = 9.81;
  struct Shape {
    double centre;       ///< distance travelled by the centre along the slope [m]
    double max_depth;    ///< H / (f g) [m]
    double half_length;  ///< Lx g(tau) [m]
    double half_width;   ///< Ly f(tau) [m]
  };
  Shape at(double t) const;
  double depth(double x, double y, double t) const;  ///< x along the slope from the initial centre
};

/// A5: steady depth-averaged velocity down a uniform chute (Pudasaini 2011; dissertation eq. 6.1)
/// for inflow depth h0 and velocity u0 at x0 (supercritical branch).
struct SteadyChute {
  double zeta, delta, K = 1.0, h0, u0, x0 = 0.0, g = 9.81;
  double velocity(double x) const;
  double depth(double x) const { return h0 * u0 / velocity(x); }
};

}  // namespace runout::engine::exact
