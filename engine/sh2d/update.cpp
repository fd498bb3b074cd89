// The positivity limiter and the update of the depth-averaged 2D scheme: the draining factors, the
// conservative update with the sources and friction at the half step (the point kernels in
// kernels.hpp), the hazard maps and the tile's sums. The update runs as a branch-free row kernel
// (vectorised) for runs of cells away from the domain's edges and from cells outside it; the
// others take the general cell function, which calls the same kernels. The tile's sums are taken
// afterwards in a scalar loop over the cells in their fixed order, so that they are the same bits
// for any thread count and any vector width.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "engine/sh2d/solver.hpp"

namespace runout::engine::sh2d_detail {
namespace {

// Draining-time factors of the cells (ia..ib-1) of one row, Fx at the face left of cell ia, Fy at the
// face below it, sy the offset to the face above; returns how many of the cells [ta, tb) (relative to
// ia) had to be limited.
RUNOUT_SIMD_CLONES long positivity_row(int n, const double* __restrict Fx, const double* __restrict Fy, std::ptrdiff_t sy,
                                       const double* __restrict H, double* __restrict r, double cx, double cy, int ta,
                                       int tb) {
  long limited = 0;
  for (int t = 0; t < n; ++t) {
    const double out = cx * (std::max(Fx[t + 1], 0.0) + std::max(-Fx[t], 0.0)) +
                       cy * (std::max(Fy[t + sy], 0.0) + std::max(-Fy[t], 0.0));
    r[t] = drain_factor(out, H[t]);
    limited += out > H[t] && t >= ta && t < tb;
  }
  return limited;
}

}  // namespace

long Solver::positivity(TileWork& w, int i0, int i1, int j0, int j1, double dt) const {
  // Draining-time limiter on the tile grown by one: a cell may not send out more volume than it holds.
  const auto& Hs = H_[cur_];
  const double cx = dt / t_.dx, cy = dt / t_.dy;
  const int ia = std::max(i0 - 1, 0), ib = std::min(i1 + 1, nx_);
  long limited = 0;
  for (int j = std::max(j0 - 1, 0); j < std::min(j1 + 1, ny_); ++j) {
    const bool in = j >= j0 && j < j1;  // a row of the tile: its limited cells are counted
    limited += positivity_row(ib - ia, &w.Fx0[w.fx(ia, j)], &w.Fy0[w.fy(ia, j)], w.bw, &Hs[idx(ia, j)],
                              &w.r[w.at(ia, j)], cx, cy, in ? i0 - ia : 0, in ? i1 - ia : 0);
  }
  return limited;
}

// The update of one cell in the general form (domain edges, cells outside the domain next to it, a
// dam's step, a flux gauge's cell): the face fluxes scaled by the sending cells' draining factors (1
// beyond the domain's edge), the outflow through its edges into `out`, what a gauge's cell sends
// right and left, the reaction of a dam's walls through its step faces, then the kernels of the row
// kernel.
template <Basal B>
void Solver::update_cell(TileWork& w, int i, int j, int i0, double t1, double dt, double& out) {
  const std::size_t q = w.at(i, j), x = w.fx(i, j), y = w.fy(i, j);
  const double rc = w.r[q];
  const double rw = i > 0 ? w.r[q - 1] : 1.0, re = i < nx_ - 1 ? w.r[q + 1] : 1.0;
  const double rs = j > 0 ? w.r[q - w.bw] : 1.0, rn = j < ny_ - 1 ? w.r[q + w.bw] : 1.0;
  const double sw = upwind_blend(w.Fx0[x], rw, rc), se = upwind_blend(w.Fx0[x + 1], rc, re);
  const double ss = upwind_blend(w.Fy0[y], rs, rc), sn = upwind_blend(w.Fy0[y + w.bw], rc, rn);
  const bool ow = w.has_outside && i > 0 && outside(i - 1, j), oe = w.has_outside && i < nx_ - 1 && outside(i + 1, j);
  const bool os = w.has_outside && j > 0 && outside(i, j - 1), on = w.has_outside && j < ny_ - 1 && outside(i, j + 1);
  // The volume each face sends out in the step (W, E, S, N; negative: it comes in): what leaves
  // through the domain's edges, and what a flux gauge's cell sends to the gauge's right and left.
  const double sent[4] = {-w.Fx0[x] * sw * dt * t_.dy, w.Fx0[x + 1] * se * dt * t_.dy, -w.Fy0[y] * ss * dt * t_.dx,
                          w.Fy0[y + w.bw] * sn * dt * t_.dx};
  if (gauge_cell(idx(i, j))) {
    const int g = gauge_slot_[idx(i, j)];
    for (int f = 0; f < 4; ++f) {
      if (slot_sides_[g][f] > 0) slot_right_[g] += sent[f];
      if (slot_sides_[g][f] < 0) slot_left_[g] += sent[f];
    }
  }
  if (i == 0 || ow) out += sent[0];
  if (i == nx_ - 1 || oe) out += sent[1];
  if (j == 0 || os) out += sent[2];
  if (j == ny_ - 1 || on) out += sent[3];
  double smu = 0, swt = 0;
  if constexpr (B == Basal::hysteresis) {
    const std::size_t k = idx(i, j);
    const MuParts p = start_parts(constants(), w.Hp[q], w.Up[q], w.Vp[q], geo_.c[k], geo_.bx[k], geo_.by[k],
                                  geo_.hxx[k], geo_.hxy[k], geo_.hyy[k]);
    smu = p.mu;
    swt = start_weight(p.q);
  }
  double wu = 0, wv = 0;  // the dams' walls' reaction through its step faces
  if (!dam_.empty()) {
    const std::size_t k = idx(i, j);
    const double lx = dt / t_.dx, ly = dt / t_.dy;
    if (i > 0 && step_face(k, k - 1)) wu += lx * w.Wxb1[x], wv += lx * w.Wxb2[x];
    if (i < nx_ - 1 && step_face(k, k + 1)) wu -= lx * w.Wxa1[x + 1], wv -= lx * w.Wxa2[x + 1];
    if (j > 0 && step_face(k, k - nx_)) wu += ly * w.Wyb1[y], wv += ly * w.Wyb2[y];
    if (j < ny_ - 1 && step_face(k, k + nx_)) wu -= ly * w.Wya1[y + w.bw], wv -= ly * w.Wya2[y + w.bw];
  }
  update_run<B>(w, j, i, i + 1, i0, t1, dt, sw, se, ss, sn, smu, swt, wu, wv);
}

// The update of cells (ia..ib-1, j), all inside the domain and away from its edges, in a loop the
// compiler can vectorise (the point kernels are branch-free): the face fluxes scaled by the sending
// cells' draining factors, the sources and friction, the new state, and the cells' terms of the
// hazard maps and the tile sums. B: the friction's kernel; without Voellmy's drag its factor would be
// exactly 1 and its square root is skipped.
template <Basal B>
RUNOUT_SIMD_CLONES void Solver::update_row(TileWork& w, int j, int ia, int ib, int i0, double t1, double dt) {
  update_run<B, true>(w, j, ia, ib, i0, t1, dt, 0, 0, 0, 0, 0, 0, 0, 0);
}

// The update of cells (ia..ib-1, j): Row, the draining factors from the work space's neighbours and
// the start/stop law's parts from start_terms; else one cell with the factors sw, se, ss, sn and
// the parts smu, swt given.
template <Basal B, bool Row>
RUNOUT_KERNEL void Solver::update_run(TileWork& w, int j, int ia, int ib, int i0, double t1, double dt, double sw1,
                                      double se1, double ss1, double sn1, double smu1, double swt1, double wu1,
                                      double wv1) {
  const std::size_t k0 = idx(ia, j), q0 = w.at(ia, j);
  const std::ptrdiff_t bw = w.bw;
  const double *__restrict H0 = &H_[cur_][k0], *__restrict HU0 = &HU_[cur_][k0], *__restrict HV0 = &HV_[cur_][k0];
  double *__restrict H1 = &H_[1 - cur_][k0], *__restrict HU1 = &HU_[1 - cur_][k0], *__restrict HV1 = &HV_[1 - cur_][k0];
  double *__restrict U1 = &U_[1 - cur_][k0], *__restrict V1 = &V_[1 - cur_][k0];
  const double *__restrict cc = &geo_.c[k0], *__restrict bx = &geo_.bx[k0], *__restrict by = &geo_.by[k0];
  const double *__restrict hxx = &geo_.hxx[k0], *__restrict hxy = &geo_.hxy[k0], *__restrict hyy = &geo_.hyy[k0];
  double *__restrict md = &hz_.max_depth[k0], *__restrict ms = &hz_.max_speed[k0];
  double *__restrict mp = &hz_.max_pressure[k0], *__restrict at = &hz_.arrival_time[k0];
  const double *__restrict Hp = &w.Hp[q0], *__restrict Up = &w.Up[q0], *__restrict Vp = &w.Vp[q0];
  const double *__restrict Ps = &w.Ps[q0], *__restrict r = &w.r[q0];
  const std::size_t x0 = w.fx(ia, j), y0 = w.fy(ia, j);
  const double *__restrict Fx0 = &w.Fx0[x0], *__restrict Fx1 = &w.Fx1[x0], *__restrict Fx2 = &w.Fx2[x0];
  const double *__restrict Fy0 = &w.Fy0[y0], *__restrict Fy1 = &w.Fy1[y0], *__restrict Fy2 = &w.Fy2[y0];
  double *__restrict oke = &w.cell_ke[ia - i0], *__restrict osp = &w.cell_speed[ia - i0];
  double *__restrict ort = &w.cell_rate[ia - i0], *__restrict oh = &w.cell_h[ia - i0];
  double *__restrict opr = &w.cell_pressure[ia - i0], *__restrict odet = &w.cell_det[ia - i0];
  const double* __restrict cr = B == Basal::ground ? &cres_[k0] : nullptr;  // the areas' drag and
  const double* __restrict kd = B == Basal::ground ? &kdet_[k0] : nullptr;  // detrainment
  double* __restrict det = B == Basal::ground ? &det_[k0] : nullptr;
  double* __restrict cov = B == Basal::ground ? &cover_[k0] : nullptr;  // the erodible cover
  double* __restrict oent = &w.cell_ent[ia - i0];
  const double lx = dt / t_.dx, ly = dt / t_.dy, dx = t_.dx, dy = t_.dy, gxd = dt * g_ * ixi_;
  const double thr = cfg_.flow_threshold, rho = cfg_.material.density;
  const StepConstants K = constants();
  const double *__restrict rmu = w.row_mu.data(), *__restrict rwt = w.row_w.data();  // start_terms'
  const int n = ib - ia;
#pragma omp simd
  for (int m = 0; m < n; ++m) {
    // Face fluxes scaled by the sending cell's draining factor (face above: one box row further).
    double sw = sw1, se = se1, ss = ss1, sn = sn1, smu = smu1, swt = swt1;
    if constexpr (Row) {
      const double rc = r[m];
      sw = upwind_blend(Fx0[m], r[m - 1], rc);
      se = upwind_blend(Fx0[m + 1], rc, r[m + 1]);
      ss = upwind_blend(Fy0[m], r[m - bw], rc);
      sn = upwind_blend(Fy0[m + bw], rc, r[m + bw]);
      smu = rmu[m];
      swt = rwt[m];
    }
    const double H = flux_update(H0[m], lx, ly, Fx0[m], Fx0[m + 1], Fy0[m], Fy0[m + bw], sw, se, ss, sn);
    double MU = flux_update(HU0[m], lx, ly, Fx1[m], Fx1[m + 1], Fy1[m], Fy1[m + bw], sw, se, ss, sn);
    double MV = flux_update(HV0[m], lx, ly, Fx2[m], Fx2[m + 1], Fy2[m], Fy2[m + bw], sw, se, ss, sn);
    if constexpr (!Row) {  // a dam's walls (the sums skipped where they are 0: the same bits as without)
      MU = wu1 != 0.0 ? MU + wu1 : MU;
      MV = wv1 != 0.0 ? MV + wv1 : MV;
    }
    double cres = 0, kdet = 0, cv = 0;
    if constexpr (B == Basal::ground) {
      cres = cr[m];
      kdet = kd[m];
      cv = cov[m];
    }
    const NewState s = update_sources<B>(K, H, MU, MV, Hp[m], Up[m], Vp[m], cc[m], bx[m], by[m], hxx[m], hxy[m],
                                         hyy[m], dt, gxd, smu, swt, cres, kdet, cv);
    if constexpr (B == Basal::ground) {
      det[m] += s.det;
      odet[m] = s.det;
      cov[m] = cv - s.ent;
      oent[m] = s.ent;
    }
    H1[m] = s.H;
    HU1[m] = s.MU;
    HV1[m] = s.MV;
    U1[m] = s.U;
    V1[m] = s.V;
    const CellTerms e = cell_terms(s, cc[m], Ps[m], dx, dy, thr, rho);
    oh[m] = e.h;
    opr[m] = e.pressure;
    oke[m] = e.ke;
    osp[m] = e.speed;
    ort[m] = e.rate;
  }
  // The maps, in a loop of their own: inside the one above the compiler splits the paths of flowing
  // and resting cells and turns the maxima into conditional stores, which blocks vectorisation.
  // Speeds and pressures are >= 0, so the maximum with the 0 of a resting cell leaves them as they
  // are. The arrival time t1 where a cell flows for the first time, as a select (stored always).
#pragma omp simd
  for (int m = 0; m < n; ++m) {
    md[m] = vmax(md[m], oh[m]);
    ms[m] = vmax(ms[m], osp[m]);
    mp[m] = vmax(mp[m], opr[m]);
    at[m] = std::isnan(at[m]) && oh[m] > thr ? t1 : at[m];
  }
}

// The update with the kernels of the material's friction (Basal).
void Solver::update(int tt, TileWork& w, const CellBox& c, double t, double dt) {
  switch (basal_) {
    case Basal::coulomb: update_cells<Basal::coulomb>(tt, w, c, t, dt); break;
    case Basal::voellmy: update_cells<Basal::voellmy>(tt, w, c, t, dt); break;
    case Basal::flow: update_cells<Basal::flow>(tt, w, c, t, dt); break;
    case Basal::hysteresis: update_cells<Basal::hysteresis>(tt, w, c, t, dt); break;
    case Basal::ground: update_cells<Basal::ground>(tt, w, c, t, dt); break;
  }
}

template <Basal B>
void Solver::update_cells(int tt, TileWork& w, const CellBox& c, double t, double dt) {
  const int i0 = c.i0, i1 = c.i1, j0 = c.j0, j1 = c.j1;
  const auto &H1 = H_[1 - cur_], &HU1 = HU_[1 - cur_], &HV1 = HV_[1 - cur_];
  double out = 0, travel = 0, mass = 0, ke = 0, top = 0, rate = 0, detrained = 0, entrained = 0;
  bool wet = false;
  for (int j = j0; j < j1; ++j) {
    // The row's cells: the row kernel for runs of cells away from the domain's edges and from cells
    // outside it, the general function for the others (the same kernels, the same bits).
    const bool inner = j > 0 && j < ny_ - 1;
    const int fb = std::min(i1, nx_ - 1);
    for (int i = i0; i < i1; ++i) {
      if (inner && i > 0 && i < fb && !general(idx(i, j))) {
        int e = i + 1;  // a run of cells for the row kernel
        while (e < fb && !general(idx(e, j))) ++e;
        if constexpr (B == Basal::hysteresis) {
          const std::size_t q = w.at(i, j);
          start_terms(e - i, idx(i, j), &w.Hp[q], &w.Up[q], &w.Vp[q], w);
        }
        update_row<B>(w, j, i, e, i0, t + dt, dt);
        i = e - 1;
        continue;
      }
      if (w.has_outside && outside(i, j)) {  // never holds material (both buffers stay 0)
        w.cell_ke[i - i0] = w.cell_speed[i - i0] = w.cell_rate[i - i0] = w.cell_det[i - i0] = w.cell_ent[i - i0] = 0.0;
        continue;
      }
      update_cell<B>(w, i, j, i0, t + dt, dt, out);
    }
    // The tile's sums, cell by cell in a fixed order; a cell outside the domain adds exact zeros.
    const std::size_t k = idx(i0, j);
    const int n = i1 - i0;
    const double *h1 = &H1[k], *hu1 = &HU1[k], *hv1 = &HV1[k];
    if (cfg_.track_travel)
      for (int m = 0; m < n; ++m)
        if (!(w.has_outside && outside(i0 + m, j))) travel += dt * std::sqrt(hu1[m] * hu1[m] + hv1[m] * hv1[m]);
    const double act = cfg_.activation_depth;
    for (int m = 0; m < n; ++m) {
      mass += h1[m];
      ke += w.cell_ke[m];  // the stopping rule sees every cell
      top = sh2d_detail::vmax(top, w.cell_speed[m]);
      rate = sh2d_detail::vmax(rate, w.cell_rate[m]);
      wet = wet || h1[m] > act;
    }
    if constexpr (B == Basal::ground)
      for (int m = 0; m < n; ++m) {
        detrained += w.cell_det[m];
        entrained += w.cell_ent[m];
      }
  }
  tile_out_[tt] += out;
  tile_det_[tt] += detrained;
  tile_ent_[tt] += entrained;
  tile_travel_[tt] += travel;
  tile_mass_[tt] = mass;
  tile_ke_[tt] = ke;
  tile_speed_[tt] = top;
  tile_rate_[tt] = rate;
  tile_wet_[tt] = wet;
}

}  // namespace runout::engine::sh2d_detail
