// The reconstruction and the predictor of the depth-averaged 2D scheme: limited slopes, the state at
// the half step with its sources and friction, and the pressure coefficients of each cell of a
// tile's box (the point kernels in kernels.hpp; a general cell loop and a branch-free row kernel
// call them).
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "engine/sh2d/solver.hpp"

namespace runout::engine::sh2d_detail {

// Active (extension) or passive (compression) earth pressure along and across the slope: the
// cell's pressure coefficients and wave factor from the sign of the velocity's divergence.
void Solver::earth_pressure(std::size_t k, int i, int j, double U, double V, double& Pxx, double& Pxy, double& Pyy,
                            double& Ps) const {
  const auto &Us = U_[cur_], &Vs = V_[cur_];
  const double bx = geo_.bx[k], by = geo_.by[k], gb = std::hypot(bx, by);
  double dx = 1, dy = 0;
  if (gb > 1e-12) {
    dx = bx / gb;
    dy = by / gb;
  } else if (U != 0 || V != 0) {
    const double s = std::hypot(U, V);
    dx = U / s;
    dy = V / s;
  }
  const std::size_t e = idx(std::min(i + 1, nx_ - 1), j), wst = idx(std::max(i - 1, 0), j);
  const std::size_t nn = idx(i, std::min(j + 1, ny_ - 1)), s = idx(i, std::max(j - 1, 0));
  // d/dx and d/dy of the velocity, then along (d) and across (s = (-dy, dx)) components
  const double dUx = (Us[e] - Us[wst]) / (2 * t_.dx), dVx = (Vs[e] - Vs[wst]) / (2 * t_.dx);
  const double dUy = (Us[nn] - Us[s]) / (2 * t_.dy), dVy = (Vs[nn] - Vs[s]) / (2 * t_.dy);
  const double along = dx * (dx * dUx + dy * dVx) + dy * (dx * dUy + dy * dVy);
  const double across = -dy * (-dy * dUx + dx * dVx) + dx * (-dy * dUy + dx * dVy);
  const int ax = along >= 0 ? 0 : 1;
  pressure(k, kx_[ax], ky_[ax][across >= 0 ? 0 : 1], dx, dy, Pxx, Pxy, Pyy);
  Ps = wave_factor(Pxx, Pyy);
}

// The predictor with the kernels of the material's friction (Basal).
template <Limiter lim>
void Solver::predictor(TileWork& w, double dt) const {
  switch (basal_) {
    case Basal::coulomb: predictor_cells<lim, Basal::coulomb>(w, dt); break;
    case Basal::voellmy: predictor_cells<lim, Basal::voellmy>(w, dt); break;
    case Basal::flow: predictor_cells<lim, Basal::flow>(w, dt); break;
    case Basal::hysteresis: predictor_cells<lim, Basal::hysteresis>(w, dt); break;
    case Basal::ground: predictor_cells<lim, Basal::ground>(w, dt); break;
  }
}
template void Solver::predictor<Limiter::minmod>(TileWork&, double) const;
template void Solver::predictor<Limiter::vanleer>(TileWork&, double) const;
template void Solver::predictor<Limiter::superbee>(TileWork&, double) const;

// The box's cells: the row kernel for runs of cells away from the domain's edges (K = 1, the
// default set-up), the general loop for the others. Which loop a cell takes depends only on its
// position; both call the same point kernels, so every tile that computes a cell gets the same bits.
template <Limiter lim, Basal B>
void Solver::predictor_cells(TileWork& w, double dt) const {
  const auto &Hs = H_[cur_], &HUs = HU_[cur_], &HVs = HV_[cur_], &Us = U_[cur_], &Vs = V_[cur_];
  const double hx = 0.5 * dt / t_.dx, hy = 0.5 * dt / t_.dy, gxd = 0.5 * dt * g_ * ixi_;
  const StepConstants K = constants();
  const std::ptrdiff_t N = nx_;
  const bool fast = !kap_;
  const int fa = std::max(w.bi0, 1), fb = std::min(w.bi0 + w.bw, nx_ - 1);
  for (int j = w.bj0; j < w.bj0 + w.bh; ++j)
    for (int i = w.bi0; i < w.bi0 + w.bw; ++i) {
      if (fast && j > 0 && j < ny_ - 1 && i >= fa && i < fb && !general(idx(i, j))) {
        int e = i + 1;  // a run of cells for the row kernel
        while (e < fb && !general(idx(e, j))) ++e;
        if constexpr (B == Basal::hysteresis) {
          const std::size_t k0 = idx(i, j);
          start_terms(e - i, k0, &Hs[k0], &Us[k0], &Vs[k0], w);
        }
        predictor_row<lim, B>(w, j, i, e, dt);
        i = e - 1;
        continue;
      }
      const std::size_t k = idx(i, j);
      const double H = Hs[k], U = Us[k], V = Vs[k];
      // Slopes only between cells of the domain, not across a dam's step.
      const bool edge = near_outside(k);
      const bool tx = i > 0 && i < nx_ - 1 && !(edge && (outside(i - 1, j) || outside(i + 1, j) || outside(i, j))) &&
                      !step_face(k, k - 1) && !step_face(k, k + 1);
      const bool ty = j > 0 && j < ny_ - 1 && !(edge && (outside(i, j - 1) || outside(i, j + 1) || outside(i, j))) &&
                      !step_face(k, k - N) && !step_face(k, k + N);
      Slopes s = limited_slopes<lim>(Hs.data(), Us.data(), Vs.data(), std::ptrdiff_t(k), tx ? -1 : 0, tx ? 1 : 0,
                                     ty ? -N : 0, ty ? N : 0, tx, ty, K.dry);
      double Pxx = Pxx_[k], Pxy = Pxy_[k], Pyy = Pyy_[k], Ps = Ps_[k];
      if (kap_) earth_pressure(k, i, j, U, V, Pxx, Pxy, Pyy, Ps);
      const double c = geo_.c[k], bx = geo_.bx[k], by = geo_.by[k];
      const double hxx = geo_.hxx[k], hxy = geo_.hxy[k], hyy = geo_.hyy[k];
      double smu = 0, sw = 0;
      if constexpr (B == Basal::hysteresis) {
        const MuParts p = start_parts(K, H, U, V, c, bx, by, hxx, hxy, hyy);
        smu = p.mu;
        sw = start_weight(p.q);
      }
      const double cres = B == Basal::ground ? cres_[k] : 0.0;
      const Predicted p = predict<B>(K, H, U, V, HUs[k], HVs[k], s, Pxx, Pxy, Pyy, c, bx, by, hxx, hxy, hyy, hx, hy,
                                     dt, gxd, smu, sw, cres);
      PredictorOut{w, w.at(i, j)}.put(0, s, p, Pxx, Pxy, Pyy, Ps);
    }
}

// The predictor for cells (ia..ib-1, j), all away from the domain's edges, K = 1, as a loop the
// compiler can vectorise (the point kernels are branch-free). B: the friction's kernel; without
// Voellmy's drag its factor would be exactly 1, and its square root and division are skipped.
template <Limiter lim, Basal B>
RUNOUT_SIMD_CLONES void Solver::predictor_row(TileWork& w, int j, int ia, int ib, double dt) const {
  const double* __restrict Hs = H_[cur_].data();
  const double* __restrict HUs = HU_[cur_].data();
  const double* __restrict HVs = HV_[cur_].data();
  const double* __restrict Us = U_[cur_].data();
  const double* __restrict Vs = V_[cur_].data();
  const double *__restrict bx = geo_.bx.data(), *__restrict by = geo_.by.data(), *__restrict cc = geo_.c.data();
  const double *__restrict hxx = geo_.hxx.data(), *__restrict hxy = geo_.hxy.data(), *__restrict hyy = geo_.hyy.data();
  const double *__restrict Pxx = Pxx_.data(), *__restrict Pxy = Pxy_.data(), *__restrict Pyy = Pyy_.data();
  const double* __restrict Ps = Ps_.data();
  const std::size_t k0 = idx(ia, j);
  const PredictorOut out{w, w.at(ia, j)};
  const double hx = 0.5 * dt / t_.dx, hy = 0.5 * dt / t_.dy, gxd = 0.5 * dt * g_ * ixi_;
  const StepConstants K = constants();
  const double *__restrict rmu = w.row_mu.data(), *__restrict rwt = w.row_w.data();  // start_terms'
  const double* __restrict cr = B == Basal::ground ? cres_.data() : nullptr;    // the areas' drag
  const std::ptrdiff_t N = nx_;
  const int n = ib - ia;
#pragma omp simd
  for (int t = 0; t < n; ++t) {
    const std::ptrdiff_t k = std::ptrdiff_t(k0) + t;
    Slopes s = limited_slopes<lim>(Hs, Us, Vs, k, -1, 1, -N, N, true, true, K.dry);
    double cres = 0;
    if constexpr (B == Basal::ground) cres = cr[k];
    const Predicted p = predict<B>(K, Hs[k], Us[k], Vs[k], HUs[k], HVs[k], s, Pxx[k], Pxy[k], Pyy[k], cc[k], bx[k],
                                   by[k], hxx[k], hxy[k], hyy[k], hx, hy, dt, gxd, rmu[t], rwt[t], cres);
    out.put(t, s, p, Pxx[k], Pxy[k], Pyy[k], Ps[k]);
  }
}

// The start/stop kernel's friction of cells k0..k0+n-1 at depth H and velocity (U, V) (the row's
// values): mu without the start/stop term into w.row_mu, the term's weights q^kappa into w.row_w.
// The power only where a cell moves, slower than beta_s (start_weight), in a scalar loop of its own:
// the row kernels that read them stay vectorised.
RUNOUT_SIMD_CLONES void Solver::start_terms(int n, std::size_t k0, const double* __restrict H, const double* __restrict U,
                                            const double* __restrict V, TileWork& w) const {
  const double *__restrict cc = &geo_.c[k0], *__restrict bx = &geo_.bx[k0], *__restrict by = &geo_.by[k0];
  const double *__restrict hxx = &geo_.hxx[k0], *__restrict hxy = &geo_.hxy[k0], *__restrict hyy = &geo_.hyy[k0];
  double *__restrict mu = w.row_mu.data(), *__restrict wt = w.row_w.data();
  const StepConstants K = constants();
#pragma omp simd
  for (int m = 0; m < n; ++m) {
    const MuParts p = start_parts(K, H[m], U[m], V[m], cc[m], bx[m], by[m], hxx[m], hxy[m], hyy[m]);
    mu[m] = p.mu;
    wt[m] = p.q;
  }
  for (int m = 0; m < n; ++m) wt[m] = start_weight(wt[m]);
}

}  // namespace runout::engine::sh2d_detail
