// coulomb_slip: the Coulomb slip wall of listing B.2. Air sticks; material slides with the slip
// fraction that makes the cell's viscous shear carry tan(delta) times the bed pressure, and sticks
// where that shear exceeds it. The shear takes the cell's viscosity, from which the slip fraction is
// computed.
#include <algorithm>

#include "engine/vof/bc/boundary.hpp"

namespace runout::engine::vof {

namespace {

class CoulombSlip final : public BoundaryCondition {
 public:
  explicit CoulombSlip(const PatchBc& bc) : tan_delta_(bc.tan_delta) {}
  Vec velocity(const BcContext& c, int f) const override {
    const Mesh& m = c.mesh;
    const int o = m.owner[f];
    const Vec Up = c.fields.U[o];
    const Vec n = unit_normal(m, f);
    const Vec ut = Up - dot(Up, n) * n;
    const double mag = norm(ut);
    double vf = 1.0;  // stick
    if (c.fields.alpha[o] >= 0.5) {
      const double mub = c.fields.mu[o];
      const double pb = c.hydrostatics.wall_pressure(f, o);
      vf = std::clamp(tan_delta_ / m.delta_coeff[f] * pb / std::max(1e-300, mub * mag), 0.0, 1.0);
    }
    return (1 - vf) * ut;
  }
  void momentum(const BcContext& c, int f, const Vec& Ub, double& diag, Vec& source) const override {
    wall_shear(c, f, Ub, false, alpha(c, f), diag, source);
  }

 private:
  double tan_delta_;
};

}  // namespace

std::unique_ptr<BoundaryCondition> make_coulomb_slip(const std::string&, const PatchBc& bc) { return std::make_unique<CoulombSlip>(bc); }

}  // namespace runout::engine::vof
