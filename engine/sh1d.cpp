#include "engine/sh1d.hpp"

#include "engine/stepping.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace runout::engine {

Channel1D Channel1D::uniform(int n, double dx, double x0, double zeta) {
  Channel1D c;
  c.n = n;
  c.dx = dx;
  c.x0 = x0;
  c.zeta.assign(n, zeta);
  c.kappa.assign(n, 0.0);
  return c;
}

Channel1D Channel1D::from_profile(int n, double dx, double x0, const std::function<double(double)>& zeta) {
  Channel1D c;
  c.n = n;
  c.dx = dx;
  c.x0 = x0;
  c.zeta.resize(n);
  c.kappa.resize(n);
  for (int i = 0; i < n; ++i) {
    const double x = c.centre(i);
    c.zeta[i] = zeta(x);
    c.kappa[i] = -(zeta(x + 0.5 * dx) - zeta(x - 0.5 * dx)) / dx;
  }
  return c;
}

void Hydrograph::at(double time, double& h_out, double& u_out) const {
  if (t.empty()) {
    h_out = 0;
    u_out = 0;
    return;
  }
  if (time <= t.front()) {
    h_out = h.front();
    u_out = u.front();
    return;
  }
  for (std::size_t k = 1; k < t.size(); ++k) {
    if (time <= t[k]) {
      const double w = (time - t[k - 1]) / (t[k] - t[k - 1]);
      h_out = h[k - 1] + w * (h[k] - h[k - 1]);
      u_out = u[k - 1] + w * (u[k] - u[k - 1]);
      return;
    }
  }
  h_out = h.back();
  u_out = u.back();
}

namespace {

constexpr int G = 3;  // ghost cells on each side

struct Work {
  std::vector<double> h, m, zeta, kappa, beta, sh, sm, hp, mp, Sh, Sm, sSh, sSm, r;
  explicit Work(int n)
      : h(n + 2 * G), m(n + 2 * G), zeta(n + 2 * G), kappa(n + 2 * G), beta(n + 2 * G),
        sh(n + 2 * G), sm(n + 2 * G), hp(n + 2 * G), mp(n + 2 * G), Sh(n + 2 * G), Sm(n + 2 * G),
        sSh(n + 2 * G), sSm(n + 2 * G), r(n + 2 * G) {}
};

void validate(const Channel1D& ch, const Sh1dConfig& cfg, const Sh1dState& s) {
  auto bad = [](const std::string& m) { throw std::invalid_argument("1D solver: " + m); };
  if (ch.n < 4) bad("the channel needs at least 4 cells");
  if (!(ch.dx > 0)) bad("cell size dx must be > 0");
  if ((int)ch.zeta.size() != ch.n || (int)ch.kappa.size() != ch.n) bad("zeta/kappa size differs from n");
  if ((int)s.h.size() != ch.n || (int)s.m.size() != ch.n) bad("initial state size differs from n");
  for (int i = 0; i < ch.n; ++i)
    if (!(s.h[i] >= 0) || !std::isfinite(s.m[i])) bad("initial depth must be finite and >= 0 (cell " + std::to_string(i) + ")");
  if (!(cfg.time.cfl > 0 && cfg.time.cfl <= 0.5)) bad("CFL number must lie in (0, 0.5]");
  if (!(cfg.time.t_end >= 0)) bad("end time must be >= 0");
  cfg.material.validate();
  if ((cfg.left == Boundary1D::inflow || cfg.right == Boundary1D::inflow) && cfg.inflow.t.empty())
    bad("an inflow boundary needs a hydrograph");
  if (cfg.gauge.record && !(cfg.gauge.xi >= ch.x0 && cfg.gauge.xi <= ch.x0 + ch.n * ch.dx))
    bad("the gauge at xi = " + std::to_string(cfg.gauge.xi) + " m lies outside the channel");
}

// The scheme's state and steps on one channel: ghosts, earth pressure, predictor, positivity
// limiter, corrector on the staggered cells and the average back onto the cells.
class Sh1dSolver final : public SteppingEngine {
 public:
  Sh1dSolver(const Channel1D& ch, const Sh1dConfig& cfg, const Sh1dState& init)
      : cfg_(cfg), n(ch.n), dx(ch.dx), x0(ch.x0), g(cfg.gravity), hdry(cfg.dry_depth), lim(cfg.limiter),
        open(cfg.left != Boundary1D::wall || cfg.right != Boundary1D::wall), curv(cfg.curvature ? 1.0 : 0.0), w(ch.n) {
    fr = cfg.material.friction();  // the law, resolved once (engine/friction)
    mu = fr.mu;
    ixi = fr.inv_xi;
    kap = cfg.material.earth_pressure == EarthPressure::active_passive;
    kact = kap ? k_x(cfg.material.phi, std::atan(mu), true) : 1.0;
    kpas = kap ? k_x(cfg.material.phi, std::atan(mu), false) : 1.0;
    for (int i = 0; i < n; ++i) {
      w.h[i + G] = init.h[i];
      w.m[i + G] = init.m[i];
      w.zeta[i + G] = ch.zeta[i];
      w.kappa[i + G] = ch.kappa[i];
    }
    // Ghost geometry: a wall is a mirror, so its ghosts carry the mirrored channel (inclination of the
    // opposite sign, same curvature) and the solution stays symmetric about the wall: no mass crosses
    // it. Open boundaries extend the edge geometry.
    for (int k = 0; k < G; ++k) {
      const bool lw = cfg.left == Boundary1D::wall, rw = cfg.right == Boundary1D::wall;
      w.zeta[G - 1 - k] = lw ? -ch.zeta[k] : ch.zeta[0];
      w.kappa[G - 1 - k] = lw ? ch.kappa[k] : ch.kappa[0];
      w.zeta[n + G + k] = rw ? -ch.zeta[n - 1 - k] : ch.zeta[n - 1];
      w.kappa[n + G + k] = rw ? ch.kappa[n - 1 - k] : ch.kappa[n - 1];
    }
  }

