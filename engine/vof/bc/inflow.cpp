// inflow: prescribed velocity and phase fraction (profiles over the face centres); its flux is
// fixed from the start and its cells are always computed. Its shear as a wall's with the inflow's
// velocity and phase fraction.
#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/error.hpp"

namespace runout::engine::vof {

namespace {

class Inflow final : public BoundaryCondition {
 public:
  explicit Inflow(const PatchBc& bc) : velocity_(bc.inflow_velocity), alpha_(bc.inflow_alpha) {}
  double alpha(const BcContext& c, int f) const override { return alpha_(c.mesh.Cf[f]); }
  Vec velocity(const BcContext& c, int f) const override { return velocity_(c.mesh.Cf[f]); }
  void momentum(const BcContext& c, int f, const Vec& Ub, double& diag, Vec& source) const override {
    wall_shear(c, f, Ub, c.wall_viscosity == WallViscosity::face, alpha(c, f), diag, source);
  }
  double predicted_flux(const BcContext& c, int f, const Vec&, bool) const override { return *fixed_flux(c, f); }
  std::optional<double> fixed_flux(const BcContext& c, int f) const override { return dot(velocity_(c.mesh.Cf[f]), c.mesh.Sf[f]); }
  bool seeds_active_region() const override { return true; }

 private:
  std::function<Vec(const Vec&)> velocity_;
  std::function<double(const Vec&)> alpha_;
};

}  // namespace

std::unique_ptr<BoundaryCondition> make_inflow(const std::string& patch, const PatchBc& bc) {
  if (!bc.inflow_velocity || !bc.inflow_alpha)
    throw VofError("boundary conditions: inflow patch '" + patch + "' needs a velocity and a phase-fraction profile");
  return std::make_unique<Inflow>(bc);
}

}  // namespace runout::engine::vof
