// The first half of one tile's step of the depth-averaged 2D scheme: the predictor to the half step
// (general loop and branch-free row kernel) and the central face fluxes (update.cpp: the rest).
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "engine/sh2d/solver.hpp"

namespace runout::engine::sh2d_detail {
namespace {

// Local speed of the central flux: an upper bound of the characteristic speeds |u| + c on both
// sides, max|u| + sqrt(max c^2) (one square root instead of two). Raising it to the dry-bed front
// speed u + 2c at wet/dry faces was tried: it adds diffusion and makes thin fronts lag more
// (docs/design/depth-averaged.md).
inline double face_speed(double uL, double c2L, double uR, double c2R) {
  return std::max(std::abs(uL), std::abs(uR)) + std::sqrt(std::max(c2L, c2R));
}

// Ghost state beyond a domain edge: a wall mirrors the inside (normal velocity and the off-diagonal
// pressure coefficient change sign, so no mass crosses and the wall pushes only normally); an
// outflow boundary copies it.
inline FaceState boundary_ghost(const FaceState& in, Boundary2D b) {
  if (b == Boundary2D::wall) return {in.H, -in.un, in.ut, in.Pnn, -in.Pnt};
  return in;
}

// Ghost state in a cell outside the domain: free outflow. The inside state is copied while it flows
// out; a flow towards the inside meets a mirror instead, so nothing comes in from where there is no
// terrain. `ghost_right`: the ghost lies on the face's right (upper) side.
inline FaceState outflow_ghost(const FaceState& in, bool ghost_right) {
  const bool leaving = ghost_right ? in.un >= 0 : in.un <= 0;
  return leaving ? in : FaceState{in.H, -in.un, in.ut, in.Pnn, -in.Pnt};
}

// Central local-speed flux (Kurganov & Tadmor 2000) between the predicted face values.
// Returns (mass, normal momentum, tangential momentum).
inline Face central_flux(const FaceState& L, const FaceState& R) {
  const double a = face_speed(L.un, L.Pnn * std::max(L.H, 0.0), R.un, R.Pnn * std::max(R.H, 0.0));
  const double mL = L.H * L.un, mR = R.H * R.un;
  return Face{0.5 * (mL + mR) - 0.5 * a * (R.H - L.H),
              0.5 * (mL * L.un + 0.5 * L.Pnn * L.H * L.H + mR * R.un + 0.5 * R.Pnn * R.H * R.H) - 0.5 * a * (mR - mL),
              0.5 * (mL * L.ut + 0.5 * L.Pnt * L.H * L.H + mR * R.ut + 0.5 * R.Pnt * R.H * R.H) -
                  0.5 * a * (R.H * R.ut - L.H * L.ut)};
}

// Between two cells that friction holds at rest: the pressure only, no numerical diffusion, so that
// material at rest stays exactly at rest.
inline Face held_face(const FaceState& L, const FaceState& R) {
  return Face{0.0, 0.25 * (L.Pnn * L.H * L.H + R.Pnn * R.H * R.H), 0.25 * (L.Pnt * L.H * L.H + R.Pnt * R.H * R.H)};
}

}  // namespace

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
  }
}

