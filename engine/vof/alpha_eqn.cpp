#include "engine/vof/alpha_eqn.hpp"

#include <algorithm>
#include <cmath>

#include "engine/vof/fv/grad.hpp"
#include "engine/vof/fv/parallel.hpp"

namespace runout::engine::vof {

AlphaEqn::AlphaEqn(const Mesh& m, const VofConfig& cfg, const BcContext& bc_ctx, const Boundaries& bcs, const ActiveRegion& region,
                   double mean_cell_size)
    : m_(m), cfg_(cfg), bc_ctx_(bc_ctx), bcs_(bcs), region_(region), delta_n_(1e-8 / mean_cell_size) {
  const auto nc = std::size_t(m.cells()), nf = std::size_t(m.faces());
  FL_.assign(nf, 0);
  AF_ = FL_;
  for (auto* v : {&amax_, &amin_, &Rp_, &Rm_, &aL_}) v->assign(nc, 0);
  grad_alpha_.assign(nc, Vec{});
}

// Only faces of the active region carry flux; alpha changes only in its cells and their
// neighbours (the halo).
void AlphaEqn::solve(Fields& F, double dt, const Vec& gravity) {
  const int n = std::max(std::max(1, cfg_.alpha_subcycles), settling_subcycles(gravity, dt));
  const double dts = dt / n;
  parallel_each(region_.faces, [&](int f) { F.alpha_phi[f] = 0; });
  for (int sub = 0; sub < n; ++sub) {
    interface_normal(F);
    fluxes_and_bounds(F);
    if (cfg_.settling_speed > 0) settling_fluxes(F);
    limit_and_update(F, dts, n);
  }
  parallel_each(region_.faces, [&](int f) { F.rho_phi[f] = bc_ctx_.mixture.rho_flux(F.alpha_phi[f], F.phi[f]); });
}

// Gravity's direction for this solve, and the settling flux's sub-cycles that keep its Courant number
// w |g.Sf| dts / V of the smaller cell at most 0.5 (the flux alone keeps alpha in [0, 1] up to 1).
int AlphaEqn::settling_subcycles(const Vec& gravity, double dt) {
  down_ = Vec{};
  const double gn = norm(gravity);
  if (cfg_.settling_speed <= 0 || gn <= 0) return 1;
  down_ = (1.0 / gn) * gravity;
  double co = 0;
  for (int f : region_.faces) {
    if (!internal(m_, f)) continue;
    const double v = std::min(m_.volume[m_.owner[f]], m_.volume[m_.neighbour[f]]);
    co = std::max(co, std::abs(cfg_.settling_speed * dot(down_, m_.Sf[f])) * dt / v);
  }
  co = region_.ranks().comm().max(co);
  return int(std::ceil(co / 0.5));
}

// The settling flux added to the low-order flux: material falls from the upper cell into the lower
// one as w alpha_upper (1 - alpha_lower) (Kynch's flux: monotone, zero once the lower cell is full or
// the upper one empty), so that a column's material gathers at its bottom and a full body is
// untouched; the mixture's volume flux phi is not changed (the air rises as the material falls).
void AlphaEqn::settling_fluxes(const Fields& F) {
  const auto& a = F.alpha;
  parallel_each(region_.faces, [&](int f) {
    if (!internal(m_, f)) return;
    const double s = cfg_.settling_speed * dot(down_, m_.Sf[f]);
    const double ao = std::clamp(a[m_.owner[f]], 0.0, 1.0), an = std::clamp(a[m_.neighbour[f]], 0.0, 1.0);
    // s > 0: gravity points from the owner to the neighbour, the owner is the upper cell.
    FL_[f] += s > 0 ? s * ao * (1 - an) : s * an * (1 - ao);
  });
}

// The interface normal per cell: the Gauss gradient of alpha.
void AlphaEqn::interface_normal(const Fields& F) {
  const auto face_alpha = [&](int f, int) { return internal(m_, f) ? interpolate(m_, f, F.alpha) : bcs_[f].alpha(bc_ctx_, f); };
  grad(m_, region_.cell_faces(), region_.halo, face_alpha, grad_alpha_, region_.face_in_region());
  region_.ranks().sync(grad_alpha_);
}

// Alpha is carried by the last pressure solve's fluxes on every face, boundary faces included: they
// are divergence-free together, so that the low-order update stays within its neighbours' bounds.
// Through a boundary face the material entering is the fill that went with that flux
// (carried_alpha): a coupled inflow whose flux changes from step to step (a nest's) brings in its
// last step's fill with its last step's flux, its record one step late, and the run's balance,
// counted from these fluxes (granular_flux), stays exact. Carried by the step's own fixed flux
// instead, the cells next to such an inflow saw the change of the flux between two steps as a
// source of material: alpha rose to 1.0000017 behind a laboratory nest's face and to 1.0058-1.0098
// behind a terrain nest's, whose record jumps at each depth-averaged step.
// Per face the upwind flux FL and the antidiffusive flux AF (central value plus compression, less
// upwind); per cell the bounds of alpha among its neighbours (and what flows in from outside).
void AlphaEqn::fluxes_and_bounds(const Fields& F) {
  const auto& a = F.alpha;
  const auto& ga = grad_alpha_;
  parallel_each(region_.faces, [&](int f) {
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
    } else {
      FL_[f] = ph * (ph >= 0 ? a[o] : bcs_[f].carried_alpha(bc_ctx_, f));
      AF_[f] = 0;
    }
  });
  // The bounds: the cell's own alpha, its neighbours' across faces of the region, and what enters
  // through its boundary faces.
  const CellFaces& cf = region_.cell_faces();
  parallel_each(region_.halo, [&](int c) {
    double hi = a[c], lo = a[c];
    for (int f : cf[c]) {
      if (!region_.face_in[f]) continue;
      if (internal(m_, f)) {
        const double other = a[m_.owner[f] == c ? m_.neighbour[f] : m_.owner[f]];
        hi = std::max(hi, other);
        lo = std::min(lo, other);
      } else if (F.phi[f] < 0) {
        const double ab = bcs_[f].carried_alpha(bc_ctx_, f);
        hi = std::max(hi, ab);
        lo = std::min(lo, ab);
      }
    }
    amax_[c] = hi;
    amin_[c] = lo;
  });
}

