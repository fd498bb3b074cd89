#include "engine/vof/pressure_eqn.hpp"

#include <algorithm>

#include "engine/vof/fv/grad.hpp"
#include "engine/vof/fv/parallel.hpp"

namespace runout::engine::vof {

PressureEqn::PressureEqn(const Mesh& m, const VofConfig& cfg, const BcContext& bc_ctx, const Boundaries& bcs, const ActiveRegion& region,
                         const Reconstruction& reconstruct, PressureSolver& solver)
    : m_(m), cfg_(cfg), bc_ctx_(bc_ctx), bcs_(bcs), region_(region), reconstruct_(reconstruct), solver_(solver) {
  const auto nc = std::size_t(m.cells()), nf = std::size_t(m.faces());
  pEqn_.resize(m.cells(), m.faces());
  phiHbyA_.assign(nf, 0);
  phig_ = phiHbyA_;
  pout_ = phiHbyA_;
  pcorr_ = phiHbyA_;
  w_ = phiHbyA_;
  grad_.assign(nc, Vec{});
  p_now_.assign(nc, 0.0);
  open_.assign(nf, 0);
  rec_.assign(nc, Vec{});
  rec_old_ = rec_;
}

void PressureEqn::make_system() {
  const auto nz = region_.pressure_nonzeros();
  solver_.make_system(region_.n_own_active, region_.row_offset, region_.n_active_total, nz.own, nz.off);
}

int PressureEqn::correct(Fields& F, const MomentumEqn& UEqn, CorrectorPass pass, double t) {
  solver_.set_tolerance(pass.final);
  const bool closed = !bcs_.has_opening() && region_.whole_mesh();  // no opening anywhere: the level is free
  // The consistent coupling (VofConfig::consistent): the pressure equation and the correction take
  // 1/(A - H1); the part of the last pressure's force that 1/A would have carried, (1/A -
  // 1/(A - H1)) F_old, stays in the predicted flux and velocity (SIMPLEC).
  const bool cons = cfg_.consistent && !pass.initial;
  const Coupling k{cons, cons ? UEqn.rAtUf : UEqn.rAUf, UEqn};
  // Within a step 1/A, the density and the active region do not change (reuse), and with them
  // neither which faces are openings, the Laplacian coefficients, the buoyancy fluxes nor the
  // outside pressures: those are set by the step's first call. Every call forms the predicted flux
  // from the correctors' H/A.
  const int n_non_orth = std::max(0, cfg_.n_non_orthogonal_correctors);
  if (!pass.reuse) {
    laplacian_coefficients(F, k);
  }
  // The non-orthogonal correctors solve again with the correction from the latest pressure, the
  // matrix kept; the flux takes the last correction (interFoam's nNonOrthogonalCorrectors loop).
  int its = 0;
  for (int non_orth = 0; non_orth <= n_non_orth; ++non_orth) {
    if (n_non_orth > 0) pressure_correction(F, k);
    predicted_flux(UEqn, pass.initial, k);
    const bool reuse = pass.reuse || non_orth > 0;
    assemble(F, reuse);
    const double diag0 = diag_rows_.empty() ? 0.0 : diag_rows_[0];
    its += solver_.solve({.initial = pass.initial, .reuse = reuse, .closed = closed, .diag0 = diag0}, t);
    solver_.solution(x_rows_);
    for (int r = 0; r < region_.n_own_active; ++r) F.p_rgh[region_.cells[r]] = x_rows_[r];
    region_.ranks().sync(F.p_rgh);
  }
  correct_flux_and_velocity(F, UEqn, pass.initial, k);
  for (int c : region_.cells) F.p[c] = F.p_rgh[c] + F.rho[c] * bc_ctx_.hydrostatics.gh(c);
  if (closed) fix_level(F);
  return its;
}

void PressureEqn::laplacian_coefficients(const Fields& F, const Coupling& k) {
  const Hydrostatics& hs = bc_ctx_.hydrostatics;
  auto& coef = pEqn_.upper;
  for (int f : region_.faces) {
    phig_[f] = coef[f] = pout_[f] = 0;
    open_[f] = 0;
    const int o = m_.owner[f];
    const bool ao = region_.active(o);
    if (internal(m_, f)) {
      const int nb = m_.neighbour[f];
      const bool an = region_.active(nb);
      if (ao && an) {
        phig_[f] = -hs.ghf(f) * (F.rho[nb] - F.rho[o]) * m_.delta_coeff[f] * m_.magSf[f] * k.rAf[f];
        coef[f] = k.rAf[f] * m_.magSf[f] * m_.delta_coeff[f];
      } else if (ao || an) {
        const int a = ao ? o : nb;
        open_[f] = ao ? 1 : -1;
        coef[f] = k.U.rA_along(k.consistent, a, m_.Sf[f]) * m_.magSf[f] * m_.delta_coeff[f];
        pout_[f] = hs.outside_p_rgh(f, a);
      }
    } else if (ao && bcs_[f].opening_at(f)) {
      open_[f] = 1;
      coef[f] = k.rAf[f] * m_.magSf[f] * m_.delta_coeff[f];
      pout_[f] = hs.outside_p_rgh(f, o);
    }
  }
}

// phiHbyA = flux(H/A) + phig; under the consistent coupling plus (1/A - 1/(A - H1)) F_old |Sf|,
// with F_old's reconstruction kept in rec_old_.
void PressureEqn::predicted_flux(const MomentumEqn& UEqn, bool initial, const Coupling& k) {
  const Hydrostatics& hs = bc_ctx_.hydrostatics;
  const auto& HbyA = UEqn.HbyA;
  const auto &rAUf = UEqn.rAUf, &rAtUf = UEqn.rAtUf;
  const bool non_orth = cfg_.n_non_orthogonal_correctors > 0;
  // Per face: the predicted flux, and (consistent coupling) the face force that its active cells'
  // F_old gathers (w_; 0 where it gives none).
  parallel_each(region_.faces, [&](int f) {
    const int o = m_.owner[f];
    const signed char op = open_[f];
    double ph = 0, w = 0;
    if (internal(m_, f)) {
      const int nb = m_.neighbour[f];
      if (op == 0) {  // both cells active (an active face that is no opening)
        ph = initial ? 0.0 : dot(interpolate(m_, f, HbyA), m_.Sf[f]);
        if (k.consistent) {
          const double Fold = hs.face_force(f);
          ph += (rAUf[f] - rAtUf[f]) * Fold * m_.magSf[f];
          w = Fold;
        }
      } else {
        const int a = op > 0 ? o : nb;
        ph = initial ? 0.0 : dot(HbyA[a], m_.Sf[f]);
        if (k.consistent) {
          const double sg = op;
          const double Fout = hs.opening_force(f, a, pout_[f]);  // out of a
          ph += sg * (UEqn.rA_along(false, a, m_.Sf[f]) - UEqn.rA_along(true, a, m_.Sf[f])) * Fout * m_.magSf[f];
          w = sg * Fout;
        }
      }
    } else if (region_.active(o)) {
      ph = bcs_[f].predicted_flux(bc_ctx_, f, HbyA[o], initial);
      if (bcs_[f].opening_at(f) && k.consistent) {
        const double Fout = hs.opening_force(f, o, pout_[f]);
        ph += (UEqn.rA_along(false, o, m_.Sf[f]) - UEqn.rA_along(true, o, m_.Sf[f])) * Fout * m_.magSf[f];
        w = Fout;
      }
    }
    phiHbyA_[f] = ph + phig_[f];
    if (non_orth) phiHbyA_[f] += pcorr_[f];
    w_[f] = w;
  });
  if (k.consistent) gather_face_forces(rec_old_);
}

// Per active cell, the sum of w_ Sf over its faces (the faces that give it nothing hold 0).
void PressureEqn::gather_face_forces(CellField<Vec>& rec) const {
  const CellFaces& cf = region_.cell_faces();
  parallel_each(region_.cells, [&](int c) {
    Vec sum{};
    for (int f : cf[c]) sum = sum + w_[f] * m_.Sf[f];
    rec[c] = sum;
  });
}

// laplacian(rAUf, p_rgh) = div(phiHbyA), an opening's outside pressure on the right-hand side.
// Within a step the matrix does not change (1/A is built once per step): later correctors keep it
// and its preconditioner and assemble only the right-hand side; the diagonal is kept from the
// step's first call (the closed domain's pinning needs it then too).
void PressureEqn::assemble(const Fields& F, bool reuse) {
  const auto& coef = pEqn_.upper;
  auto &diag = pEqn_.diag, &rhs = pEqn_.source;
  const CellFaces& cf = region_.cell_faces();
  // Per active cell over its faces: the fluxes out of it and its share of the Laplacian.
  parallel_each(region_.cells, [&](int c) {
    double r = 0, d = reuse ? diag[c] : 0.0;
    for (int f : cf[c]) {
      const double cc = coef[f];
      if (open_[f] != 0) {  // c is the face's active cell
        r -= double(open_[f]) * phiHbyA_[f];
        if (!reuse) d += cc;
        r += cc * pout_[f];
      } else if (m_.owner[f] == c) {
        r -= phiHbyA_[f];
        if (!reuse && internal(m_, f)) d += cc;
      } else {
        r += phiHbyA_[f];
        if (!reuse) d += cc;
      }
    }
    rhs[c] = r;
    diag[c] = d;
  });
  solver_.begin_matrix(reuse);
  const auto& row = region_.global_row;
  const Ranks& ranks = region_.ranks();
  if (!reuse)
    for (int f : region_.faces)
      if (open_[f] == 0 && internal(m_, f) && region_.active(m_.owner[f])) {
        const int o = m_.owner[f], nb = m_.neighbour[f];
        if (ranks.own(o)) solver_.set_entry(row[o], row[nb], -coef[f]);
        if (ranks.own(nb)) solver_.set_entry(row[nb], row[o], -coef[f]);
      }
  const auto n = std::size_t(region_.n_own_active);
  diag_rows_.resize(n);
  rhs_rows_.resize(n);
  x_rows_.resize(n);
  parallel_for(int(n), [&](int r) {
    const int c = region_.cells[std::size_t(r)];
    diag_rows_[std::size_t(r)] = diag[c];
    rhs_rows_[std::size_t(r)] = rhs[c];
    x_rows_[std::size_t(r)] = F.p_rgh[c];
  });
  solver_.set_rows(diag_rows_, rhs_rows_, x_rows_, reuse);
}

// phi = phiHbyA + pEqn.flux(); U = H/A + rA reconstruct((phig + pEqn.flux()) / rAf) (plus the
// consistent coupling's share of F_old).
void PressureEqn::correct_flux_and_velocity(Fields& F, const MomentumEqn& UEqn, bool initial, const Coupling& k) {
  const bool non_orth = cfg_.n_non_orthogonal_correctors > 0;
  parallel_each(region_.faces, [&](int f) {
    const int o = m_.owner[f];
    const signed char op = open_[f];
    double w = 0;
    if (op != 0) {
      // An opening: the flux out of the active cell a follows its pressure and the outside's.
      const int a = op > 0 ? o : m_.neighbour[f];
      const double sg = op;
      const double pflux_out = pEqn_.flux_out(f, F.p_rgh[a], pout_[f]);
      F.phi[f] = phiHbyA_[f] + sg * pflux_out;
      const double ra = k.U.rA_along(k.consistent, a, m_.Sf[f]);
      if (ra > 0) w = pflux_out / ra / m_.magSf[f] * sg;
    } else {
      const double pflux = internal(m_, f) ? pEqn_.flux(m_, f, F.p_rgh) : 0.0;
      F.phi[f] = phiHbyA_[f] + pflux;
      if (internal(m_, f) && k.rAf[f] > 0) {
        const double corr = non_orth ? pcorr_[f] : 0.0;
        w = (phig_[f] + pflux + corr) / k.rAf[f] / m_.magSf[f];
      }
    }
    w_[f] = w;
  });
  if (initial) return;
  gather_face_forces(rec_);
  parallel_each(region_.cells, [&](int c) {
    const Vec R = reconstruct_(c, rec_[c]);
    F.U[c] = UEqn.HbyA[c] + UEqn.rA_apply(k.consistent, c, R);
    if (k.consistent) F.U[c] = F.U[c] + UEqn.rA_difference_apply(c, reconstruct_(c, rec_old_[c]));
  });
  region_.ranks().sync(F.U);
}

// The Gauss gradient of the pressure p over the active region: face values interpolated between
// active cells; on walls and openings the cell's p carried hydrostatically to the face,
// p + rho (ghf - gh) (the zero gradient of p_rgh that the walls' flux assumes: p itself has the
// weight's gradient there).
void PressureEqn::pressure_gradient(const Fields& F, const CellField<double>& p, CellField<Vec>& out) const {
  const Hydrostatics& hs = bc_ctx_.hydrostatics;
  const auto face_p = [&](int f, int c) {
    // An opening out of c, or a wall: p carried to the face.
    if (open_[f] != 0 || !internal(m_, f)) return carried_hydrostatically(p[c], F.rho[c], hs.gh(c), hs.ghf(f));
    return interpolate(m_, f, p);
  };
  grad(m_, region_.cell_faces(), region_.cells, face_p, out);
}

// The face force's non-orthogonal part from the latest pressure, -rAf (non_orth . grad(p)_f -
// rho_f non_orth . g), limited against the orthogonal part (VofConfig::non_orthogonal_limiter), on
// the faces between active cells (explicit: it goes with the predicted flux). It is the
// non-orthogonal part of -ghf snGrad(rho) - snGrad(p_rgh), taken from p, which is continuous across
// the interface, where p_rgh jumps by (rho1 - rho2) g.(x - x_ref) and its cell gradients would carry
// the jump into the neighbouring cells (docs/design/vof.md).
void PressureEqn::pressure_correction(const Fields& F, const Coupling& k) {
  const Hydrostatics& hs = bc_ctx_.hydrostatics;
  parallel_each(region_.cells, [&](int c) { p_now_[c] = F.p_rgh[c] + F.rho[c] * hs.gh(c); });
  pressure_gradient(F, p_now_, grad_);
  const Vec& g = hs.gravity();
  parallel_each(region_.faces, [&](int f) {
    pcorr_[f] = 0;
    if (open_[f] != 0 || !internal(m_, f) || !region_.active(m_.owner[f])) return;
    const Vec& kv = m_.non_orth[f];
    const double corr = -(dot(kv, interpolate(m_, f, grad_)) - interpolate(m_, f, F.rho) * dot(kv, g));
    pcorr_[f] = k.rAf[f] * limited_correction(corr, hs.orthogonal_force(f) * m_.magSf[f], cfg_.non_orthogonal_limiter);
  });
}

// A closed domain fixes the pressure only up to a constant, but the Coulomb viscosity needs the
// pressure itself: it is zero in the highest cell (along gravity), the top of the air.
// Split over ranks, the highest cell is the highest of the ranks' highest own cells (the lowest rank's
// where two are equally high).
void PressureEqn::fix_level(Fields& F) {
  const int nc = m_.cells();
  const Hydrostatics& hs = bc_ctx_.hydrostatics;
  const Ranks& ranks = region_.ranks();
  int top = 0;
  for (int c = 1; c < ranks.owned(nc); ++c)
    if (hs.gh(c) < hs.gh(top)) top = c;
  double pmin = F.p[top];
  if (ranks.distributed()) {
    struct {
      double gh;
      int rank;
    } mine{hs.gh(top), ranks.comm().rank}, best{};
    MPI_Allreduce(&mine, &best, 1, MPI_DOUBLE_INT, MPI_MINLOC, ranks.comm().comm);
    MPI_Bcast(&pmin, 1, MPI_DOUBLE, best.rank, ranks.comm().comm);
  }
  for (int c = 0; c < nc; ++c) {
    F.p[c] -= pmin;
    F.p_rgh[c] -= pmin;
  }
  solver_.shift(-pmin);
}

}  // namespace runout::engine::vof
