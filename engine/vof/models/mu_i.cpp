// The mu(I) rheology of the granular phase (Jop, Forterre & Pouliquen 2006): the shear stress is
// mu(I) p along the strain rate, with the inertial number I = d |strain rate| / sqrt(p / rho_s) and
//   mu(I) = mu_s + (mu_2 - mu_s) / (I_0 / I + 1),
// as a viscosity nu = mu(I) p / (rho1 |strain rate|), clipped to [nu_min, nu_max] like the Coulomb
// viscosity (which is the limit mu_2 = mu_s: then both give the same bits).
//
// "mu_i" takes Barker & Gray (2017)'s partial regularisation. The law above makes the equations
// ill posed at low I (small perturbations grow the faster the shorter their wavelength, so results
// depend on the mesh); below an inertial number I_1 the friction is instead
//   mu(I) = sqrt(alpha / ln(A / I)),
// which is well posed there and goes to 0 as I -> 0 (the material creeps under any stress, slowly:
// with the default beads I_1 = 0.0207, and mu is 0.357 at I = 1e-3 and 0.295 at I = 1e-6 against
// mu_s = 0.382). I_1 and A join the two branches with the same
// value and slope: the slope of the low branch is mu^3 / (2 alpha I), so I_1 is the smallest root
// of 2 alpha I mu'(I) - mu(I)^3 and A = I_1 exp(alpha / mu(I_1)^2). It is partial: at high I the
// law stays ill posed, as every mu(I) curve is there. "mu_i_unregularised" takes the law as it
// stands, for comparison.
#include <algorithm>
#include <cmath>
#include <string>

#include "engine/vof/models/granular_viscosity.hpp"

namespace runout::engine::vof {

namespace {

class MuIViscosity final : public GranularViscosity {
 public:
  MuIViscosity(const VofConfig& c, bool regularised)
      : mu_s_(c.mu_i.mu_s), dmu_(c.mu_i.mu_2 - c.mu_i.mu_s), i0_(c.mu_i.i0), d_(c.mu_i.grain_diameter),
        rho_s_(c.mu_i.grain_density), alpha_(c.mu_i.alpha), rho1_(c.rho1), nu_min_(c.nu_min), nu_max_(c.nu_max) {
    const auto& m = c.mu_i;
    if (!(m.mu_s > 0 && std::isfinite(m.mu_s))) throw VofError("mu(I): mu_s must be > 0 (got " + std::to_string(m.mu_s) + ")");
    if (!(m.mu_2 >= m.mu_s && std::isfinite(m.mu_2)))
      throw VofError("mu(I): mu_2 must be at least mu_s (got mu_2 = " + std::to_string(m.mu_2) + ", mu_s = " + std::to_string(m.mu_s) + ")");
    if (!(m.i0 > 0 && std::isfinite(m.i0))) throw VofError("mu(I): I_0 must be > 0 (got " + std::to_string(m.i0) + ")");
    if (!(m.grain_diameter > 0 && m.grain_diameter < 1))
      throw VofError("mu(I): the grain diameter must lie in (0, 1) m (got " + std::to_string(m.grain_diameter) + ")");
    if (!(m.grain_density >= c.rho1 && std::isfinite(m.grain_density)))
      throw VofError("mu(I): the grain density must be at least the bulk density " + std::to_string(c.rho1) + " kg/m3 (got " +
                     std::to_string(m.grain_density) + ")");
    if (regularised && dmu_ > 0) join(m);
  }

  double nu(double p, double sr) const override {
    const double s = std::max(sr, 1e-300);
    const double mu = dmu_ != 0 && p > 0 ? friction(d_ * s / std::sqrt(p / rho_s_)) : mu_s_;
    const double nu = mu * p / (rho1_ * s);
    return std::clamp(std::isfinite(nu) ? nu : nu_max_, nu_min_, nu_max_);
  }

  double friction(double I) const {
    if (I < i1_) return I > 0 ? std::sqrt(alpha_ / std::log(a_ / I)) : 0.0;
    return mu_s_ + dmu_ / (i0_ / I + 1.0);
  }

 private:
  double law(double I) const { return mu_s_ + dmu_ / (i0_ / I + 1.0); }
  double slope(double I) const { return dmu_ * i0_ / ((i0_ + I) * (i0_ + I)); }
  double gap(double I) const { return 2 * alpha_ * I * slope(I) - std::pow(law(I), 3); }

  // I_1: the first sign change of gap() on a logarithmic scan, refined by bisection.
  void join(const VofConfig::MuI& m) {
    if (!(m.alpha > 0 && std::isfinite(m.alpha))) throw VofError("mu(I): the regularisation's alpha must be > 0");
    double lo = 1e-12, hi = -1;
    for (double I = lo; I < 1e3; I *= 1.1) {
      if (gap(I) > 0) {
        hi = I;
        break;
      }
      lo = I;
    }
    if (hi < 0)
      throw VofError("mu(I): the regularisation cannot join the law (mu_2 - mu_s = " + std::to_string(dmu_) +
                     " is too small for alpha = " + std::to_string(m.alpha) +
                     "); take the unregularised law (mu_i_unregularised) or a larger mu_2 - mu_s");
    for (int k = 0; k < 200 && hi - lo > 1e-15 * hi; ++k) {
      const double mid = 0.5 * (lo + hi);
      (gap(mid) > 0 ? hi : lo) = mid;
    }
    i1_ = hi;
    a_ = i1_ * std::exp(alpha_ / (law(i1_) * law(i1_)));
  }

  double mu_s_, dmu_, i0_, d_, rho_s_, alpha_, rho1_, nu_min_, nu_max_;
  double i1_ = 0, a_ = 0;  // below I_1 the regularised branch (I_1 = 0: none)
};

}  // namespace

std::unique_ptr<GranularViscosity> make_mu_i_viscosity(const VofConfig& cfg) { return std::make_unique<MuIViscosity>(cfg, true); }
std::unique_ptr<GranularViscosity> make_mu_i_unregularised_viscosity(const VofConfig& cfg) {
  return std::make_unique<MuIViscosity>(cfg, false);
}

}  // namespace runout::engine::vof