template <Limiter lim, Basal B>
void Solver::predictor_cells(TileWork& w, double dt) const {
  const auto &Hs = H_[cur_], &HUs = HU_[cur_], &HVs = HV_[cur_], &Us = U_[cur_], &Vs = V_[cur_];
  const double hx = 0.5 * dt / t_.dx, hy = 0.5 * dt / t_.dy, dry = cfg_.dry_depth;
  // Cells away from the domain's edges take the branch-free row kernel (K = 1, the default set-up);
  // which kernel a cell takes depends only on its position, so every tile that computes it gets the
  // same bits.
  const bool fast = !kap_;
  const int fa = std::max(w.bi0, 1), fb = std::min(w.bi0 + w.bw, nx_ - 1);
  for (int j = w.bj0; j < w.bj0 + w.bh; ++j)
    for (int i = w.bi0; i < w.bi0 + w.bw; ++i) {
      if (fast && j > 0 && j < ny_ - 1 && i >= fa && i < fb && !near_outside(idx(i, j))) {
        int e = i + 1;  // a run of cells for the row kernel
        while (e < fb && !near_outside(idx(e, j))) ++e;
        if constexpr (B == Basal::hysteresis) {
          const std::size_t k0 = idx(i, j);
          start_terms(e - i, k0, &Hs[k0], &Us[k0], &Vs[k0], w);
        }
        predictor_row<lim, B>(w, j, i, e, dt);
        i = e - 1;
        continue;
      }
      const std::size_t k = idx(i, j), q = w.at(i, j);
      const double H = Hs[k], MU = HUs[k], MV = HVs[k], U = Us[k], V = Vs[k];
      // Limited slopes of the depth and of the velocity (primitive variables: reconstructing the
      // velocity rather than the momentum keeps thin layers from producing spurious speeds).
      double sHx = 0, sux = 0, svx = 0, sHy = 0, suy = 0, svy = 0;
      const bool edge = near_outside(k);  // slopes only between cells of the domain
      if (i > 0 && i < nx_ - 1 && !(edge && (outside(i - 1, j) || outside(i + 1, j) || outside(i, j)))) {
        const std::size_t l = k - 1, r = k + 1;
        sHx = limited_slope(lim, H - Hs[l], Hs[r] - H);
        if (Hs[l] > dry && Hs[r] > dry) {
          sux = limited_slope(lim, U - Us[l], Us[r] - U);
          svx = limited_slope(lim, V - Vs[l], Vs[r] - V);
        }
      }
      if (j > 0 && j < ny_ - 1 && !(edge && (outside(i, j - 1) || outside(i, j + 1) || outside(i, j)))) {
        const std::size_t b = k - nx_, a = k + nx_;
        sHy = limited_slope(lim, H - Hs[b], Hs[a] - H);
        if (Hs[b] > dry && Hs[a] > dry) {
          suy = limited_slope(lim, U - Us[b], Us[a] - U);
          svy = limited_slope(lim, V - Vs[b], Vs[a] - V);
        }
      }
      double Pxx = Pxx_[k], Pxy = Pxy_[k], Pyy = Pyy_[k], Ps = Ps_[k];
      if (kap_) earth_pressure(k, i, j, U, V, Pxx, Pxy, Pyy, Ps);
      // Predictor to t + dt/2 (eq. 4.78 in primitive form, pressure coefficients frozen in the cell).
      const double gn = normal_g(k, U, V);
      const double acc = -geo_.c[k] * geo_.c[k] * gn;  // gravity + normal reaction per unit volume
      double Hp = H - hx * (U * sHx + H * sux) - hy * (V * sHy + H * svy);
      double Up = 0, Vp = 0;
      if (H > dry) {
        Up = U - hx * (U * sux + Pxx * sHx) - hy * (V * suy + Pxy * sHy) + 0.5 * dt * acc * geo_.bx[k];
        Vp = V - hx * (U * svx + Pxy * sHx) - hy * (V * svy + Pyy * sHy) + 0.5 * dt * acc * geo_.by[k];
      }
      // Keep the predicted face depths non-negative; where they are not, fall back to first order.
      if (Hp - 0.5 * std::abs(sHx) - 0.5 * std::abs(sHy) < 0) {
        sHx = sux = svx = sHy = suy = svy = 0;
        Hp = H;
        Up = H > dry ? U + 0.5 * dt * acc * geo_.bx[k] : 0.0;
        Vp = H > dry ? V + 0.5 * dt * acc * geo_.by[k] : 0.0;
      }
      // Friction with the load and mu of the state at t.
      const double M3 = m3(k, Up, Vp), imp = 0.5 * dt * resistance(k, 1.0, gn, basal_mu<B>(k, H, U, V, gn));
      const bool rest = apply_friction(Up, Vp, M3, imp);
      if (ixi_ > 0 && H > dry) {  // Voellmy drag over the half step, implicit
        const double f = turbulent_factor(std::max(M3 - imp, 0.0), H * geo_.c[k], 0.5 * dt * g_ * ixi_);
        Up *= f;
        Vp *= f;
      }
      w.held[q] = rest && MU == 0.0 && MV == 0.0 ? 1.0 : 0.0;
      w.sHx[q] = sHx;
      w.sux[q] = sux;
      w.svx[q] = svx;
      w.sHy[q] = sHy;
      w.suy[q] = suy;
      w.svy[q] = svy;
      w.Hp[q] = Hp;
      w.Up[q] = Up;
      w.Vp[q] = Vp;
      w.Pxx[q] = Pxx;
      w.Pxy[q] = Pxy;
      w.Pyy[q] = Pyy;
      w.Ps[q] = Ps;
    }
}