  Sh1dResult run();
  // The engine's side of the run loop (engine/stepping.hpp).
  double time() const override { return t_; }
  long steps() const override { return r_.steps; }
  StepReport step(double t_end) override;
  double kinetic_energy() const override { return ke_; }

 private:
  double vel(double h, double m) const { return h > hdry ? m / h : 0.0; }
  double mass() const {
    double s = 0;
    for (int i = G; i < n + G; ++i) s += w.h[i];
    return s * dx;
  }
  void fill_ghosts(double t);
  void read_gauge() const;
  void fill_side(Boundary1D b, bool left, double t);
  void set_beta();
  double next_dt(double t, double t_end) const;
  template <MuForm M>
  void advance(double dt, double lam, Sh1dResult& r);
  template <MuForm M>
  void predictor(double dt, double lam);
  void positivity(double lam);
  template <MuForm M>
  void corrector(double dt, double lam, Sh1dResult& r);
  void average_back();
  // Slope of the discharge m = h u from the limited slopes of h and of the velocity (product rule):
  // limiting m itself would clip it where it peaks, ahead of the depth's crest, although the velocity
  // is smooth and monotone there. Dry neighbours leave the velocity slope at zero.
  double momentum_slope(const std::vector<double>& H, const std::vector<double>& M, double sh, int k) const {
    if (!(H[k - 1] > hdry && H[k] > hdry && H[k + 1] > hdry)) return limited_slope(lim, M[k] - M[k - 1], M[k + 1] - M[k]);
    const double u = M[k] / H[k];
    return u * sh + H[k] * limited_slope(lim, u - M[k - 1] / H[k - 1], M[k + 1] / H[k + 1] - u);
  }
  // Coulomb resistance per unit width, h mu g_n with g_n = (g cos(zeta) + kappa u^2)_+ and mu the
  // law's (constant, or mu(h, Fr) at this state, Fr = |u| / sqrt(g_n h)); Voellmy's drag is applied
  // implicitly (turbulent_factor).
  template <MuForm M>
  double resistance(double h, double u, double zeta, double kappa) const {
    const double gn = std::max(0.0, g * std::cos(zeta) + curv * kappa * u * u);
    if constexpr (M == MuForm::constant) return h * mu * gn;
    else return h * flow_mu<M == MuForm::hysteresis>(fr, h, std::abs(u), gn) * gn;
  }
  void drag(double& m, double h, double span) const {
    if (ixi > 0 && h > hdry) m *= turbulent_factor(std::abs(m) / h, h, span * g * ixi);
  }
  double flux_m(int k) const {
    const double h = w.hp[k], u = vel(h, w.mp[k]);
    return w.mp[k] * u + 0.5 * w.beta[k] * h * h;
  }
  double src(double h, int k) const { return h * g * std::sin(w.zeta[k]); }
  double scale(int k) const {  // limiter factor for the flux through x_k
    if (w.mp[k] > 0) return w.r[k - 1];
    if (w.mp[k] < 0) return w.r[k];
    return 1.0;
  }

