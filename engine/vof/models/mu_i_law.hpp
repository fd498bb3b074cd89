#pragma once
// The mu(I) law of the granular phase (Jop, Forterre & Pouliquen 2006): the shear stress is
// mu(I) p along the strain rate, with the inertial number I = d |strain rate| / sqrt(p / rho_s) and
//   mu(I) = mu_s + (mu_2 - mu_s) / (I_0 / I + 1),
// (models/mu_i.hpp makes it the viscosity nu = mu(I) p / (rho1 |strain rate|)). Header-only and free
// of the solver's libraries, so that a scenario's parameters are checked where it is resolved.
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

#include "engine/vof/config.hpp"
#include "engine/vof/error.hpp"

namespace runout::engine::vof {

class MuILaw {
 public:
  /// Checks the parameters (VofError naming the one that is wrong) and, regularised, joins the
  /// branches (VofError when mu_2 - mu_s is too small for alpha).
  MuILaw(const VofConfig::MuI& m, double rho1, bool regularised)
      : mu_s_(m.mu_s), dmu_(m.mu_2 - m.mu_s), i0_(m.i0), alpha_(m.alpha != 0 ? m.alpha : scaled_alpha(m)) {
    if (!(m.mu_s > 0 && std::isfinite(m.mu_s))) throw VofError("mu(I): mu_s must be > 0 (got " + std::to_string(m.mu_s) + ")");
    if (!(m.mu_2 >= m.mu_s && std::isfinite(m.mu_2)))
      throw VofError("mu(I): mu_2 must be at least mu_s (got mu_2 = " + std::to_string(m.mu_2) + ", mu_s = " + std::to_string(m.mu_s) + ")");
    if (!(m.i0 > 0 && std::isfinite(m.i0))) throw VofError("mu(I): I_0 must be > 0 (got " + std::to_string(m.i0) + ")");
    if (!(m.grain_diameter > 0 && m.grain_diameter < 1))
      throw VofError("mu(I): the grain diameter must lie in (0, 1) m (got " + std::to_string(m.grain_diameter) + ")");
    if (!(m.grain_density >= rho1 && std::isfinite(m.grain_density)))
      throw VofError("mu(I): the grain density must be at least the bulk density " + std::to_string(rho1) + " kg/m3 (got " +
                     std::to_string(m.grain_density) + ")");
    if (regularised && dmu_ > 0) join();
  }

  /// mu(I) for I >= 0.
  double friction(double I) const {
    if (I < i1_) return I > 0 ? std::sqrt(alpha_ / std::log(a_ / I)) : 0.0;
    return law(I);
  }
  bool constant() const { return dmu_ == 0; }  ///< mu_2 = mu_s: the Coulomb limit
  /// The smallest alpha for which the regularisation joins the law of mu_s, mu_2 and I_0 (the join
  /// needs 2 alpha I mu'(I) >= mu(I)^3 somewhere); infinite for mu_2 = mu_s.
  static double smallest_alpha(double mu_s, double mu_2, double i0) {
    if (!(mu_2 > mu_s)) return HUGE_VAL;
    double most = 0;  // the largest 2 I mu'(I) / mu(I)^3 over a fine logarithmic scan
    for (double I = 1e-12; I < 1e3; I *= 1.001) {
      const double mu = law(mu_s, mu_2 - mu_s, i0, I);
      most = std::max(most, 2 * I * slope(mu_2 - mu_s, i0, I) / (mu * mu * mu));
    }
    return most > 0 ? 1 / most : HUGE_VAL;
  }
  /// alpha when VofConfig::MuI::alpha is 0: Barker & Gray's 1.9 for the glass beads (MuI's
  /// defaults), scaled with the smallest alpha that joins (0.886 for the beads; 2.7 for PVC's law and
  /// 4.0 for the sands' of the lab materials, whose mu_s is higher), so that every law is joined as
  /// far from its limit as the beads'.
  static double scaled_alpha(const VofConfig::MuI& m) {
    static const double beads = smallest_alpha(VofConfig::MuI{}.mu_s, VofConfig::MuI{}.mu_2, VofConfig::MuI{}.i0);
    const double own = smallest_alpha(m.mu_s, m.mu_2, m.i0);
    return std::isfinite(own) ? 1.9 * own / beads : 1.9;
  }
  double mu_s() const { return mu_s_; }
  double alpha() const { return alpha_; }
  double i1() const { return i1_; }  ///< below it the regularised branch (0: none)

 private:
  static double law(double mu_s, double dmu, double i0, double I) { return mu_s + dmu / (i0 / I + 1.0); }
  static double slope(double dmu, double i0, double I) { return dmu * i0 / ((i0 + I) * (i0 + I)); }
  double law(double I) const { return law(mu_s_, dmu_, i0_, I); }
  double slope(double I) const { return slope(dmu_, i0_, I); }
  VofError cannot_join(const std::string& why) const {
    return VofError("mu(I): the regularisation cannot join the law (mu_2 - mu_s = " + std::to_string(dmu_) + " is too small for alpha = " +
                    std::to_string(alpha_) + why + "); take the unregularised law (mu_i_unregularised) or a larger mu_2 - mu_s");
  }
  double gap(double I) const { return 2 * alpha_ * I * slope(I) - std::pow(law(I), 3); }

  // I_1: the first sign change of gap() on a logarithmic scan, refined by bisection.
  void join() {
    if (!(alpha_ > 0 && std::isfinite(alpha_))) throw VofError("mu(I): the regularisation's alpha must be > 0");
    double lo = 1e-12, hi = -1;
    for (double I = lo; I < 1e3; I *= 1.1) {
      if (gap(I) > 0) {
        hi = I;
        break;
      }
      lo = I;
    }
    if (hi < 0) throw cannot_join("");
    for (int k = 0; k < 200 && hi - lo > 1e-15 * hi; ++k) {
      const double mid = 0.5 * (lo + hi);
      (gap(mid) > 0 ? hi : lo) = mid;
    }
    i1_ = hi;
    a_ = i1_ * std::exp(alpha_ / (law(i1_) * law(i1_)));
    if (!std::isfinite(a_)) throw cannot_join(": its branch would not creep");
  }

  double mu_s_, dmu_, i0_, alpha_;
  double i1_ = 0, a_ = 0;
};

}  // namespace runout::engine::vof
