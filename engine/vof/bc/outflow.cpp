// outflow: zero gradient; the flux follows the cell's H/A and the pressure correction; no shear.
#include "engine/vof/bc/boundary.hpp"

namespace runout::engine::vof {

namespace {

class Outflow final : public BoundaryCondition {
 public:
  Vec velocity(const BcContext& c, int f) const override { return c.fields.U[c.mesh.owner[f]]; }
  double predicted_flux(const BcContext& c, int f, const Vec& HbyA_o, bool initial) const override {
    return initial ? 0.0 : dot(HbyA_o, c.mesh.Sf[f]);
  }
};

}  // namespace

std::unique_ptr<BoundaryCondition> make_outflow(const std::string&, const PatchBc&) { return std::make_unique<Outflow>(); }

}  // namespace runout::engine::vof
