// The momentum predictor: the momentum matrix solved with the last pressure's and the buoyancy's
// force, so that the viscous coupling (the Coulomb viscosity reaches 1e2 m2/s) is converged every
// step.
#include "engine/vof/momentum_eqn.hpp"

namespace runout::engine::vof {

// The force per cell, V reconstruct(-ghf snGrad(rho) - snGrad(p_rgh)) |Sf|, over the active region
// (force_ holds the sum of the face forces times Sf); a face to the air at rest outside the region
// is an opening with the outside's pressure, as in the pressure equation. Walls and inflows: the
// pressure gradient normal to them is balanced (fixed flux).
void MomentumEqn::predictor_forces() {
  const Hydrostatics& hs = bc_ctx_.hydrostatics;
  auto& rec = force_;
  for (int c : region_.cells) rec[c] = Vec{};
  for (int f : region_.faces) {
    const int o = m_.owner[f];
    const bool ao = region_.active(o);
    double q = 0;  // force per area, normal to the face (along Sf)
    if (internal(m_, f)) {
      const int nb = m_.neighbour[f];
      const bool an = region_.active(nb);
      if (ao && an) {
        q = hs.face_force(f);
        rec[o] = rec[o] + q * m_.Sf[f];
        rec[nb] = rec[nb] + q * m_.Sf[f];
      } else {
        const int c = ao ? o : nb;
        const double sg = ao ? 1 : -1;  // Sf out of c
        q = hs.opening_force(f, c, hs.outside_p_rgh(f, c));  // out of c
        rec[c] = rec[c] + (sg * q) * m_.Sf[f];
      }
    } else if (ao && bcs_[f].opening()) {
      q = hs.opening_force(f, o, hs.outside_p_rgh(f, o));
      rec[o] = rec[o] + q * m_.Sf[f];
    }
  }
}

// The matrix over every cell, cells outside the active region (or not predicted) as rows of the
// identity with their velocity (zero for the air at rest outside the region). Every face's entries
// are set, zero where they are not used, so that the matrix keeps the whole mesh's nonzero
// structure from one assembly to the next. Under the consistent coupling only the material's cells
// (alpha >= consistent_alpha) are predicted; the air around them keeps its velocity (the cells'
// coefficients to it go to the right-hand side), as under PISO. Predicting the air too let the
// cell-reconstructed buoyancy force drive air currents over a resting heap's stair-stepped surface
// (0.1 m/s) that dragged it along at 2 mm/s (docs/design/vof.md).
int MomentumEqn::predict(Fields& F, double t) {
  predictor_forces();
  const int nc = m_.cells();
  const bool material_only = cfg_.consistent;
  auto solved = [&](int c) { return region_.active(c) && (!material_only || F.alpha[c] >= cfg_.consistent_alpha); };
  const auto& cO = UEqn_.upper;
  const auto& cN = UEqn_.lower;
  known_.assign(nc, Vec{});
  solver_.begin();
  for (int f = 0; f < m_.n_internal; ++f) {
    const int o = m_.owner[f], nb = m_.neighbour[f];
    const bool so = solved(o), sn = solved(nb);
    const bool both = so && sn;
    solver_.set(o, nb, both ? -cO[f] : 0.0);
    solver_.set(nb, o, both ? -cN[f] : 0.0);
    if (so && !sn && region_.active(nb)) known_[o] = known_[o] + cO[f] * F.U[nb];
    if (sn && !so && region_.active(o)) known_[nb] = known_[nb] + cN[f] * F.U[o];
  }
  for (int c = 0; c < nc; ++c) solver_.set(c, c, solved(c) ? UEqn_.diag[c] : 1.0);
  solver_.assemble();
  int its_total = 0;
  auto b = std::vector<double>(nc), x = b;
  for (int i = 0; i < dims_; ++i) {
    for (int c = 0; c < nc; ++c) {
      double src = 0, x0 = 0;
      if (solved(c)) {
        const Vec Fc = reconstruct_(c, force_[c]);
        src = comp(UEqn_.source[c], i) + m_.volume[c] * comp(Fc, i) + comp(known_[c], i);
        x0 = comp(F.U[c], i);
      } else if (region_.active(c)) {
        src = x0 = comp(F.U[c], i);
      }
      b[c] = src;
      x[c] = x0;
    }
    its_total += solver_.solve(b, x, t);
    for (int c : region_.cells) comp_ref(F.U[c], i) = x[c];
  }
  return its_total;
}

}  // namespace runout::engine::vof
