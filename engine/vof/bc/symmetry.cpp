// symmetry: a plane of symmetry (a frictionless wall): no flow through it (its normal velocity is
// held by the flux) and no shear along it.
#include "engine/vof/bc/boundary.hpp"

namespace runout::engine::vof {

namespace {

class Symmetry final : public BoundaryCondition {
 public:
  Vec velocity(const BcContext& c, int f) const override {
    const Vec Up = c.fields.U[c.mesh.owner[f]];
    const Vec n = unit_normal(c.mesh, f);
    return Up - dot(Up, n) * n;
  }
};

}  // namespace

std::unique_ptr<BoundaryCondition> make_symmetry(const std::string&, const PatchBc&) { return std::make_unique<Symmetry>(); }

}  // namespace runout::engine::vof
