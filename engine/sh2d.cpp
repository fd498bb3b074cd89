#include "engine/sh2d.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace runout::engine {

SurfaceGeometry SurfaceGeometry::from(const Terrain2D& t) {
  SurfaceGeometry s;
  const int nx = t.nx, ny = t.ny;
  const std::size_t n = t.cells();
  s.bx.assign(n, 0);
  s.by.assign(n, 0);
  s.hxx.assign(n, 0);
  s.hxy.assign(n, 0);
  s.hyy.assign(n, 0);
  s.c.assign(n, 1);
  auto z = [&](int i, int j) {
    i = std::clamp(i, 0, nx - 1);
    j = std::clamp(j, 0, ny - 1);
    return t.z[std::size_t(j) * nx + i];
  };
  // Centred differences inside, one-sided at the edges (second derivatives copied from inside).
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t k = std::size_t(j) * nx + i;
      const int il = std::max(i - 1, 0), ir = std::min(i + 1, nx - 1);
      const int jl = std::max(j - 1, 0), jr = std::min(j + 1, ny - 1);
      s.bx[k] = ir > il ? (z(ir, j) - z(il, j)) / ((ir - il) * t.dx) : 0.0;
      s.by[k] = jr > jl ? (z(i, jr) - z(i, jl)) / ((jr - jl) * t.dy) : 0.0;
      const int ic = std::clamp(i, 1, std::max(nx - 2, 0)), jc = std::clamp(j, 1, std::max(ny - 2, 0));
      if (nx >= 3) s.hxx[k] = (z(ic + 1, j) - 2 * z(ic, j) + z(ic - 1, j)) / (t.dx * t.dx);
      if (ny >= 3) s.hyy[k] = (z(i, jc + 1) - 2 * z(i, jc) + z(i, jc - 1)) / (t.dy * t.dy);
      if (nx >= 3 && ny >= 3)
        s.hxy[k] = (z(ic + 1, jc + 1) - z(ic + 1, jc - 1) - z(ic - 1, jc + 1) + z(ic - 1, jc - 1)) /
                   (4 * t.dx * t.dy);
      s.c[k] = 1.0 / std::sqrt(1.0 + s.bx[k] * s.bx[k] + s.by[k] * s.by[k]);
    }
  return s;
}

Sh2dState state_from_normal_depth(const Terrain2D& terrain, const std::vector<double>& h) {
  if (h.size() != terrain.cells()) throw std::invalid_argument("initial depth: size differs from the terrain grid");
  const auto geo = SurfaceGeometry::from(terrain);
  Sh2dState s;
  s.H.resize(h.size());
  s.HU.assign(h.size(), 0.0);
  s.HV.assign(h.size(), 0.0);
  for (std::size_t k = 0; k < h.size(); ++k) s.H[k] = h[k] / geo.c[k];
  return s;
}

std::vector<double> normal_depth(const Terrain2D& terrain, const Sh2dState& s) {
  const auto geo = SurfaceGeometry::from(terrain);
  std::vector<double> h(s.H.size());
  for (std::size_t k = 0; k < h.size(); ++k) h[k] = s.H[k] * geo.c[k];
  return h;
}