// Face state of cell q on the side `sign` (+1: its upper face, -1: its lower face) in face
// coordinates (normal, tangential): x faces use (U, V, Pxx), y faces (V, U, Pyy).
template <bool X>
inline FaceState side_state(const TileWork& w, std::size_t q, double sign) {
  if constexpr (X)
    return {w.Hp[q] + sign * 0.5 * w.sHx[q], w.Up[q] + sign * 0.5 * w.sux[q], w.Vp[q] + sign * 0.5 * w.svx[q],
            w.Pxx[q], w.Pxy[q]};
  else
    return {w.Hp[q] + sign * 0.5 * w.sHy[q], w.Vp[q] + sign * 0.5 * w.svy[q], w.Up[q] + sign * 0.5 * w.suy[q],
            w.Pyy[q], w.Pxy[q]};
}

template <bool X>
Face Solver::face(const TileWork& w, int ia, int ja, int ib, int jb, bool lo, bool hi, Boundary2D blo,
                  Boundary2D bhi) const {
  // Flux through the face between cells a (left/below) and b; lo/hi: the face is a domain edge.
  if (!lo && !hi && !w.all_active && cell_active(ia, ja) != cell_active(ib, jb)) return Face{0, 0, 0};
  const bool oa = !lo && w.has_outside && outside(ia, ja), ob = !hi && w.has_outside && outside(ib, jb);
  if (oa && ob) return Face{0, 0, 0};
  FaceState L{}, R{};
  if (!lo && !oa) L = side_state<X>(w, w.at(ia, ja), +1.0);
  if (!hi && !ob) R = side_state<X>(w, w.at(ib, jb), -1.0);
  if (lo) L = boundary_ghost(R, blo);
  if (hi) R = boundary_ghost(L, bhi);
  if (oa) return central_flux(outflow_ghost(R, false), R);
  if (ob) return central_flux(L, outflow_ghost(L, true));
  return (!lo && !hi && w.held[w.at(ia, ja)] != 0.0 && w.held[w.at(ib, jb)] != 0.0) ? held_face(L, R)
                                                                                      : central_flux(L, R);
}

// The interior faces of one box row (x) or between two box rows (y) in one branch-free loop the
// compiler can vectorise: the same arithmetic as side_state + central_flux / held_face. Cell
// pointers point at the right/upper cell of the first face; the left/lower cell is `s` before it.
// Outputs: mass, normal and tangential momentum flux.
RUNOUT_SIMD_CLONES void face_row(int n, std::ptrdiff_t s, const double* __restrict Hp, const double* __restrict sH,
                     const double* __restrict Un, const double* __restrict sUn, const double* __restrict Ut,
                     const double* __restrict sUt, const double* __restrict Pnn, const double* __restrict Pnt,
                     const double* __restrict held, double* __restrict o0, double* __restrict on,
                     double* __restrict ot) {
  for (int k = 0; k < n; ++k) {
    const std::ptrdiff_t r = k, l = k - s;
    const double HL = Hp[l] + 0.5 * sH[l], uL = Un[l] + 0.5 * sUn[l], tL = Ut[l] + 0.5 * sUt[l];
    const double HR = Hp[r] - 0.5 * sH[r], uR = Un[r] - 0.5 * sUn[r], tR = Ut[r] - 0.5 * sUt[r];
    const double a = std::max(std::abs(uL), std::abs(uR)) +
                     std::sqrt(std::max(Pnn[l] * std::max(HL, 0.0), Pnn[r] * std::max(HR, 0.0)));
    const double mL = HL * uL, mR = HR * uR;
    const double pL = 0.5 * Pnn[l] * HL * HL, pR = 0.5 * Pnn[r] * HR * HR;
    const double qL = 0.5 * Pnt[l] * HL * HL, qR = 0.5 * Pnt[r] * HR * HR;
    const double h = held[l] * held[r], m = 1.0 - h;  // 1 / 0 masks: exact selects, no branch
    o0[k] = m * (0.5 * (mL + mR) - 0.5 * a * (HR - HL));
    on[k] = m * (0.5 * (mL * uL + pL + mR * uR + pR) - 0.5 * a * (mR - mL)) + h * (0.5 * (pL + pR));
    ot[k] = m * (0.5 * (mL * tL + qL + mR * tR + qR) - 0.5 * a * (HR * tR - HL * tL)) + h * (0.5 * (qL + qR));
  }
}

