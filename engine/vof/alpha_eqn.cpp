#include "engine/vof/alpha_eqn.hpp"

#include <algorithm>
#include <cmath>

namespace runout::engine::vof {

AlphaEqn::AlphaEqn(const Mesh& m, const VofConfig& cfg, const BcContext& bc_ctx, const Boundaries& bcs, const ActiveRegion& region,
                   double mean_cell_size)
    : m_(m), cfg_(cfg), bc_ctx_(bc_ctx), bcs_(bcs), region_(region), delta_n_(1e-8 / mean_cell_size) {
  const auto nc = std::size_t(m.cells()), nf = std::size_t(m.faces());
  FL_.assign(nf, 0);
  AF_ = FL_;
  for (auto* v : {&amax_, &amin_, &Pp_, &Pm_, &Rp_, &Rm_, &aL_}) v->assign(nc, 0);
  grad_alpha_.assign(nc, Vec{});
}

// Only faces of the active region carry flux; alpha changes only in its cells and their
// neighbours (the halo).
void AlphaEqn::solve(Fields& F, double dt) {
  const int n = std::max(1, cfg_.alpha_subcycles);
  const double dts = dt / n;
  for (int f : region_.faces) F.alpha_phi[f] = 0;
  for (int sub = 0; sub < n; ++sub) {
    interface_normal(F);
    fluxes_and_bounds(F);
    limit_and_update(F, dts, n);
  }
  for (int f : region_.faces) F.rho_phi[f] = bc_ctx_.mixture.rho_flux(F.alpha_phi[f], F.phi[f]);
}

// The interface normal per cell: the Gauss gradient of alpha.
void AlphaEqn::interface_normal(const Fields& F) {
  auto& ga = grad_alpha_;
  for (int c : region_.halo) ga[c] = Vec{};
  for (int f : region_.faces) {
    const int o = m_.owner[f];
    const double af = internal(m_, f) ? interpolate(m_, f, F.alpha) : bcs_[f].alpha(bc_ctx_, f);
    ga[o] = ga[o] + af * m_.Sf[f];
    if (internal(m_, f)) ga[m_.neighbour[f]] = ga[m_.neighbour[f]] - af * m_.Sf[f];
  }
  for (int c : region_.halo) ga[c] = (1.0 / m_.volume[c]) * ga[c];
}

// Per face the upwind flux FL and the antidiffusive flux AF (central value plus compression, less
// upwind); per cell the bounds of alpha among its neighbours (and what flows in from outside).
void AlphaEqn::fluxes_and_bounds(const Fields& F) {
  const auto& a = F.alpha;
  const auto& ga = grad_alpha_;
  for (int c : region_.halo) amax_[c] = amin_[c] = a[c];
  for (int f : region_.faces) {
    const int o = m_.owner[f];
    const double ph = F.phi[f];
    if (internal(m_, f)) {
      const int nb = m_.neighbour[f];
      const double ao = a[o], an = a[nb];
      FL_[f] = ph * (ph >= 0 ? ao : an);
      // Central value and compression flux.
      const double w = m_.weight[f];
      const double ac = w * ao + (1 - w) * an;
      Vec gf = w * ga[o] + (1 - w) * ga[nb];
      // Unit interface normal; deltaN = 1e-8 / (mean cell size) only keeps the division finite.
      const double nS = dot(gf, m_.Sf[f]) / (norm(gf) + delta_n_);
      const double phir = cfg_.c_alpha * std::abs(ph) / m_.magSf[f] * nS;
      const double a_up = phir >= 0 ? ao : an, b_up = phir >= 0 ? 1 - an : 1 - ao;
      const double FH = ph * ac + phir * a_up * b_up;
      AF_[f] = FH - FL_[f];
      amax_[o] = std::max(amax_[o], an);
      amin_[o] = std::min(amin_[o], an);
      amax_[nb] = std::max(amax_[nb], ao);
      amin_[nb] = std::min(amin_[nb], ao);
    } else {
      const double ab = ph >= 0 ? a[o] : bcs_[f].alpha(bc_ctx_, f);
      FL_[f] = ph * ab;
      AF_[f] = 0;
      if (ph < 0) {
        amax_[o] = std::max(amax_[o], ab);
        amin_[o] = std::min(amin_[o], ab);
      }
    }
  }
}

// Zalesak's limiter: the low-order update, the antidiffusive fluxes into (Pp) and out of (Pm) each
// cell, the fractions Rp, Rm of them the cell's bounds allow, and the update with each face's
// antidiffusive flux scaled by the smaller fraction of its two cells.
void AlphaEqn::limit_and_update(Fields& F, double dts, int subcycles) {
  auto& a = F.alpha;
  for (int c : region_.halo) {
    aL_[c] = a[c] * m_.volume[c];
    Pp_[c] = Pm_[c] = 0;
  }
  for (int f : region_.faces) {
    const int o = m_.owner[f];
    aL_[o] -= dts * FL_[f];
    if (internal(m_, f)) {
      const int nb = m_.neighbour[f];
      aL_[nb] += dts * FL_[f];
      const double A = AF_[f];
      // A > 0 takes from the owner, gives to the neighbour.
      if (A > 0) {
        Pm_[o] += A;
        Pp_[nb] += A;
      } else {
        Pp_[o] -= A;
        Pm_[nb] -= A;
      }
    }
  }
  for (int c : region_.halo) {
    const double V = m_.volume[c];
    const double lo = aL_[c] / V;
    const double up = std::clamp(amax_[c], 0.0, 1.0), dn = std::clamp(amin_[c], 0.0, 1.0);
    const double Qp = std::max(0.0, (up - lo) * V / dts), Qm = std::max(0.0, (lo - dn) * V / dts);
    Rp_[c] = Pp_[c] > 0 ? std::min(1.0, Qp / Pp_[c]) : 1.0;
    Rm_[c] = Pm_[c] > 0 ? std::min(1.0, Qm / Pm_[c]) : 1.0;
  }
  for (int f : region_.faces) {
    double Fl = FL_[f];
    if (internal(m_, f)) {
      const int o = m_.owner[f], nb = m_.neighbour[f];
      const double A = AF_[f];
      const double lam = A > 0 ? std::min(Rm_[o], Rp_[nb]) : std::min(Rp_[o], Rm_[nb]);
      Fl += lam * A;
      const double dA = lam * A * dts;
      aL_[o] -= dA;
      aL_[nb] += dA;
    }
    F.alpha_phi[f] += Fl / subcycles;
  }
  for (int c : region_.halo) a[c] = aL_[c] / m_.volume[c];
}

}  // namespace runout::engine::vof