namespace {

void validate(const Terrain2D& t, const Sh2dConfig& cfg, const Sh2dState& s) {
  auto bad = [](const std::string& m) { throw std::invalid_argument("2D solver: " + m); };
  if (t.nx < 1 || t.ny < 1) bad("terrain grid is empty");
  if (!(t.dx > 0 && t.dy > 0)) bad("cell sizes dx, dy must be > 0");
  if (t.z.size() != t.cells()) bad("terrain elevation size differs from nx * ny");
  for (double v : t.z)
    if (!std::isfinite(v)) bad("terrain elevations must be finite (fill nodata before the engine)");
  if (s.H.size() != t.cells() || s.HU.size() != t.cells() || s.HV.size() != t.cells())
    bad("initial state size differs from the terrain grid");
  for (std::size_t k = 0; k < s.H.size(); ++k)
    if (!(s.H[k] >= 0) || !std::isfinite(s.HU[k]) || !std::isfinite(s.HV[k]))
      bad("initial depth must be finite and >= 0 (cell " + std::to_string(k) + ")");
  if (!(cfg.time.cfl > 0 && cfg.time.cfl <= 0.5)) bad("CFL number must lie in (0, 0.5]");
  if (!(cfg.time.t_end >= 0)) bad("end time must be >= 0");
  if (cfg.tile < 4) bad("tile size must be >= 4 cells");
  cfg.material.validate();
}

struct Face {
  double f0, f1, f2;
};

class Solver {
 public:
  Solver(const Terrain2D& t, const Sh2dConfig& cfg, Sh2dState s)
      : t_(t), cfg_(cfg), geo_(SurfaceGeometry::from(t)), nx_(t.nx), ny_(t.ny), n_(t.cells()),
        T_(cfg.tile), ntx_((nx_ + T_ - 1) / T_), nty_((ny_ + T_ - 1) / T_), ntiles_(ntx_ * nty_),
        H_(std::move(s.H)), HU_(std::move(s.HU)), HV_(std::move(s.HV)) {
    g_ = cfg.gravity;
    mu_ = cfg.material.coulomb_coefficient();
    ixi_ = cfg.material.inv_xi();
    kap_ = cfg.material.earth_pressure == EarthPressure::active_passive;
    if (kap_) {
      const double d = std::atan(mu_), phi = cfg.material.phi;
      kx_[0] = k_x(phi, d, true);
      kx_[1] = k_x(phi, d, false);
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) ky_[a][b] = k_y(kx_[a], d, b == 0);
    }
    for (auto* v : {&sHx_, &sux_, &svx_, &sHy_, &suy_, &svy_, &Hp_, &Up_, &Vp_}) v->assign(n_, 0.0);
    held_.assign(n_, 0);
    U_.resize(n_);
    V_.resize(n_);
    for (std::size_t k = 0; k < n_; ++k) {
      U_[k] = vel(H_[k], HU_[k]);
      V_[k] = vel(H_[k], HV_[k]);
    }
    r_.assign(n_, 1.0);
    Pxx_.resize(n_);
    Pxy_.resize(n_);
    Pyy_.resize(n_);
    Ps_.resize(n_);
    for (std::size_t k = 0; k < n_; ++k) set_pressure(k, 1.0, 1.0, 1.0, 0.0);
    Fx_.assign(std::size_t(nx_ + 1) * ny_, Face{0, 0, 0});
    Fy_.assign(std::size_t(ny_ + 1) * nx_, Face{0, 0, 0});
    tile_mass_.assign(ntiles_, 0);
    tile_ke_.assign(ntiles_, 0);
    tile_speed_.assign(ntiles_, 0);
    tile_rate_.assign(ntiles_, 0);
    tile_out_.assign(ntiles_, 0);
    tile_travel_.assign(ntiles_, 0);
    tile_limited_.assign(ntiles_, 0);
    tile_wet_.assign(ntiles_, 0);
    active_flag_.assign(ntiles_, 0);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    hz_.max_depth.assign(n_, 0);
    hz_.max_speed.assign(n_, 0);
    hz_.max_pressure.assign(n_, 0);
    hz_.arrival_time.assign(n_, nan);
    // Initial tile sums, wet flags, wave speeds.
    for (int tt = 0; tt < ntiles_; ++tt) tile_scan(tt);
    for (std::size_t k = 0; k < n_; ++k) record_hazard(k, 0.0);
    rebuild_active();
  }

  Sh2dResult run();

 private:
  std::size_t idx(int i, int j) const { return std::size_t(j) * nx_ + i; }
  void tile_range(int tt, int& i0, int& i1, int& j0, int& j1) const {
    const int ti = tt % ntx_, tj = tt / ntx_;
    i0 = ti * T_;
    i1 = std::min(i0 + T_, nx_);
    j0 = tj * T_;
    j1 = std::min(j0 + T_, ny_);
  }
  bool tile_active(int ti, int tj) const {
    return ti >= 0 && tj >= 0 && ti < ntx_ && tj < nty_ && active_flag_[tj * ntx_ + ti];
  }
  double vel(double H, double M) const { return H > cfg_.dry_depth ? M / H : 0.0; }