// The predictor of the branch-free kind for cells (ia..ib-1, j), all away from the domain's edges,
// K = 1. Same arithmetic as the general loop in Solver::predictor_cells, written with 0/1
// masks instead of branches so that the compiler can vectorise it. B: the friction's kernel; without
// Voellmy's drag its factor would be exactly 1, and its square root and division are skipped.
template <Limiter lim, Basal B>
RUNOUT_SIMD_CLONES void Solver::predictor_row(TileWork& w, int j, int ia, int ib, double dt) const {
  constexpr bool Voellmy = B == Basal::voellmy;
  const double* __restrict Hs = H_[cur_].data();
  const double* __restrict HUs = HU_[cur_].data();
  const double* __restrict HVs = HV_[cur_].data();
  const double* __restrict Us = U_[cur_].data();
  const double* __restrict Vs = V_[cur_].data();
  const double *__restrict bx = geo_.bx.data(), *__restrict by = geo_.by.data(), *__restrict cc = geo_.c.data();
  const double *__restrict hxx = geo_.hxx.data(), *__restrict hxy = geo_.hxy.data(), *__restrict hyy = geo_.hyy.data();
  const double *__restrict Pxx = Pxx_.data(), *__restrict Pxy = Pxy_.data(), *__restrict Pyy = Pyy_.data();
  const double* __restrict Ps = Ps_.data();
  const std::size_t q0 = w.at(ia, j), k0 = idx(ia, j);
  double *__restrict oHx = &w.sHx[q0], *__restrict oux = &w.sux[q0], *__restrict ovx = &w.svx[q0];
  double *__restrict oHy = &w.sHy[q0], *__restrict ouy = &w.suy[q0], *__restrict ovy = &w.svy[q0];
  double *__restrict oHp = &w.Hp[q0], *__restrict oUp = &w.Up[q0], *__restrict oVp = &w.Vp[q0];
  double *__restrict oPxx = &w.Pxx[q0], *__restrict oPxy = &w.Pxy[q0], *__restrict oPyy = &w.Pyy[q0];
  double *__restrict oPs = &w.Ps[q0], *__restrict oheld = &w.held[q0];
  const double hx = 0.5 * dt / t_.dx, hy = 0.5 * dt / t_.dy, dry = cfg_.dry_depth, g = g_, mu = mu_, ixi = ixi_;
  const double qcap = qcap_;
  const double curv = cfg_.curvature ? 1.0 : 0.0;
  const BasalFriction fr = fr_;
  const double *__restrict rmu = w.row_mu.data(), *__restrict rwt = w.row_w.data();  // start_terms'
  const std::ptrdiff_t N = nx_;
  auto mm = [](double a, double b) { return limited_slope(lim, a, b); };
  const int n = ib - ia;
#pragma omp simd
  for (int t = 0; t < n; ++t) {
    const std::ptrdiff_t k = std::ptrdiff_t(k0) + t;
    const double H = Hs[k], U = Us[k], V = Vs[k];
    const double wx = std::min(Hs[k - 1], Hs[k + 1]) > dry ? 1.0 : 0.0;
    const double wy = std::min(Hs[k - N], Hs[k + N]) > dry ? 1.0 : 0.0;
    double sHx = mm(H - Hs[k - 1], Hs[k + 1] - H);
    double sux = wx * mm(U - Us[k - 1], Us[k + 1] - U), svx = wx * mm(V - Vs[k - 1], Vs[k + 1] - V);
    double sHy = mm(H - Hs[k - N], Hs[k + N] - H);
    double suy = wy * mm(U - Us[k - N], Us[k + N] - U), svy = wy * mm(V - Vs[k - N], Vs[k + N] - V);
    const double pxx = Pxx[k], pxy = Pxy[k], pyy = Pyy[k];
    const double gn = std::max(0.0, g + std::min(qcap, U * U * hxx[k] + 2 * U * V * hxy[k] + V * V * hyy[k]));
    const double c = cc[k], acc = -c * c * gn, wet = H > dry ? 1.0 : 0.0;
    const double Hp1 = H - hx * (U * sHx + H * sux) - hy * (V * sHy + H * svy);
    const double Up1 = wet * (U - hx * (U * sux + pxx * sHx) - hy * (V * suy + pxy * sHy) + 0.5 * dt * acc * bx[k]);
    const double Vp1 = wet * (V - hx * (U * svx + pxy * sHx) - hy * (V * svy + pyy * sHy) + 0.5 * dt * acc * by[k]);
    // First order where a predicted face depth would be negative.
    const double bad = Hp1 - 0.5 * std::abs(sHx) - 0.5 * std::abs(sHy) < 0 ? 1.0 : 0.0, good = 1.0 - bad;
    sHx *= good;
    sux *= good;
    svx *= good;
    sHy *= good;
    suy *= good;
    svy *= good;
    const double Hp = good * Hp1 + bad * H;
    double Up = good * Up1 + bad * (wet * (U + 0.5 * dt * acc * bx[k]));
    double Vp = good * Vp1 + bad * (wet * (V + 0.5 * dt * acc * by[k]));
    // Friction over the half step, bounded: the same numbers as apply_friction, then Voellmy's
    // drag implicitly (turbulent_factor; 1 without it). Load and mu of the state at t.
    const double load = curv * gn + (1.0 - curv) * g;
    double mu_k = mu;
    if constexpr (B == Basal::flow) {
      const double w0 = bx[k] * U + by[k] * V;
      mu_k = flow_mu<false>(fr, H * c, std::sqrt(U * U + V * V + w0 * w0), c * load);
    } else if constexpr (B == Basal::hysteresis) {
      mu_k = with_start(fr, rmu[t], rwt[t]);
    }
    const double imp = 0.5 * dt * (mu_k * c * load);
    const double wp = bx[k] * Up + by[k] * Vp;
    const double M3 = std::sqrt(Up * Up + Vp * Vp + wp * wp);
    const double f = std::max(0.0, 1.0 - imp / std::max(M3, 1e-300));
    const double rest = M3 <= imp ? 1.0 : 0.0;
    if constexpr (Voellmy) {
      const double ft = 2.0 / (1.0 + std::sqrt(1.0 + 4.0 * (0.5 * dt * g * ixi / std::max(H * c, 1e-300)) *
                                                         std::max(M3 - imp, 0.0)));
      Up *= f * ft;
      Vp *= f * ft;
    } else {
      Up *= f;
      Vp *= f;
    }
    oheld[t] = std::abs(HUs[k]) + std::abs(HVs[k]) == 0.0 ? rest : 0.0;
    oHx[t] = sHx;
    oux[t] = sux;
    ovx[t] = svx;
    oHy[t] = sHy;
    ouy[t] = suy;
    ovy[t] = svy;
    oHp[t] = Hp;
    oUp[t] = Up;
    oVp[t] = Vp;
    oPxx[t] = pxx;
    oPxy[t] = pxy;
    oPyy[t] = pyy;
    oPs[t] = Ps[k];
  }
}

