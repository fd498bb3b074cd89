// The second half of one tile's step of the depth-averaged 2D scheme: the positivity limiter and the
// update with the sources, friction, hazard maps and the tile's sums. Both run as branch-free row
// kernels (0/1 selects instead of branches, so that the compiler vectorises them); cells at the
// domain's edges and next to cells outside it take the general cell function. The tile's sums are
// taken afterwards in a scalar loop over the cells in their fixed order, so that they are the same
// bits for any thread count and any vector width.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "engine/sh2d/solver.hpp"

namespace runout::engine::sh2d_detail {
namespace {

// The same number for the row kernel, as a sum of 0/1-weighted terms: exact because the factors lie
// in [0, 1]. Written as selects, the compiler would load rl and rr only in their branch and could
// not vectorise the loop (a conditional load might fault).
inline double upwind_blend(double f0, double rl, double rr) {
  const double pos = f0 > 0 ? 1.0 : 0.0, neg = f0 < 0 ? 1.0 : 0.0;
  return pos * rl + neg * rr + (1.0 - pos - neg);
}

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
    const bool lim = out > H[t];
    r[t] = lim ? H[t] / out : 1.0;
    limited += lim && t >= ta && t < tb;
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

// The update of one cell in the general form (domain edges, cells outside the domain next to it):
// new state, hazard maps, the outflow through its edges into `out`, and its terms of the tile's sums
// into the work space's row buffers (index i - i0).
template <Basal B>
void Solver::update_cell(TileWork& w, int i, int j, int i0, double t, double dt, double& out) {
  const auto &H0 = H_[cur_], &HU0 = HU_[cur_], &HV0 = HV_[cur_];
  auto &H1 = H_[1 - cur_], &HU1 = HU_[1 - cur_], &HV1 = HV_[1 - cur_], &U1 = U_[1 - cur_], &V1 = V_[1 - cur_];
  const double lx = dt / t_.dx, ly = dt / t_.dy, dry = cfg_.dry_depth;
  // Scaled face flux: the limiter factor of the upwind (sending) cell.
  auto scaled = [&](const Face& f, int il, int jl, int ir, int jr, bool has_l, bool has_r) {
    double s = 1.0;
    if (f.f0 > 0 && has_l) s = w.r[w.at(il, jl)];
    else if (f.f0 < 0 && has_r) s = w.r[w.at(ir, jr)];
    return Face{f.f0 * s, f.f1 * s, f.f2 * s};
  };
  const std::size_t k = idx(i, j), q = w.at(i, j);
  const Face fw = scaled(w.fxf(w.fx(i, j)), i - 1, j, i, j, i > 0, true);
  const Face fe = scaled(w.fxf(w.fx(i + 1, j)), i, j, i + 1, j, true, i < nx_ - 1);
  const Face fs = scaled(w.fyf(w.fy(i, j)), i, j - 1, i, j, j > 0, true);
  const Face fn = scaled(w.fyf(w.fy(i, j + 1)), i, j, i, j + 1, true, j < ny_ - 1);
  const bool ow = w.has_outside && i > 0 && outside(i - 1, j), oe = w.has_outside && i < nx_ - 1 && outside(i + 1, j);
  const bool os = w.has_outside && j > 0 && outside(i, j - 1), on = w.has_outside && j < ny_ - 1 && outside(i, j + 1);
  if (i == 0 || ow) out -= fw.f0 * dt * t_.dy;
  if (i == nx_ - 1 || oe) out += fe.f0 * dt * t_.dy;
  if (j == 0 || os) out -= fs.f0 * dt * t_.dx;
  if (j == ny_ - 1 || on) out += fn.f0 * dt * t_.dx;
  double H = H0[k] - lx * (fe.f0 - fw.f0) - ly * (fn.f0 - fs.f0);
  if (H < 0) H = 0;  // round-off only: the limiter above bounds the outflow by the content
  // Source at the half step (midpoint rule).
  const double Hp = w.Hp[q], Up = w.Up[q], Vp = w.Vp[q];
  const double gn = normal_g(k, Up, Vp);
  const double drive = -Hp * geo_.c[k] * geo_.c[k] * gn;
  double MU = HU0[k] - lx * (fe.f1 - fw.f1) - ly * (fn.f1 - fs.f1) + dt * drive * geo_.bx[k];
  double MV = HV0[k] - lx * (fe.f2 - fw.f2) - ly * (fn.f2 - fs.f2) + dt * drive * geo_.by[k];
  double U = 0, V = 0, sp = 0;
  if (H > dry) {
    // Friction at the half step (midpoint rule), as a bounded impulse that never reverses u; its load
    // and mu from the half-step state.
    const double M3 = m3(k, MU, MV), impulse = dt * resistance(k, Hp, gn, basal_mu<B>(k, Hp, Up, Vp, gn));
    apply_friction(MU, MV, M3, impulse);
    const double inv = 1.0 / H;
    sp = std::max(M3 - impulse, 0.0) * inv;  // surface speed after Coulomb friction
    if (ixi_ > 0) {  // Voellmy drag, implicit in the speed
      const double f = turbulent_factor(sp, H * geo_.c[k], dt * g_ * ixi_);
      MU *= f;
      MV *= f;
      sp *= f;
    }
    U = MU * inv;
    V = MV * inv;
  } else {
    MU = MV = 0;
  }
  H1[k] = H;
  HU1[k] = MU;
  HV1[k] = MV;
  U1[k] = U;
  V1[k] = V;
  // Hazard maps and the terms of the tile sums from the new state.
  const double h = H * geo_.c[k], sp2 = sp * sp;
  const bool flowing = h > cfg_.flow_threshold;
  hz_.max_depth[k] = std::max(hz_.max_depth[k], h);
  if (flowing) {
    hz_.max_speed[k] = std::max(hz_.max_speed[k], sp);
    hz_.max_pressure[k] = std::max(hz_.max_pressure[k], cfg_.material.density * sp2);
    if (std::isnan(hz_.arrival_time[k])) hz_.arrival_time[k] = t + dt;
  }
  w.cell_ke[i - i0] = 0.5 * H * sp2;
  w.cell_speed[i - i0] = flowing ? sp : 0.0;  // reported speeds: flowing cells only, as in the map
  w.cell_rate[i - i0] = std::abs(U) / t_.dx + std::abs(V) / t_.dy + w.Ps[q] * std::sqrt(H);
}

// The update of cells (ia..ib-1, j), all inside the domain and away from its edges: the same
// arithmetic as update_cell, branch-free. B: the friction's kernel; without Voellmy's drag its
// factor would be exactly 1 and its square root is skipped.
template <Basal B>
RUNOUT_SIMD_CLONES void Solver::update_row(TileWork& w, int j, int ia, int ib, int i0, double dt) {
  constexpr bool Voellmy = B == Basal::voellmy;
  const std::size_t k0 = idx(ia, j), q0 = w.at(ia, j);
  const std::ptrdiff_t bw = w.bw;
  const double *__restrict H0 = &H_[cur_][k0], *__restrict HU0 = &HU_[cur_][k0], *__restrict HV0 = &HV_[cur_][k0];
  double *__restrict H1 = &H_[1 - cur_][k0], *__restrict HU1 = &HU_[1 - cur_][k0], *__restrict HV1 = &HV_[1 - cur_][k0];
  double *__restrict U1 = &U_[1 - cur_][k0], *__restrict V1 = &V_[1 - cur_][k0];
  const double *__restrict cc = &geo_.c[k0], *__restrict bx = &geo_.bx[k0], *__restrict by = &geo_.by[k0];
  const double *__restrict hxx = &geo_.hxx[k0], *__restrict hxy = &geo_.hxy[k0], *__restrict hyy = &geo_.hyy[k0];
  double *__restrict md = &hz_.max_depth[k0], *__restrict ms = &hz_.max_speed[k0];
  double* __restrict mp = &hz_.max_pressure[k0];
  const double *__restrict Hp = &w.Hp[q0], *__restrict Up = &w.Up[q0], *__restrict Vp = &w.Vp[q0];
  const double *__restrict Ps = &w.Ps[q0], *__restrict r = &w.r[q0];
  const std::size_t x0 = w.fx(ia, j), y0 = w.fy(ia, j);
  const double *__restrict Fx0 = &w.Fx0[x0], *__restrict Fx1 = &w.Fx1[x0], *__restrict Fx2 = &w.Fx2[x0];
  const double *__restrict Fy0 = &w.Fy0[y0], *__restrict Fy1 = &w.Fy1[y0], *__restrict Fy2 = &w.Fy2[y0];
  double *__restrict oke = &w.cell_ke[ia - i0], *__restrict osp = &w.cell_speed[ia - i0];
  double *__restrict ort = &w.cell_rate[ia - i0], *__restrict oh = &w.cell_h[ia - i0];
  double *__restrict opr = &w.cell_pressure[ia - i0];
  const double lx = dt / t_.dx, ly = dt / t_.dy, dx = t_.dx, dy = t_.dy, dry = cfg_.dry_depth, g = g_, qcap = qcap_;
  const double mu = mu_, gxd = dt * g_ * ixi_, thr = cfg_.flow_threshold, rho = cfg_.material.density;
  const double curv = cfg_.curvature ? 1.0 : 0.0;  // a 0/1 weight: exact, as gn and g are finite
  const BasalFriction fr = fr_;
  const double *__restrict rmu = w.row_mu.data(), *__restrict rwt = w.row_w.data();  // start_terms'
  const int n = ib - ia;
#pragma omp simd
  for (int m = 0; m < n; ++m) {
    // Face fluxes scaled by the sending cell's draining factor (face above: one box row further).
    const double rc = r[m];
    const double sw = upwind_blend(Fx0[m], r[m - 1], rc), se = upwind_blend(Fx0[m + 1], rc, r[m + 1]);
    const double ss = upwind_blend(Fy0[m], r[m - bw], rc), sn = upwind_blend(Fy0[m + bw], rc, r[m + bw]);
    double H = H0[m] - lx * (Fx0[m + 1] * se - Fx0[m] * sw) - ly * (Fy0[m + bw] * sn - Fy0[m] * ss);
    H = H < 0 ? 0.0 : H;
    const double hp = Hp[m], up = Up[m], vp = Vp[m], c = cc[m];
    const double gn = vmax(0.0, g + vmin(qcap, up * up * hxx[m] + 2 * up * vp * hxy[m] + vp * vp * hyy[m]));
    const double drive = -hp * c * c * gn;
    double MU = HU0[m] - lx * (Fx1[m + 1] * se - Fx1[m] * sw) - ly * (Fy1[m + bw] * sn - Fy1[m] * ss) + dt * drive * bx[m];
    double MV = HV0[m] - lx * (Fx2[m + 1] * se - Fx2[m] * sw) - ly * (Fy2[m + bw] * sn - Fy2[m] * ss) + dt * drive * by[m];
    const double wz = bx[m] * MU + by[m] * MV;
    const double M3 = std::sqrt(MU * MU + MV * MV + wz * wz);
    const double load = curv * gn + (1.0 - curv) * g;
    double mu_k = mu;  // mu of the half-step state
    if constexpr (B == Basal::flow) {
      const double wq = bx[m] * up + by[m] * vp;
      mu_k = flow_mu<false>(fr, hp * c, std::sqrt(up * up + vp * vp + wq * wq), c * load);
    } else if constexpr (B == Basal::hysteresis) {
      mu_k = with_start(fr, rmu[m], rwt[m]);
    }
    const double imp = dt * (hp * mu_k * c * load);
    const bool rest = M3 <= imp;  // apply_friction: stopped, or slowed by the impulse
    const double f = 1.0 - imp / M3;
    MU = rest ? 0.0 : MU * f;
    MV = rest ? 0.0 : MV * f;
    const double inv = 1.0 / H;
    double sp = vmax(M3 - imp, 0.0) * inv;
    if constexpr (Voellmy) {
      const double ft = turbulent_factor(sp, H * c, gxd);
      MU *= ft;
      MV *= ft;
      sp *= ft;
    }
    const bool wet = H > dry;
    const double U = wet ? MU * inv : 0.0, V = wet ? MV * inv : 0.0;
    sp = wet ? sp : 0.0;
    H1[m] = H;
    HU1[m] = wet ? MU : 0.0;
    HV1[m] = wet ? MV : 0.0;
    U1[m] = U;
    V1[m] = V;
    const double h = H * c, sp2 = sp * sp;
    const bool flowing = h > thr;
    oh[m] = h;
    opr[m] = flowing ? rho * sp2 : 0.0;
    oke[m] = 0.5 * H * sp2;
    osp[m] = flowing ? sp : 0.0;
    ort[m] = std::abs(U) / dx + std::abs(V) / dy + Ps[m] * std::sqrt(H);
  }
  // The maps, in a loop of their own: inside the one above the compiler splits the paths of flowing
  // and resting cells and turns the maxima into conditional stores, which blocks vectorisation.
  // Speeds and pressures are >= 0, so the maximum with the 0 of a resting cell leaves them as they
  // are. The arrival time is set in update's cell loop.
#pragma omp simd
  for (int m = 0; m < n; ++m) {
    md[m] = vmax(md[m], oh[m]);
    ms[m] = vmax(ms[m], osp[m]);
    mp[m] = vmax(mp[m], opr[m]);
  }
}

// The update with the kernels of the material's friction (Basal).
void Solver::update(int tt, TileWork& w, const CellBox& c, double t, double dt) {
  switch (basal_) {
    case Basal::coulomb: update_cells<Basal::coulomb>(tt, w, c, t, dt); break;
    case Basal::voellmy: update_cells<Basal::voellmy>(tt, w, c, t, dt); break;
    case Basal::flow: update_cells<Basal::flow>(tt, w, c, t, dt); break;
    case Basal::hysteresis: update_cells<Basal::hysteresis>(tt, w, c, t, dt); break;
  }
}

template <Basal B>
void Solver::update_cells(int tt, TileWork& w, const CellBox& c, double t, double dt) {
  const int i0 = c.i0, i1 = c.i1, j0 = c.j0, j1 = c.j1;
  const auto &H1 = H_[1 - cur_], &HU1 = HU_[1 - cur_], &HV1 = HV_[1 - cur_];
  double out = 0, travel = 0, mass = 0, ke = 0, vmax = 0, rate = 0;
  bool wet = false;
  for (int j = j0; j < j1; ++j) {
    // The row's cells: the row kernel away from the domain's edges, the general function elsewhere.
    int ia = i0, ib = i0;
    if (!w.has_outside && j > 0 && j < ny_ - 1) {
      ia = std::max(i0, 1);
      ib = std::max(ia, std::min(i1, nx_ - 1));
    }
    for (int i = i0; i < i1; ++i) {
      if (i == ia && ib > ia) {
        if constexpr (B == Basal::hysteresis) {
          const std::size_t q = w.at(ia, j);
          start_terms(ib - ia, idx(ia, j), &w.Hp[q], &w.Up[q], &w.Vp[q], w);
        }
        update_row<B>(w, j, ia, ib, i0, dt);
        i = ib - 1;
        continue;
      }
      if (w.has_outside && outside(i, j)) continue;  // never holds material (both buffers stay 0)
      update_cell<B>(w, i, j, i0, t, dt, out);
    }
    // The tile's sums, cell by cell in a fixed order.
    for (int i = i0; i < i1; ++i) {
      const std::size_t k = idx(i, j);
      if (w.has_outside && outside(i, j)) continue;
      if (cfg_.track_travel) travel += dt * std::sqrt(HU1[k] * HU1[k] + HV1[k] * HV1[k]);
      mass += H1[k];
      ke += w.cell_ke[i - i0];  // the stopping rule sees every cell
      vmax = std::max(vmax, w.cell_speed[i - i0]);
      rate = std::max(rate, w.cell_rate[i - i0]);
      wet = wet || H1[k] > cfg_.activation_depth;
      // The arrival time of a cell that flows for the first time (the row kernel leaves it).
      if (i >= ia && i < ib && std::isnan(hz_.arrival_time[k]) && H1[k] * geo_.c[k] > cfg_.flow_threshold)
        hz_.arrival_time[k] = t + dt;
    }
  }
  tile_out_[tt] += out;
  tile_travel_[tt] += travel;
  tile_mass_[tt] = mass;
  tile_ke_[tt] = ke;
  tile_speed_[tt] = vmax;
  tile_rate_[tt] = rate;
  tile_wet_[tt] = wet;
}

}  // namespace runout::engine::sh2d_detail