  // Pi = g [c^4 Kx d d^T + c^2 Ky s s^T], d the downslope unit vector (or (dx, dy) on flat ground).
  void set_pressure(std::size_t k, double Kx, double Ky, double ddx, double ddy) {
    const double bx = geo_.bx[k], by = geo_.by[k], c = geo_.c[k], gb = std::hypot(bx, by);
    if (gb > 1e-12) {
      ddx = bx / gb;
      ddy = by / gb;
    }
    const double a = g_ * c * c * c * c * Kx, b = g_ * c * c * Ky;
    Pxx_[k] = a * ddx * ddx + b * ddy * ddy;
    Pxy_[k] = (a - b) * ddx * ddy;
    Pyy_[k] = a * ddy * ddy + b * ddx * ddx;
    Ps_[k] = std::sqrt(Pxx_[k]) / t_.dx + std::sqrt(Pyy_[k]) / t_.dy;
  }

  // Driving acceleration factor (g + Q)_+ with Q = U^T Hess(b) U.
  // The normal reaction keeps the flow on the surface and always includes Q: it turns the velocity
  // in curved terrain without loss of energy. The option `curvature` only decides whether the
  // centrifugal part raises the basal friction (as in eq. 3.48), as in the 1D solver.
  double normal_g(std::size_t k, double U, double V) const {
    const double Q = U * U * geo_.hxx[k] + 2 * U * V * geo_.hxy[k] + V * V * geo_.hyy[k];
    return std::max(0.0, g_ + Q);
  }
  // Resistance per horizontal area (magnitude of the friction force, 3D); gn = (g + Q)_+.
  double resistance(std::size_t k, double H, double U, double V, double gn) const {
    const double w = geo_.bx[k] * U + geo_.by[k] * V;
    const double load = cfg_.curvature ? gn : g_;
    return H * (mu_ * geo_.c[k] * load + g_ * ixi_ * (U * U + V * V + w * w));
  }
  double m3(std::size_t k, double MU, double MV) const {
    const double w = geo_.bx[k] * MU + geo_.by[k] * MV;
    return std::sqrt(MU * MU + MV * MV + w * w);
  }

  void tile_scan(int tt);
  void record_hazard(std::size_t k, double t);
  void rebuild_active();
  void predictor(int tt, double dt);
  template <Limiter L>
  void predictor_t(int tt, double dt);
  void faces(int tt);
  void positivity(int tt, double dt);
  void update(int tt, double t, double dt);
  Face x_face(int i, int j) const;
  Face y_face(int i, int j) const;

  const Terrain2D& t_;
  const Sh2dConfig& cfg_;
  SurfaceGeometry geo_;
  int nx_, ny_;
  std::size_t n_;
  int T_, ntx_, nty_, ntiles_;
  double g_ = 9.81, mu_ = 0, ixi_ = 0;
  bool kap_ = false;
  double kx_[2] = {1, 1}, ky_[2][2] = {{1, 1}, {1, 1}};
  std::vector<double> H_, HU_, HV_, U_, V_;  // U_, V_: velocity (zero where dry)
  std::vector<double> sHx_, sux_, svx_, sHy_, suy_, svy_, Hp_, Up_, Vp_, r_, Pxx_, Pxy_, Pyy_;
  std::vector<double> Ps_;  // sqrt(Pxx) / dx + sqrt(Pyy) / dy: the gravity-wave part of the CFL rate per sqrt(H)
  std::vector<std::uint8_t> held_;
  std::vector<Face> Fx_, Fy_;
  std::vector<double> tile_mass_, tile_ke_, tile_speed_, tile_rate_, tile_out_, tile_travel_;
  std::vector<long> tile_limited_;
  std::vector<std::uint8_t> tile_wet_, active_flag_;
  std::vector<int> active_;
  HazardMaps hz_;
};

void Solver::tile_scan(int tt) {
  int i0, i1, j0, j1;
  tile_range(tt, i0, i1, j0, j1);
  double mass = 0, ke = 0, vmax = 0, rate = 0;
  bool wet = false;
  for (int j = j0; j < j1; ++j)
    for (int i = i0; i < i1; ++i) {
      const std::size_t k = idx(i, j);
      const double H = H_[k], U = vel(H, HU_[k]), V = vel(H, HV_[k]);
      const double w = geo_.bx[k] * U + geo_.by[k] * V, sp2 = U * U + V * V + w * w;
      mass += H;
      ke += 0.5 * H * sp2;
      vmax = std::max(vmax, std::sqrt(sp2));
      const double Hs = std::max(H, 0.0);
      rate = std::max(rate, (std::abs(U) + std::sqrt(Pxx_[k] * Hs)) / t_.dx +
                                (std::abs(V) + std::sqrt(Pyy_[k] * Hs)) / t_.dy);
      wet = wet || H > cfg_.activation_depth;
    }
  tile_mass_[tt] = mass;
  tile_ke_[tt] = ke;
  tile_speed_[tt] = vmax;
  tile_rate_[tt] = rate;
  tile_wet_[tt] = wet;
}

