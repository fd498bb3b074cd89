#include "engine/vof/bc/boundary.hpp"

#include "engine/vof/error.hpp"

namespace runout::engine::vof {

void BoundaryCondition::momentum(const BcContext&, int, const Vec&, double&, Vec&) const {}

double BoundaryCondition::predicted_flux(const BcContext&, int, const Vec&, bool) const { return 0.0; }

double boundary_mu(const BcContext& c, int f, const Vec& Ub, double alpha_b) {
  const Mesh& m = c.mesh;
  const int o = m.owner[f];
  const Vec n = unit_normal(m, f);
  const Vec sn = m.delta_coeff[f] * (Ub - c.fields.U[o]);
  Tensor gb = c.fields.gradU[o];
  auto& g = gb.g;
  for (int j = 0; j < 3; ++j) {
    double nG = 0;
    for (int i = 0; i < 3; ++i) nG += comp(n, i) * g[i][j];
    for (int i = 0; i < 3; ++i) g[i][j] += comp(n, i) * (comp(sn, j) - nG);
  }
  const double nu1 = c.viscosity.nu(c.hydrostatics.wall_pressure(f, o), strain_rate(gb));
  return c.mixture.mu(alpha_b, nu1);
}

void wall_shear(const BcContext& c, int f, const Vec& Ub, bool face_viscosity, double alpha_b, double& diag, Vec& source) {
  const Mesh& m = c.mesh;
  const int o = m.owner[f];
  const double D = (face_viscosity ? boundary_mu(c, f, Ub, alpha_b) : c.fields.mu[o]) * m.magSf[f] * m.delta_coeff[f];
  diag += D;
  source = source + D * Ub;
}

}  // namespace runout::engine::vof

namespace runout::engine::vof {

Boundaries::Boundaries(const Mesh& m, const std::map<std::string, PatchBc>& bc) : n_internal_(m.n_internal) {
  face_.resize(std::size_t(m.faces() - m.n_internal));
  for (const auto& p : m.patches) {
    const auto it = bc.find(p.name);
    if (it == bc.end()) throw VofError("boundary conditions: patch '" + p.name + "' has none");
    conditions_.push_back(make_boundary_condition(p.name, it->second));
    if (conditions_.back()->opening()) has_opening_ = true;
    for (int f = p.start; f < p.start + p.size; ++f) face_[f - m.n_internal] = conditions_.back().get();
  }
  for (const auto& [name, _] : bc)
    if (m.patch_index(name) < 0) throw VofError("boundary conditions: the mesh has no patch '" + name + "'");
}

}  // namespace runout::engine::vof