// The start/stop kernel's friction of cells k0..k0+n-1 at depth H and velocity (U, V) (the row's
// values): mu without the start/stop term into w.row_mu, the term's weights q^kappa into w.row_w.
// The power only where a cell moves, slower than beta_s (start_weight), in a scalar loop of its own:
// the row kernels that read them stay vectorised. The same arithmetic as basal_mu.
RUNOUT_SIMD_CLONES void Solver::start_terms(int n, std::size_t k0, const double* __restrict H, const double* __restrict U,
                                            const double* __restrict V, TileWork& w) const {
  const double *__restrict cc = &geo_.c[k0], *__restrict bx = &geo_.bx[k0], *__restrict by = &geo_.by[k0];
  const double *__restrict hxx = &geo_.hxx[k0], *__restrict hxy = &geo_.hxy[k0], *__restrict hyy = &geo_.hyy[k0];
  double *__restrict mu = w.row_mu.data(), *__restrict wt = w.row_w.data();
  const double g = g_, qcap = qcap_, curv = cfg_.curvature ? 1.0 : 0.0;
  const BasalFriction fr = fr_;
#pragma omp simd
  for (int m = 0; m < n; ++m) {
    const double u = U[m], v = V[m], c = cc[m];
    const double gn = vmax(0.0, g + vmin(qcap, u * u * hxx[m] + 2 * u * v * hxy[m] + v * v * hyy[m]));
    const double load = curv * gn + (1.0 - curv) * g, w3 = bx[m] * u + by[m] * v;
    const MuParts p = flow_mu_parts(fr, H[m] * c, std::sqrt(u * u + v * v + w3 * w3), c * load);
    mu[m] = p.mu;
    wt[m] = p.q;
  }
  for (int m = 0; m < n; ++m) wt[m] = start_weight(wt[m]);
}