void Solver::record_hazard(std::size_t k, double t) {
  const double H = H_[k], h = H * geo_.c[k];
  const double sp = H > cfg_.dry_depth ? m3(k, HU_[k], HV_[k]) / H : 0.0;
  hz_.max_depth[k] = std::max(hz_.max_depth[k], h);
  hz_.max_speed[k] = std::max(hz_.max_speed[k], sp);
  hz_.max_pressure[k] = std::max(hz_.max_pressure[k], cfg_.material.density * sp * sp);
  if (h > cfg_.arrival_threshold && std::isnan(hz_.arrival_time[k])) hz_.arrival_time[k] = t;
}

void Solver::rebuild_active() {
  std::vector<std::uint8_t> next(ntiles_, 0);
  for (int tj = 0; tj < nty_; ++tj)
    for (int ti = 0; ti < ntx_; ++ti) {
      bool a = !cfg_.skip_inactive;
      for (int dj = -1; dj <= 1 && !a; ++dj)
        for (int di = -1; di <= 1 && !a; ++di) {
          const int u = ti + di, v = tj + dj;
          if (u >= 0 && v >= 0 && u < ntx_ && v < nty_ && tile_wet_[v * ntx_ + u]) a = true;
        }
      next[tj * ntx_ + ti] = a;
    }
  active_.clear();
  for (int tt = 0; tt < ntiles_; ++tt) {
    if (active_flag_[tt] && !next[tt]) {
      // A tile leaves the computation: its thin remains (below the activation depth) stay where they
      // are, at rest, so that the volume is kept exactly.
      int i0, i1, j0, j1;
      tile_range(tt, i0, i1, j0, j1);
      for (int j = j0; j < j1; ++j)
        for (int i = i0; i < i1; ++i) HU_[idx(i, j)] = HV_[idx(i, j)] = U_[idx(i, j)] = V_[idx(i, j)] = 0.0;
      tile_ke_[tt] = 0;
      tile_speed_[tt] = 0;
    }
    active_flag_[tt] = next[tt];
    if (next[tt]) active_.push_back(tt);
  }
}

void Solver::predictor(int tt, double dt) {
  switch (cfg_.limiter) {
    case Limiter::minmod: return predictor_t<Limiter::minmod>(tt, dt);
    case Limiter::vanleer: return predictor_t<Limiter::vanleer>(tt, dt);
    case Limiter::superbee: return predictor_t<Limiter::superbee>(tt, dt);
  }
}

