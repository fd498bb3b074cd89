// atmosphere: open to the air at rest outside (total pressure of the still air). Air flows in with
// the flux's normal velocity and no material, anything flows out with the cell's velocity
// (pressureInletOutletVelocity); no shear.
#include "engine/vof/bc/boundary.hpp"

namespace runout::engine::vof {

namespace {

class Atmosphere final : public BoundaryCondition {
 public:
  double alpha(const BcContext& c, int f) const override { return c.fields.phi[f] < 0 ? 0.0 : c.fields.alpha[c.mesh.owner[f]]; }
  Vec velocity(const BcContext& c, int f) const override {
    const Mesh& m = c.mesh;
    const Vec Up = c.fields.U[m.owner[f]];
    const Vec n = unit_normal(m, f);
    const double ph = c.fields.phi[f];
    return ph >= 0 ? Up : (ph / m.magSf[f]) * n;
  }
  double predicted_flux(const BcContext& c, int f, const Vec& HbyA_o, bool initial) const override {
    return initial ? 0.0 : dot(HbyA_o, c.mesh.Sf[f]);
  }
  bool opening() const override { return true; }
};

}  // namespace

std::unique_ptr<BoundaryCondition> make_atmosphere(const std::string&, const PatchBc&) { return std::make_unique<Atmosphere>(); }

}  // namespace runout::engine::vof
