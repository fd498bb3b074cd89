// The Coulomb viscosity of the granular phase (listing B.1): nu = tan(phi) p / (rho1 |strain rate|),
// clipped to [nu_min, nu_max]; where the strain rate vanishes, nu_max.
#include <algorithm>
#include <cmath>

#include "engine/vof/models/granular_viscosity.hpp"

namespace runout::engine::vof {

namespace {

constexpr double kPi = 3.14159265358979323846;

class CoulombViscosity final : public GranularViscosity {
 public:
  explicit CoulombViscosity(const VofConfig& c)
      : tan_phi_(std::tan(c.phi_deg * kPi / 180)), rho1_(c.rho1), nu_min_(c.nu_min), nu_max_(c.nu_max) {}
  double nu(double p, double sr) const override {
    const double nu = tan_phi_ * p / (rho1_ * std::max(sr, 1e-300));
    return std::clamp(std::isfinite(nu) ? nu : nu_max_, nu_min_, nu_max_);
  }

 private:
  double tan_phi_, rho1_, nu_min_, nu_max_;
};

}  // namespace

std::unique_ptr<GranularViscosity> make_coulomb_viscosity(const VofConfig& cfg) { return std::make_unique<CoulombViscosity>(cfg); }

}  // namespace runout::engine::vof