template <Limiter lim>
void Solver::predictor_t(int tt, double dt) {
  int i0, i1, j0, j1;
  tile_range(tt, i0, i1, j0, j1);
  const double hx = 0.5 * dt / t_.dx, hy = 0.5 * dt / t_.dy;
  for (int j = j0; j < j1; ++j)
    for (int i = i0; i < i1; ++i) {
      const std::size_t k = idx(i, j);
      const double H = H_[k], MU = HU_[k], MV = HV_[k];
      const double U = U_[k], V = V_[k];
      // Limited slopes of the depth and of the velocity (primitive variables: reconstructing the
      // velocity rather than the momentum keeps the speed of thin flow fronts; see docs/engine.md).
      double sHx = 0, sux = 0, svx = 0, sHy = 0, suy = 0, svy = 0;
      const double dry = cfg_.dry_depth;
      if (i > 0 && i < nx_ - 1) {
        const std::size_t l = k - 1, r = k + 1;
        sHx = limited_slope(lim, H - H_[l], H_[r] - H);
        if (H_[l] > dry && H_[r] > dry) {
          sux = limited_slope(lim, U - U_[l], U_[r] - U);
          svx = limited_slope(lim, V - V_[l], V_[r] - V);
        }
      }
      if (j > 0 && j < ny_ - 1) {
        const std::size_t b = k - nx_, a = k + nx_;
        sHy = limited_slope(lim, H - H_[b], H_[a] - H);
        if (H_[b] > dry && H_[a] > dry) {
          suy = limited_slope(lim, U - U_[b], U_[a] - U);
          svy = limited_slope(lim, V - V_[b], V_[a] - V);
        }
      }
      if (kap_) {
        // Active (extension) or passive (compression) along and across the slope.
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
        auto vel_at = [&](int ii, int jj, double& u, double& v) {
          ii = std::clamp(ii, 0, nx_ - 1);
          jj = std::clamp(jj, 0, ny_ - 1);
          const std::size_t q = idx(ii, jj);
          u = U_[q];
          v = V_[q];
        };
        double ue, ve, uw, vw, un, vn, us, vs;
        vel_at(i + 1, j, ue, ve);
        vel_at(i - 1, j, uw, vw);
        vel_at(i, j + 1, un, vn);
        vel_at(i, j - 1, us, vs);
        // d/dx and d/dy of the along (d) and across (s = (-dy, dx)) velocity components
        const double dUx = (ue - uw) / (2 * t_.dx), dVx = (ve - vw) / (2 * t_.dx);
        const double dUy = (un - us) / (2 * t_.dy), dVy = (vn - vs) / (2 * t_.dy);
        const double along = dx * (dx * dUx + dy * dVx) + dy * (dx * dUy + dy * dVy);
        const double across = -dy * (-dy * dUx + dx * dVx) + dx * (-dy * dUy + dx * dVy);
        const int ax = along >= 0 ? 0 : 1;
        set_pressure(k, kx_[ax], ky_[ax][across >= 0 ? 0 : 1], dx, dy);
      }
      const double Pxx = Pxx_[k], Pxy = Pxy_[k], Pyy = Pyy_[k];
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
      const bool rest = apply_friction(Up, Vp, m3(k, Up, Vp), 0.5 * dt * resistance(k, 1.0, U, V, gn));
      held_[k] = rest && MU == 0.0 && MV == 0.0;
      sHx_[k] = sHx;
      sux_[k] = sux;
      svx_[k] = svx;
      sHy_[k] = sHy;
      suy_[k] = suy;
      svy_[k] = svy;
      Hp_[k] = Hp;
      Up_[k] = Up;
      Vp_[k] = Vp;
    }
}

// Local speed of the central flux: an upper bound of the characteristic speeds |u| + c on both
// sides, max|u| + sqrt(max c^2) (one square root instead of two). Raising it to the dry-bed front
// speed u + 2c at wet/dry faces was tried: it adds diffusion and makes thin fronts lag more
// (docs/engine.md).
inline double face_speed(double uL, double c2L, double uR, double c2R) {
  return std::max(std::abs(uL), std::abs(uR)) + std::sqrt(std::max(c2L, c2R));
}

// A reconstructed state on one side of a face, in face coordinates: depth, normal and tangential
// velocity, and the pressure coefficients Pi_nn, Pi_nt of that side's cell.
struct FaceState {
  double H, un, ut, Pnn, Pnt;
};

// Ghost state beyond a domain edge: a wall mirrors the inside (normal velocity and the off-diagonal
// pressure coefficient change sign, so no mass crosses and the wall pushes only normally); an
// outflow boundary copies it.
inline FaceState boundary_ghost(const FaceState& in, Boundary2D b) {
  if (b == Boundary2D::wall) return {in.H, -in.un, in.ut, in.Pnn, -in.Pnt};
  return in;
}

// Central local-speed flux (Kurganov & Tadmor 2000) between the predicted face values, with
// a = max(|u_n| + sqrt(Pi_nn H)) over both sides. Returns (mass, normal momentum, tangential momentum).
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
Face Solver::x_face(int i, int j) const {
  // Face between cells (i-1, j) and (i, j); i in [0, nx]. Face states: depth H, normal velocity un,
  // tangential velocity ut, pressure coefficients Pnn (= Pxx) and Pnt (= Pxy).
  const bool west = i == 0, east = i == nx_;
  const std::size_t kl = west ? idx(0, j) : idx(i - 1, j), kr = east ? idx(nx_ - 1, j) : idx(i, j);
  FaceState L{}, R{};
  if (!west) L = {Hp_[kl] + 0.5 * sHx_[kl], Up_[kl] + 0.5 * sux_[kl], Vp_[kl] + 0.5 * svx_[kl], Pxx_[kl], Pxy_[kl]};
  if (!east) R = {Hp_[kr] - 0.5 * sHx_[kr], Up_[kr] - 0.5 * sux_[kr], Vp_[kr] - 0.5 * svx_[kr], Pxx_[kr], Pxy_[kr]};
  if (west) L = boundary_ghost(R, cfg_.west);
  if (east) R = boundary_ghost(L, cfg_.east);
  if (!west && !east && held_[kl] && held_[kr]) return held_face(L, R);
  return central_flux(L, R);
}