void Solver::faces(TileWork& w, int ci0, int ci1, int cj0, int cj1) const {
  // Every face of the cells (ci0..ci1-1, cj0..cj1-1) (the tile grown by one, clipped to the grid: what
  // the positivity limiter and the update read), from the box's predicted values. A face between an
  // active tile and an inactive one carries nothing: both its cells hold less than the activation
  // depth and the inactive side is not updated, so this keeps the volume exact.
  auto put_x = [&](int i, int j, const Face& f) {
    const std::size_t k = w.fx(i, j);
    w.Fx0[k] = f.f0;
    w.Fx1[k] = f.f1;
    w.Fx2[k] = f.f2;
  };
  auto put_y = [&](int i, int j, const Face& g) {  // g in (mass, normal, tangential)
    const std::size_t k = w.fy(i, j);
    w.Fy0[k] = g.f0;
    w.Fy1[k] = g.f2;
    w.Fy2[k] = g.f1;
  };
  // Faces between two cells of the domain take the branch-free row kernel where every tile around is
  // active and no cell is outside; the domain's edges and the rest the general function.
  const bool rows = w.all_active && !w.has_outside;
  const int xa = std::max(ci0, 1), xb = std::min(ci1, nx_ - 1);  // x faces [xa, xb] between two cells
  for (int j = cj0; j < cj1; ++j) {
    if (rows && xb >= xa) {
      const std::size_t q = w.at(xa, j), f = w.fx(xa, j);
      face_row(xb - xa + 1, 1, &w.Hp[q], &w.sHx[q], &w.Up[q], &w.sux[q], &w.Vp[q], &w.svx[q], &w.Pxx[q], &w.Pxy[q],
               &w.held[q], &w.Fx0[f], &w.Fx1[f], &w.Fx2[f]);
    }
    for (int i = ci0; i <= ci1; ++i) {
      if (rows && i == xa && xb >= xa) i = xb + 1;  // done above
      if (i > ci1) break;
      const bool west = i == 0, east = i == nx_;
      put_x(i, j, face<true>(w, i - 1, j, i, j, west, east, cfg_.west, cfg_.east));
    }
  }
  for (int j = cj0; j <= cj1; ++j) {  // y faces: the face below row j
    const bool south = j == 0, north = j == ny_;
    if (rows && !south && !north) {
      const std::size_t q = w.at(ci0, j), f = w.fy(ci0, j);
      face_row(ci1 - ci0, w.bw, &w.Hp[q], &w.sHy[q], &w.Vp[q], &w.svy[q], &w.Up[q], &w.suy[q], &w.Pyy[q], &w.Pxy[q],
               &w.held[q], &w.Fy0[f], &w.Fy2[f], &w.Fy1[f]);
      continue;
    }
    for (int i = ci0; i < ci1; ++i) put_y(i, j, face<false>(w, i, j - 1, i, j, south, north, cfg_.south, cfg_.north));
  }
}