  const Sh1dConfig& cfg_;
  const int n;
  const double dx, x0, g, hdry;
  const Limiter lim;
  const bool open;
  const double curv;
  BasalFriction fr;
  double mu = 0, ixi = 0, kact = 1, kpas = 1;
  bool kap = false;
  Work w;
  double t_ = 0, ke_ = 0;  // the time reached, the last step's kinetic energy
  Sh1dResult r_;          // the run's figures so far
};

void Sh1dSolver::fill_side(Boundary1D b, bool left, double t) {
  for (int k = 0; k < G; ++k) {
    const int gi = left ? G - 1 - k : n + G + k;  // ghost index, k-th away from the edge
    const int mi = left ? G + k : n + G - 1 - k;   // mirror index inside
    const int ei = left ? G : n + G - 1;           // edge cell
    switch (b) {
      case Boundary1D::wall:
        w.h[gi] = w.h[mi];
        w.m[gi] = -w.m[mi];
        break;
      case Boundary1D::outflow:
        w.h[gi] = w.h[ei];
        w.m[gi] = w.m[ei];
        break;
      case Boundary1D::inflow: {
        // The hydrograph state holds at the boundary face: the ghosts are the inside reflected
        // through it (w_g = 2 w_in - w_mirror), so that the piecewise-linear solution passes
        // through the prescribed depth and discharge there (second order at the boundary).
        double hi, ui;
        cfg_.inflow.at(t, hi, ui);
        const double qi = hi * (left ? ui : -ui);
        w.h[gi] = std::max(0.0, 2 * hi - w.h[mi]);
        w.m[gi] = w.h[gi] > 0 ? 2 * qi - w.m[mi] : 0.0;
        break;
      }
    }
  }
}

void Sh1dSolver::fill_ghosts(double t) {
  fill_side(cfg_.left, true, t);
  fill_side(cfg_.right, false, t);
}

// Per-cell earth pressure: active where the flow extends (du/dxi >= 0).
void Sh1dSolver::set_beta() {
  for (int k = 1; k < n + 2 * G - 1; ++k) {
    double K = 1.0;
    if (kap) K = (vel(w.h[k + 1], w.m[k + 1]) - vel(w.h[k - 1], w.m[k - 1]) >= 0) ? kact : kpas;
    w.beta[k] = K * g * std::cos(w.zeta[k]);
  }
  w.beta[0] = w.beta[1];
  w.beta[n + 2 * G - 1] = w.beta[n + 2 * G - 2];
}

double Sh1dSolver::next_dt(double t, double t_end) const {
  const auto& tc = cfg_.time;
  double amax = 0;
  for (int k = 0; k < n + 2 * G; ++k)
    amax = std::max(amax, std::abs(vel(w.h[k], w.m[k])) + std::sqrt(w.beta[k] * std::max(w.h[k], 0.0)));
  double dt = amax > 0 ? tc.cfl * dx / amax : tc.dt_max;
  dt = std::min({dt, tc.dt_max, t_end - t});
  if (!(dt > 0) || !std::isfinite(dt)) dt = t_end - t;
  return dt;
}

// One step of the scheme, with the friction coefficient's form M.
template <MuForm M>
void Sh1dSolver::advance(double dt, double lam, Sh1dResult& r) {
  predictor<M>(dt, lam);
  positivity(lam);
  corrector<M>(dt, lam, r);
  average_back();
}

// Predictor (4.78): limited slopes and a half step with the flux Jacobian (4.79, 4.86); the friction
// (its load and mu) from the state at t.
template <MuForm M>
void Sh1dSolver::predictor(double dt, double lam) {
  for (int k = 1; k < n + 2 * G - 1; ++k) {
    w.sh[k] = limited_slope(lim, w.h[k] - w.h[k - 1], w.h[k + 1] - w.h[k]);
    w.sm[k] = momentum_slope(w.h, w.m, w.sh[k], k);
    const double h = w.h[k], u = vel(h, w.m[k]), b = w.beta[k];
    w.hp[k] = std::max(0.0, h - 0.5 * lam * w.sm[k]);
    double mp = w.m[k] - 0.5 * lam * ((b * h - u * u) * w.sh[k] + 2.0 * u * w.sm[k]) +
                0.5 * dt * h * g * std::sin(w.zeta[k]);
    double dummy = 0;
    apply_friction(mp, dummy, std::abs(mp), 0.5 * dt * resistance<M>(h, u, w.zeta[k], w.kappa[k]));
    drag(mp, h, 0.5 * dt);
    w.mp[k] = mp;
  }
}

// The predicted values at the cell centres x_k are the fluxes through the faces of the staggered
// cells [x_k, x_k+1]. Draining-time limiter: no staggered cell sends out more mass than it holds;
// the factor of the sending cell scales the whole flux, which keeps mass conservative.
void Sh1dSolver::positivity(double lam) {
  for (int k = 1; k < n + 2 * G - 2; ++k) {
    const double content = 0.5 * (w.h[k] + w.h[k + 1]) + (w.sh[k] - w.sh[k + 1]) / 8.0;
    const double out = lam * (std::max(w.mp[k + 1], 0.0) + std::max(-w.mp[k], 0.0));
    w.r[k] = out > content ? std::max(content, 0.0) / out : 1.0;
  }
  w.r[0] = w.r[n + 2 * G - 2] = 1.0;
}

// Corrector (4.73, 4.74, 4.77, 4.80) on the staggered cell between k and k+1.
template <MuForm M>
void Sh1dSolver::corrector(double dt, double lam, Sh1dResult& r) {
  for (int k = 1; k < n + 2 * G - 2; ++k) {
    const double s0 = scale(k), s1 = scale(k + 1);
    double Sh = 0.5 * (w.h[k] + w.h[k + 1]) + (w.sh[k] - w.sh[k + 1]) / 8.0 - lam * (s1 * w.mp[k + 1] - s0 * w.mp[k]);
    double Sm = 0.5 * (w.m[k] + w.m[k + 1]) + (w.sm[k] - w.sm[k + 1]) / 8.0 - lam * (s1 * flux_m(k + 1) - s0 * flux_m(k));
    const double hq1 = std::max(0.0, w.hp[k] + 0.25 * w.sh[k]);
    const double hq3 = std::max(0.0, w.hp[k + 1] - 0.25 * w.sh[k + 1]);
    Sm += 0.5 * dt * (src(hq1, k) + src(hq3, k + 1));
    if (Sh < 0) {  // round-off only, after the limiter above
      ++r.positivity_clips;
      r.positivity_mass -= Sh * dx;
      Sh = 0;
    }
    // Friction at the half step (midpoint rule, second order), bounded so it never reverses u.
    const double uq1 = vel(w.hp[k], w.mp[k]), uq3 = vel(w.hp[k + 1], w.mp[k + 1]);
    const double R = 0.5 * (resistance<M>(hq1, uq1, w.zeta[k], w.kappa[k]) +
                            resistance<M>(hq3, uq3, w.zeta[k + 1], w.kappa[k + 1]));
    double dummy = 0;
    apply_friction(Sm, dummy, std::abs(Sm), dt * R);
    drag(Sm, Sh, dt);
    w.Sh[k] = Sh;
    w.Sm[k] = Sm;
  }
}

// Average back onto the cells: cell k lies between staggered cells k-1 and k.
void Sh1dSolver::average_back() {
  for (int k = 2; k < n + 2 * G - 3; ++k) {
    w.sSh[k] = limited_slope(lim, w.Sh[k] - w.Sh[k - 1], w.Sh[k + 1] - w.Sh[k]);
    w.sSm[k] = momentum_slope(w.Sh, w.Sm, w.sSh[k], k);
  }
  for (int k = G; k < n + G; ++k) {
    const double h = 0.5 * (w.Sh[k - 1] + w.Sh[k]) - (w.sSh[k] - w.sSh[k - 1]) / 8.0;
    const double m = 0.5 * (w.Sm[k - 1] + w.Sm[k]) - (w.sSm[k] - w.sSm[k - 1]) / 8.0;
    w.h[k] = h;
    w.m[k] = h > hdry ? m : 0.0;
  }
}

void Sh1dSolver::read_gauge() const {
  if (!cfg_.gauge.record) return;
  const double s = std::clamp((cfg_.gauge.xi - x0) / dx - 0.5, 0.0, double(n - 1));
  const int i = std::min(int(s), n - 2);
  const double a = s - i;
  const double h = (1 - a) * w.h[i + G] + a * w.h[i + 1 + G], m = (1 - a) * w.m[i + G] + a * w.m[i + 1 + G];
  cfg_.gauge.record(t_, h, vel(h, m));
}

StepReport Sh1dSolver::step(double t_end) {
  Sh1dResult& r = r_;
  fill_ghosts(t_);
  set_beta();
  const double dt = next_dt(t_, t_end);
  const double lam = dt / dx;
  const double mass_before = open ? mass() : 0.0;
  switch (fr.form()) {
    case MuForm::constant: advance<MuForm::constant>(dt, lam, r); break;
    case MuForm::flow: advance<MuForm::flow>(dt, lam, r); break;
    case MuForm::hysteresis: advance<MuForm::hysteresis>(dt, lam, r); break;
  }
  t_ += dt;
  ++r.steps;
  if (open) r.boundary_exchange += mass() - mass_before;
  read_gauge();
  double ke = 0, umax = 0;
  for (int i = 0; i < n; ++i) {
    const double h = w.h[i + G], u = vel(h, w.m[i + G]);
    r.max_depth[i] = std::max(r.max_depth[i], h);
    r.max_speed[i] = std::max(r.max_speed[i], std::abs(u));
    ke += 0.5 * h * u * u * dx;
    umax = std::max(umax, std::abs(u));
  }
  ke_ = ke;
  StepReport rep;
  rep.t = t_;
  rep.dt = dt;
  rep.mass = mass();
  rep.kinetic_energy = ke;
  rep.max_speed = umax;
  rep.active_fraction = 1.0;
  return rep;
}

Sh1dResult Sh1dSolver::run() {
  const auto wall0 = std::chrono::steady_clock::now();
  r_.max_depth.assign(n, 0.0);
  r_.max_speed.assign(n, 0.0);
  r_.mass_initial = mass();
  read_gauge();
  const auto& tc = cfg_.time;
  LoopSchedule schedule;
  schedule.t_end = tc.t_end;
  schedule.stop_fraction = tc.stop_fraction;
  schedule.max_steps = tc.max_steps;
  schedule.progress_every = tc.progress_every;
  LoopHooks hooks;
  hooks.progress = tc.progress;
  LoopState loop;
  r_.stop = run_steps(*this, schedule, loop, hooks, false);
  r_.t = t_;
  r_.state.h.assign(w.h.begin() + G, w.h.begin() + G + n);
  r_.state.m.assign(w.m.begin() + G, w.m.begin() + G + n);
  r_.mass_final = mass();
  r_.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return std::move(r_);
}

}  // namespace

Sh1dResult run_sh1d(const Channel1D& ch, const Sh1dConfig& cfg, Sh1dState init) {
  validate(ch, cfg, init);
  Sh1dSolver s(ch, cfg, init);
  return s.run();
}

}  // namespace runout::engine
