// coulomb_friction: the bed's Coulomb friction as a force, tan(delta) p |Sf| against the sliding
// velocity, implicit in the velocity: a drag of tan(delta) p |Sf| / |u_t| (at most the creep
// speed's), so that the force's magnitude is the friction while the material slides and material
// held by less comes to rest. Material slides along it (no flow through it); air sticks, with a
// wall's shear.
#include <algorithm>

#include "engine/vof/bc/boundary.hpp"

namespace runout::engine::vof {

namespace {

class CoulombFriction final : public BoundaryCondition {
 public:
  explicit CoulombFriction(const PatchBc& bc)
      : tan_delta_(bc.tan_delta),
        creep_speed_(bc.friction_creep_speed),
        min_alpha_(bc.friction_min_alpha),
        total_normal_(bc.friction_total_normal_stress) {}
  Vec velocity(const BcContext& c, int f) const override {
    const int o = c.mesh.owner[f];
    const Vec Up = c.fields.U[o];
    const Vec n = unit_normal(c.mesh, f);
    return c.fields.alpha[o] >= min_alpha_ ? Up - dot(Up, n) * n : Vec{};
  }
  void momentum(const BcContext& c, int f, const Vec& Ub, double& diag, Vec& source) const override {
    const Mesh& m = c.mesh;
    const int o = m.owner[f];
    if (c.fields.alpha[o] < min_alpha_) {
      wall_shear(c, f, Ub, c.wall_viscosity == WallViscosity::face, alpha(c, f), diag, source);
      return;
    }
    const Vec n = unit_normal(m, f);
    const Vec U = c.fields.U[o];
    const Vec ut = U - dot(U, n) * n;
    double load = c.hydrostatics.wall_pressure(f, o);
    if (total_normal_) {  // less the viscous normal stress 2 mu n.grad(U).n (compression raises the load)
      const auto& g = c.fields.gradU[o].g;
      const double nn[3] = {n.x, n.y, n.z};
      double enn = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) enn += nn[i] * g[i][j] * nn[j];
      load -= 2 * c.fields.mu[o] * enn;
    }
    const double drag = tan_delta_ * std::max(load, 0.0) * m.magSf[f] / std::max(norm(ut), creep_speed_);
    // The drag sits on the diagonal, which both components share; the part it would put on the
    // velocity normal to the bed is given back explicitly, so that it acts along the bed.
    diag += drag;
    source = source + (drag * dot(U, n)) * n;
  }

 private:
  double tan_delta_, creep_speed_, min_alpha_;
  bool total_normal_;
};

}  // namespace

std::unique_ptr<BoundaryCondition> make_coulomb_friction(const std::string&, const PatchBc& bc) {
  return std::make_unique<CoulombFriction>(bc);
}

}  // namespace runout::engine::vof