// The cells of the tile that can change in this step: those within two cells (the scheme's stencil)
// of a cell holding material, as a box. Every other cell of the tile is empty and stays empty, bit
// for bit: its fluxes, sources and friction are all zero. Empty when the tile and its two-cell
// halo hold nothing.
CellBox Solver::material_box(int i0, int i1, int j0, int j1) const {
  if (!cfg_.skip_inactive || !cfg_.skip_empty) return CellBox{i0, i1, j0, j1};
  const auto& Hs = H_[cur_];
  const int xa = std::max(i0 - 2, 0), xb = std::min(i1 + 2, nx_), ya = std::max(j0 - 2, 0), yb = std::min(j1 + 2, ny_);
  int a0 = xb, a1 = xa - 1, b0 = yb, b1 = ya - 1;
  for (int j = ya; j < yb; ++j) {
    const double* row = &Hs[idx(0, j)];
    int first = xa;
    while (first < xb && !(row[first] > 0)) ++first;
    if (first == xb) continue;
    int last = xb - 1;
    while (!(row[last] > 0)) --last;
    a0 = std::min(a0, first);
    a1 = std::max(a1, last);
    b0 = std::min(b0, j);
    b1 = j;
  }
  if (a1 < a0) return CellBox{i0, i0, j0, j0};
  return CellBox{std::max(a0 - 2, i0), std::min(a1 + 3, i1), std::max(b0 - 2, j0), std::min(b1 + 3, j1)};
}

// Empties the tile's cells outside box c in the new time level, which still holds the state of the
// step before: the cells that may hold something there (filled_) and lie outside c. Afterwards the
// level's filled box is c.
void Solver::clear_outside(int tt, const CellBox& c) {
  const int nb = 1 - cur_;
  const CellBox o = filled_[nb][tt];
  auto clear = [&](int j, int a, int b) {
    if (b <= a) return;
    const std::size_t k = idx(a, j), n = std::size_t(b - a);
    for (auto* v : {&H_[nb], &HU_[nb], &HV_[nb], &U_[nb], &V_[nb]}) std::fill_n(v->begin() + std::ptrdiff_t(k), n, 0.0);
  };
  for (int j = o.j0; j < o.j1; ++j) {
    if (c.empty() || j < c.j0 || j >= c.j1) {
      clear(j, o.i0, o.i1);
      continue;
    }
    clear(j, o.i0, std::min(o.i1, c.i0));
    clear(j, std::max(o.i0, c.i1), o.i1);
  }
  filled_[nb][tt] = c;
}

// The whole tile may hold something in both time levels (set-up, a frozen tile, a secondary release).
void Solver::fill_whole(int tt) {
  int i0, i1, j0, j1;
  tile_range(tt, i0, i1, j0, j1);
  filled_[0][tt] = filled_[1][tt] = CellBox{i0, i1, j0, j1};
}

long Solver::step_tile(int tt, double t, double dt, TileWork& w) {
  int i0, i1, j0, j1;
  tile_range(tt, i0, i1, j0, j1);
  const CellBox c = material_box(i0, i1, j0, j1);
  clear_outside(tt, c);
  if (c.empty()) {  // nothing within reach: the tile's sums are those of an empty tile
    tile_mass_[tt] = tile_ke_[tt] = tile_speed_[tt] = tile_rate_[tt] = 0.0;
    tile_wet_[tt] = 0;
    return 0;
  }
  w.bi0 = std::max(c.i0 - 2, 0);
  w.bj0 = std::max(c.j0 - 2, 0);
  w.bw = std::min(c.i1 + 2, nx_) - w.bi0;
  w.bh = std::min(c.j1 + 2, ny_) - w.bj0;
  const int ti = tt % ntx_, tj = tt / ntx_;
  w.has_outside = box_out_[tt] != 0;
  w.all_active = true;
  for (int dj = -1; dj <= 1; ++dj)
    for (int di = -1; di <= 1; ++di) {
      const int u = ti + di, v = tj + dj;
      if (u >= 0 && v >= 0 && u < ntx_ && v < nty_ && !active_flag_[v * ntx_ + u]) w.all_active = false;
    }
  switch (cfg_.limiter) {
    case Limiter::minmod: predictor<Limiter::minmod>(w, dt); break;
    case Limiter::vanleer: predictor<Limiter::vanleer>(w, dt); break;
    case Limiter::superbee: predictor<Limiter::superbee>(w, dt); break;
  }
  faces(w, std::max(c.i0 - 1, 0), std::min(c.i1 + 1, nx_), std::max(c.j0 - 1, 0), std::min(c.j1 + 1, ny_));
  tile_limited_[tt] += positivity(w, c.i0, c.i1, c.j0, c.j1, dt);
  update(tt, w, c, t, dt);
  return long(c.i1 - c.i0) * (c.j1 - c.j0);
}

}  // namespace runout::engine::sh2d_detail
