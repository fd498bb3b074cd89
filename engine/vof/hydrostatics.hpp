#pragma once
// Gravity and the still air: g.x per cell and face (gravity may depend on time), the reference
// level x_ref (the highest point open to the atmosphere), the still air's pressure outside the
// domain's openings and the active region, the pressure on a wall face, the confining pressure of
// the Coulomb viscosity, and the last pressure's and the buoyancy's force per area on a face.
#include <cmath>
#include <functional>
#include <vector>

#include "engine/vof/config.hpp"
#include "engine/vof/fields.hpp"
#include "engine/vof/mpi/ranks.hpp"
#include "engine/vof/fv/ops.hpp"

namespace runout::engine::vof {

/// A face gradient's non-orthogonal correction limited as OpenFOAM's "limited corrected psi": at
/// most psi / (1 - psi) times the orthogonal part (psi >= 1: unlimited; 0: no correction).
inline double limited_correction(double corr, double orth, double psi) {
  if (psi >= 1) return corr;
  const double lim = psi / (1 - psi) * std::abs(orth);
  return std::abs(corr) > lim ? corr * (lim / std::abs(corr)) : corr;
}

class Hydrostatics {
 public:
  /// ranks: the run's ranks (the reference level is the whole mesh's).
  Hydrostatics(const Mesh& m, const VofConfig& cfg, const Fields& fields, const Ranks& ranks);
  void resize();

  /// Gravity at time t: g.x per cell and face and the reference level, recomputed when g changed
  /// (`opening(f)`: boundary face f is open to the atmosphere). force: recompute in any case.
  void update(double t, const std::function<bool(int)>& opening, bool force = false);
  /// No gravity (the initial potential flow): g.x zero everywhere.
  void zero();

  double gh(int c) const { return gh_[c]; }
  double ghf(int f) const { return ghf_[f]; }
  const CellField<double>& gh() const { return gh_; }

  // Outside the domain's openings, and outside the active region, is air at rest: hydrostatic,
  // p = rho_air g.(x - x_ref), zero at the highest point open to the atmosphere (x_ref). On an
  // opening next to active cell a, p_rgh_b = p_b - rho_a g.x_b. (Taking p = 0 all along a vertical
  // opening instead drives air through it: the air inside is hydrostatic, and the 1.5 Pa across a
  // 15 cm opening set up a circulation that grew to 5 m/s while the material rested.)
  double still_air_p(double g_dot_x) const { return rho2_ * (g_dot_x - gh_ref_); }
  double outside_p_rgh(int f, int a) const {
    const double g = ghf_[f];
    return still_air_p(g) - fields_.rho[a] * g;
  }
  // What the Coulomb viscosity and the Coulomb bed conditions subtract from p at a point with
  // g.x = g_dot_x (VofConfig::coulomb_pressure): nothing, or the still air's pressure there.
  double coulomb_level(double g_dot_x) const { return excess_ ? still_air_p(g_dot_x) : 0.0; }
  // The pressure on a wall face, as OpenFOAM's p.boundaryField() under the buoyantPressure
  // condition (p_rgh the cell's, the density the cell's, gh the face's): the bed pressure the
  // Coulomb conditions need (listing B.2), not the cell centre's, which in a flow one or two cells
  // deep is half of it or less; less coulomb_level(). Written as the cell's pressure p (from the
  // last pressure solve) carried hydrostatically to the face, p_P + rho_P (gh_f - gh_P): the same
  // as p_rgh_P + rho_P gh_f while the density is the one p was formed with, and independent of the
  // mesh's origin when it is not (at the start of a step the density is already the new one; the
  // form p_rgh_P + rho_P gh_f then added (rho_new - rho_old) g.x_f: estimated 1.4 kPa for a PVC
  // cell filling by 0.1 in a step 2 m from the origin of a 50 deg chute, where the bed pressure is
  // about 100 Pa).
  double wall_pressure(int f, int o) const {
    return carried_hydrostatically(fields_.p[o], fields_.rho[o], gh_[o], ghf_[f]) - coulomb_level(ghf_[f]);
  }
  // The confining pressure of the Coulomb viscosity in cell c: p less coulomb_level().
  double confining_pressure(int c) const { return fields_.p[c] - coulomb_level(gh_[c]); }
  // The last pressure's and the buoyancy's force per area on an internal face, along Sf:
  // -ghf snGrad(rho) - snGrad(p_rgh) (the momentum predictor's and the consistent coupling's F_old).
  // With VofConfig::n_non_orthogonal_correctors > 0 the face gradients' non-orthogonal parts are
  // added (update_non_orthogonal_force, from the fields of its last call).
  /// Gravity at the time of the last update().
  const Vec& gravity() const { return g_last_; }
  double face_force(int f) const {
    const double orth = orthogonal_force(f);
    return non_orth_ ? orth + non_orth_force_[f] : orth;
  }
  // face_force's orthogonal part: from the two cells' values along the line joining them.
  double orthogonal_force(int f) const {
    const int o = m_.owner[f], nb = m_.neighbour[f];
    const double dl = m_.delta_coeff[f];
    return -ghf_[f] * (fields_.rho[nb] - fields_.rho[o]) * dl - (fields_.p_rgh[nb] - fields_.p_rgh[o]) * dl;
  }
  /// face_force's non-orthogonal part, -(Mesh::non_orth . grad(p)_f - rho_f Mesh::non_orth . g) /
  /// |Sf|, from the cells' Gauss gradient of the current pressure p (on boundary faces the cell's p
  /// carried hydrostatically to the face), limited by VofConfig::non_orthogonal_limiter against the
  /// orthogonal part. The same as the non-orthogonal parts of -ghf snGrad(rho) - snGrad(p_rgh), but
  /// from p, which is continuous across the interface where p_rgh jumps by (rho1 - rho2)
  /// g.(x - x_ref) (docs/design/vof.md).
  /// On the listed faces (internal ones; the others skipped), from the gradient in `cells`, which
  /// must hold both sides of every listed face (the active region's faces and halo). Nothing
  /// without non-orthogonal correctors.
  void update_non_orthogonal_force(const CellFaces& cell_faces, const std::vector<int>& faces, const std::vector<int>& cells);
  // The same on an opening (atmosphere, edge of the active region), out of the active cell a, with
  // the outside's p_rgh pout.
  double opening_force(int f, int a, double pout) const { return -(pout - fields_.p_rgh[a]) * m_.delta_coeff[f]; }

 private:
  const Mesh& m_;
  const Fields& fields_;
  const Ranks& ranks_;
  std::function<Vec(double)> gravity_;
  double rho2_;
  bool excess_;
  CellField<double> gh_;
  FaceField<double> ghf_;
  double gh_ref_ = 0;
  bool non_orth_ = false;
  double limiter_ = 1;  // VofConfig::non_orthogonal_limiter
  FaceField<double> non_orth_force_;
  CellField<Vec> grad_p_;
  Vec g_last_;
  bool gravity_set_ = false;
};

}  // namespace runout::engine::vof
