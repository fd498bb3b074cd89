// The mu(I) rheology as the granular phase's viscosity: nu = mu(I) p / (rho1 |strain rate|) with
// I = d |strain rate| / sqrt(p / rho_s), clipped to [nu_min, nu_max] like the Coulomb viscosity
// (which is the limit mu_2 = mu_s: then both give the same bits). The law and its regularisation:
// mu_i_law.hpp.
#include <algorithm>
#include <cmath>

#include "engine/vof/models/granular_viscosity.hpp"
#include "engine/vof/models/mu_i_law.hpp"

namespace runout::engine::vof {

namespace {

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

}  // namespace

std::unique_ptr<GranularViscosity> make_mu_i_viscosity(const VofConfig& cfg) { return std::make_unique<MuIViscosity>(cfg, true); }
std::unique_ptr<GranularViscosity> make_mu_i_unregularised_viscosity(const VofConfig& cfg) {
  return std::make_unique<MuIViscosity>(cfg, false);
}

}  // namespace runout::engine::vof