// Zalesak's limiter: the low-order update, the antidiffusive fluxes into (Pp) and out of (Pm) each
// cell, the fractions Rp, Rm of them the cell's bounds allow, and the update with each face's
// antidiffusive flux scaled by the smaller fraction of its two cells.
void AlphaEqn::limit_and_update(Fields& F, double dts, int subcycles) {
  auto& a = F.alpha;
  const CellFaces& cf = region_.cell_faces();
  // The low-order update and the antidiffusive fluxes into and out of each cell, per cell over its
  // faces of the region in ascending order.
  parallel_each(region_.halo, [&](int c) {
    double aL = a[c] * m_.volume[c], Pp = 0, Pm = 0;
    for (int f : cf[c]) {
      if (!region_.face_in[f]) continue;
      const bool own = m_.owner[f] == c;
      if (own) aL -= dts * FL_[f];
      else aL += dts * FL_[f];
      if (!internal(m_, f)) continue;
      const double A = AF_[f];
      // A > 0 takes from the owner, gives to the neighbour.
      if (A > 0) {
        if (own) Pm += A;
        else Pp += A;
      } else {
        if (own) Pp -= A;
        else Pm -= A;
      }
    }
    aL_[c] = aL;
    const double V = m_.volume[c];
    const double lo = aL / V;
    const double up = std::clamp(amax_[c], 0.0, 1.0), dn = std::clamp(amin_[c], 0.0, 1.0);
    const double Qp = std::max(0.0, (up - lo) * V / dts), Qm = std::max(0.0, (lo - dn) * V / dts);
    Rp_[c] = Pp > 0 ? std::min(1.0, Qp / Pp) : 1.0;
    Rm_[c] = Pm > 0 ? std::min(1.0, Qm / Pm) : 1.0;
  });
  region_.ranks().sync(Rp_);
  region_.ranks().sync(Rm_);
  // Each face's antidiffusive flux scaled by the smaller fraction of its two cells.
  parallel_each(region_.faces, [&](int f) {
    double Fl = FL_[f];
    double dA = 0;
    if (internal(m_, f)) {
      const int o = m_.owner[f], nb = m_.neighbour[f];
      const double A = AF_[f];
      const double lam = A > 0 ? std::min(Rm_[o], Rp_[nb]) : std::min(Rp_[o], Rm_[nb]);
      Fl += lam * A;
      dA = lam * A * dts;
    }
    AF_[f] = dA;  // (the antidiffusive flux is spent: its share of this step kept here)
    F.alpha_phi[f] += Fl / subcycles;
  });
  parallel_each(region_.halo, [&](int c) {
    double aL = aL_[c];
    for (int f : cf[c]) {
      if (f >= m_.n_internal || !region_.face_in[f]) continue;
      if (m_.owner[f] == c) aL -= AF_[f];
      else aL += AF_[f];
    }
    a[c] = aL / m_.volume[c];
  });
  region_.ranks().sync(a);
}

}  // namespace runout::engine::vof
