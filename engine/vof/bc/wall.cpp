// wall: a stick wall. No flow through it, no slip along it; its shear from the viscosity on the
// face or the cell's (VofConfig::wall_viscosity).
#include "engine/vof/bc/boundary.hpp"

namespace runout::engine::vof {

namespace {

class Wall final : public BoundaryCondition {
 public:
  Vec velocity(const BcContext&, int) const override { return {}; }
  void momentum(const BcContext& c, int f, const Vec& Ub, double& diag, Vec& source) const override {
    wall_shear(c, f, Ub, c.wall_viscosity == WallViscosity::face, alpha(c, f), diag, source);
  }
};

}  // namespace

std::unique_ptr<BoundaryCondition> make_wall(const std::string&, const PatchBc&) { return std::make_unique<Wall>(); }

}  // namespace runout::engine::vof