Face Solver::y_face(int i, int j) const {
  // Face between cells (i, j-1) and (i, j); j in [0, ny]. Normal = y: the flux components come back
  // as (mass, x-momentum, y-momentum).
  const bool south = j == 0, north = j == ny_;
  const std::size_t kl = south ? idx(i, 0) : idx(i, j - 1), kr = north ? idx(i, ny_ - 1) : idx(i, j);
  FaceState L{}, R{};
  if (!south) L = {Hp_[kl] + 0.5 * sHy_[kl], Vp_[kl] + 0.5 * svy_[kl], Up_[kl] + 0.5 * suy_[kl], Pyy_[kl], Pxy_[kl]};
  if (!north) R = {Hp_[kr] - 0.5 * sHy_[kr], Vp_[kr] - 0.5 * svy_[kr], Up_[kr] - 0.5 * suy_[kr], Pyy_[kr], Pxy_[kr]};
  if (south) L = boundary_ghost(R, cfg_.south);
  if (north) R = boundary_ghost(L, cfg_.north);
  const Face f = (!south && !north && held_[kl] && held_[kr]) ? held_face(L, R) : central_flux(L, R);
  return Face{f.f0, f.f2, f.f1};  // (mass, normal, tangential) -> (mass, x, y)
}

void Solver::faces(int tt) {
  int i0, i1, j0, j1;
  tile_range(tt, i0, i1, j0, j1);
  const int ti = tt % ntx_, tj = tt / ntx_;
  const bool left_in = tile_active(ti - 1, tj), right_in = tile_active(ti + 1, tj);
  const bool below_in = tile_active(ti, tj - 1), above_in = tile_active(ti, tj + 1);
  // x faces: the tile owns the left faces of its cells, and its right edge where no active tile does.
  const int ie = (i1 == nx_ || !right_in) ? i1 : i1 - 1;
  for (int j = j0; j < j1; ++j)
    for (int i = i0; i <= ie; ++i) {
      Face& f = Fx_[std::size_t(j) * (nx_ + 1) + i];
      const bool to_inactive = (i == i0 && i > 0 && !left_in) || (i == i1 && i < nx_);
      f = to_inactive ? Face{0, 0, 0} : x_face(i, j);
    }
  const int je = (j1 == ny_ || !above_in) ? j1 : j1 - 1;
  for (int j = j0; j <= je; ++j)
    for (int i = i0; i < i1; ++i) {
      Face& f = Fy_[std::size_t(j) * nx_ + i];
      const bool to_inactive = (j == j0 && j > 0 && !below_in) || (j == j1 && j < ny_);
      f = to_inactive ? Face{0, 0, 0} : y_face(i, j);
    }
}

void Solver::positivity(int tt, double dt) {
  // Draining-time limiter: a cell may not send out more volume than it holds.
  int i0, i1, j0, j1;
  tile_range(tt, i0, i1, j0, j1);
  long limited = 0;
  for (int j = j0; j < j1; ++j)
    for (int i = i0; i < i1; ++i) {
      const std::size_t k = idx(i, j);
      const double out = dt / t_.dx * (std::max(Fx_[std::size_t(j) * (nx_ + 1) + i + 1].f0, 0.0) +
                                       std::max(-Fx_[std::size_t(j) * (nx_ + 1) + i].f0, 0.0)) +
                         dt / t_.dy * (std::max(Fy_[std::size_t(j + 1) * nx_ + i].f0, 0.0) +
                                       std::max(-Fy_[std::size_t(j) * nx_ + i].f0, 0.0));
      double r = 1.0;
      if (out > H_[k]) {
        r = H_[k] / out;
        ++limited;
      }
      r_[k] = r;
    }
  tile_limited_[tt] += limited;
}

void Solver::update(int tt, double t, double dt) {
  int i0, i1, j0, j1;
  tile_range(tt, i0, i1, j0, j1);
  const double lx = dt / t_.dx, ly = dt / t_.dy, dry = cfg_.dry_depth;
  double out = 0, travel = 0, mass = 0, ke = 0, vmax = 0, rate = 0;
  bool wet = false;
  // Scaled face flux: the limiter factor of the upwind (sending) cell.
  auto scaled = [&](const Face& f, std::size_t left, std::size_t right, bool has_left, bool has_right) {
    double s = 1.0;
    if (f.f0 > 0 && has_left) s = r_[left];
    else if (f.f0 < 0 && has_right) s = r_[right];
    return Face{f.f0 * s, f.f1 * s, f.f2 * s};
  };
  for (int j = j0; j < j1; ++j)
    for (int i = i0; i < i1; ++i) {
      const std::size_t k = idx(i, j);
      const std::size_t fx = std::size_t(j) * (nx_ + 1) + i, fy = std::size_t(j) * nx_ + i;
      const Face w = scaled(Fx_[fx], k - 1, k, i > 0, true);
      const Face e = scaled(Fx_[fx + 1], k, k + 1, true, i < nx_ - 1);
      const Face s = scaled(Fy_[fy], k - nx_, k, j > 0, true);
      const Face nn = scaled(Fy_[fy + nx_], k, k + nx_, true, j < ny_ - 1);
      if (i == 0) out -= w.f0 * dt * t_.dy;
      if (i == nx_ - 1) out += e.f0 * dt * t_.dy;
      if (j == 0) out -= s.f0 * dt * t_.dx;
      if (j == ny_ - 1) out += nn.f0 * dt * t_.dx;
      double H = H_[k] - lx * (e.f0 - w.f0) - ly * (nn.f0 - s.f0);
      if (H < 0) H = 0;  // round-off only: the limiter above bounds the outflow by the content
      // Source at the half step (midpoint rule).
      const double Hp = Hp_[k], Up = Up_[k], Vp = Vp_[k];
      const double gn = normal_g(k, Up, Vp);
      const double drive = -Hp * geo_.c[k] * geo_.c[k] * gn;
      double MU = HU_[k] - lx * (e.f1 - w.f1) - ly * (nn.f1 - s.f1) + dt * drive * geo_.bx[k];
      double MV = HV_[k] - lx * (e.f2 - w.f2) - ly * (nn.f2 - s.f2) + dt * drive * geo_.by[k];
      double U = 0, V = 0, sp = 0;
      if (H > dry) {
        // Friction at the half step (midpoint rule), as a bounded impulse that never reverses u.
        const double M3 = m3(k, MU, MV), impulse = dt * resistance(k, Hp, Up, Vp, gn);
        apply_friction(MU, MV, M3, impulse);
        const double inv = 1.0 / H;
        U = MU * inv;
        V = MV * inv;
        sp = std::max(M3 - impulse, 0.0) * inv;  // surface speed after friction
      } else {
        MU = MV = 0;
      }
      H_[k] = H;
      HU_[k] = MU;
      HV_[k] = MV;
      U_[k] = U;
      V_[k] = V;
      if (cfg_.track_travel) travel += dt * std::sqrt(MU * MU + MV * MV);
      // Hazard maps and tile sums from the new state.
      const double h = H * geo_.c[k], sp2 = sp * sp;
      hz_.max_depth[k] = std::max(hz_.max_depth[k], h);
      hz_.max_speed[k] = std::max(hz_.max_speed[k], sp);
      hz_.max_pressure[k] = std::max(hz_.max_pressure[k], cfg_.material.density * sp2);
      if (h > cfg_.arrival_threshold && std::isnan(hz_.arrival_time[k])) hz_.arrival_time[k] = t + dt;
      mass += H;
      ke += 0.5 * H * sp2;
      vmax = std::max(vmax, sp);
      rate = std::max(rate, std::abs(U) / t_.dx + std::abs(V) / t_.dy + Ps_[k] * std::sqrt(H));
      wet = wet || H > cfg_.activation_depth;
    }
  tile_out_[tt] += out;
  tile_travel_[tt] += travel;
  tile_mass_[tt] = mass;
  tile_ke_[tt] = ke;
  tile_speed_[tt] = vmax;
  tile_rate_[tt] = rate;
  tile_wet_[tt] = wet;
}

Sh2dResult Solver::run() {
  const auto wall0 = std::chrono::steady_clock::now();
  const auto& tc = cfg_.time;
  Sh2dResult res;
  auto& d = res.diag;
  auto sum_tiles = [&](const std::vector<double>& v) {
    double s = 0;
    for (int tt = 0; tt < ntiles_; ++tt) s += v[tt];
    return s;
  };
  const double cell_area = t_.dx * t_.dy;
  d.volume_initial = sum_tiles(tile_mass_) * cell_area;
  double t = 0, active_sum = 0;
  const auto loop0 = std::chrono::steady_clock::now();
  while (t < tc.t_end) {
    if (d.steps >= tc.max_steps) {
      d.stop = StopReason::max_steps;
      break;
    }
    double rate = 0;
    for (int tt : active_) rate = std::max(rate, tile_rate_[tt]);
    double dt = rate > 0 ? tc.cfl / rate : tc.dt_max;
    dt = std::min({dt, tc.dt_max, tc.t_end - t});
    if (!(dt > 0) || !std::isfinite(dt)) dt = tc.t_end - t;
    const int na = int(active_.size());
    std::size_t ncells = 0;
    for (int tt : active_) {
      int i0, i1, j0, j1;
      tile_range(tt, i0, i1, j0, j1);
      ncells += std::size_t(i1 - i0) * (j1 - j0);
    }
#pragma omp parallel
    {
#pragma omp for schedule(static)
      for (int a = 0; a < na; ++a) predictor(active_[a], dt);
#pragma omp for schedule(static)
      for (int a = 0; a < na; ++a) faces(active_[a]);
#pragma omp for schedule(static)
      for (int a = 0; a < na; ++a) positivity(active_[a], dt);
#pragma omp for schedule(static)
      for (int a = 0; a < na; ++a) update(active_[a], t, dt);
    }
    t += dt;
    ++d.steps;
    d.cell_updates += double(ncells);
    const double frac = double(ncells) / double(n_);
    active_sum += frac;
    d.max_active_fraction = std::max(d.max_active_fraction, frac);
    rebuild_active();
    const double ke = sum_tiles(tile_ke_);
    d.kinetic_energy_peak = std::max(d.kinetic_energy_peak, ke * cell_area);
    double vmax = 0;
    for (int tt = 0; tt < ntiles_; ++tt) vmax = std::max(vmax, tile_speed_[tt]);
    d.max_speed = std::max(d.max_speed, vmax);
    if (tc.progress && d.steps % tc.progress_every == 0) {
      Progress p{t, dt, sum_tiles(tile_mass_) * cell_area, vmax, ke * cell_area, frac, d.steps};
      if (!tc.progress(p)) {
        d.stop = StopReason::cancelled;
        break;
      }
    }
    if (tc.stop_fraction > 0 && d.kinetic_energy_peak > 0 && ke * cell_area < tc.stop_fraction * d.kinetic_energy_peak) {
      d.stop = StopReason::kinetic_energy;
      break;
    }
  }
  d.loop_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - loop0).count();
  d.t = t;
  d.volume_final = sum_tiles(tile_mass_) * cell_area;
  d.volume_outflow = sum_tiles(tile_out_);
  d.mean_travel = d.volume_initial > 0 ? sum_tiles(tile_travel_) * cell_area / d.volume_initial : 0.0;
  for (int tt = 0; tt < ntiles_; ++tt) d.positivity_limited += tile_limited_[tt];
  d.mean_active_fraction = d.steps > 0 ? active_sum / double(d.steps) : 0.0;
  hz_.final_depth.resize(n_);
  for (std::size_t k = 0; k < n_; ++k) hz_.final_depth[k] = H_[k] * geo_.c[k];
  res.hazard = std::move(hz_);
  res.state.H = std::move(H_);
  res.state.HU = std::move(HU_);
  res.state.HV = std::move(HV_);
  d.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return res;
}

}  // namespace

Sh2dResult run_sh2d(const Terrain2D& terrain, const Sh2dConfig& config, Sh2dState initial) {
  validate(terrain, config, initial);
  Solver s(terrain, config, std::move(initial));
  return s.run();
}

}  // namespace runout::engine
