// The depth-averaged 2D solver: set-up, the step over the active tiles, checkpoints, the engine's
// side of the run loop (Sh2dEngine) and the entry points run_sh2d.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "engine/sh2d/solver.hpp"

namespace runout::engine {
namespace sh2d_detail {
namespace {

void validate_resistance(const Terrain2D& t, const Sh2dConfig& cfg) {
  auto bad = [](const std::string& m) { throw std::invalid_argument("2D solver: resistance areas: " + m); };
  const ResistanceAreas& r = cfg.resistance;
  if (r.empty()) return;
  if (r.c.size() != t.cells() || (!r.k_det.empty() && r.k_det.size() != t.cells())) bad("field sizes differ from the grid");
  for (std::size_t k = 0; k < r.c.size(); ++k)
    if (!(r.c[k] >= 0 && std::isfinite(r.c[k])) || (!r.k_det.empty() && !(r.k_det[k] >= 0 && std::isfinite(r.k_det[k]))))
      bad("drag coefficient and detrainment must be finite and >= 0 (cell " + std::to_string(k) + ")");
  if (!(r.speed_min >= 0 && r.speed_min <= r.speed_max && r.depth_min >= 0 && r.depth_min <= r.depth_max))
    bad("the band needs 0 <= speed_min <= speed_max and 0 <= depth_min <= depth_max");
  if (cfg.material.friction().flow) bad("need a constant mu (Coulomb or Voellmy), not a flow-dependent friction law");
}

void validate_cover(const Terrain2D& t, const Sh2dConfig& cfg) {
  auto bad = [](const std::string& m) { throw std::invalid_argument("2D solver: erodible cover: " + m); };
  const ErodibleCover& e = cfg.cover;
  if (e.empty()) return;
  if (e.depth.size() != t.cells() || e.density.size() != t.cells()) bad("field sizes differ from the grid");
  for (std::size_t k = 0; k < e.depth.size(); ++k)
    if (!(e.depth[k] >= 0 && std::isfinite(e.depth[k])) || !(e.density[k] > 0 && std::isfinite(e.density[k])))
      bad("depth must be finite and >= 0 and density finite and > 0 (cell " + std::to_string(k) + ")");
  if (!e.ploughing && !(e.erosion_energy > 0 && std::isfinite(e.erosion_energy)))
    bad("the erosion energy e_b must be finite and > 0 (or ploughing)");
  if (cfg.material.friction().flow) bad("need a constant mu (Coulomb or Voellmy), not a flow-dependent friction law");
}

void validate_dams(const Terrain2D& t, const Sh2dConfig& cfg) {
  auto bad = [](const std::string& m) { throw std::invalid_argument("2D solver: dams: " + m); };
  const auto& d = cfg.dam_height;
  if (d.empty()) return;
  if (d.size() != t.cells()) bad("the dam heights' size differs from the grid");
  for (std::size_t k = 0; k < d.size(); ++k)
    if (!(d[k] >= 0 && d[k] <= 1000)) bad("a dam height must lie in [0, 1000] m (cell " + std::to_string(k) + ")");
}

void validate(const Terrain2D& t, const Sh2dConfig& cfg, const Sh2dState& s) {
  auto bad = [](const std::string& m) { throw std::invalid_argument("2D solver: " + m); };
  if (t.nx < 1 || t.ny < 1) bad("terrain grid is empty");
  if (!(t.dx > 0 && t.dy > 0)) bad("cell sizes dx, dy must be > 0");
  if (t.z.size() != t.cells()) bad("terrain elevation size differs from nx * ny");
  for (double v : t.z)
    if (!std::isfinite(v)) bad("terrain elevations must be finite (fill nodata before the engine)");
  if (s.H.size() != t.cells() || s.HU.size() != t.cells() || s.HV.size() != t.cells())
    bad("initial state size differs from the terrain grid");
  if (!t.outside.empty()) {
    if (t.outside.size() != t.cells()) bad("outside mask size differs from the terrain grid");
    for (std::size_t k = 0; k < t.cells(); ++k)
      if (t.outside[k] && s.H[k] != 0) bad("initial depth must be 0 in cells outside the domain (cell " + std::to_string(k) + ")");
  }
  for (std::size_t k = 0; k < s.H.size(); ++k)
    if (!(s.H[k] >= 0) || !std::isfinite(s.H[k]) || !std::isfinite(s.HU[k]) || !std::isfinite(s.HV[k]))
      bad("initial depth must be finite and >= 0 (cell " + std::to_string(k) + ")");
  if (!(cfg.time.cfl > 0 && cfg.time.cfl <= 0.5)) bad("CFL number must lie in (0, 0.5]");
  if (!(cfg.time.t_end >= 0)) bad("end time must be >= 0");
  if (cfg.tile < 4) bad("tile size must be >= 4 cells");
  if (!(cfg.curvature_cap >= 0)) bad("curvature cap must be >= 0");
  for (const auto& a : cfg.secondary) {
    if (a.cells.size() != a.depth.size()) bad("secondary release '" + a.name + "': cells and depths differ in number");
    for (std::size_t q = 0; q < a.cells.size(); ++q) {
      if (a.cells[q] >= t.cells()) bad("secondary release '" + a.name + "': a cell lies outside the grid");
      if (!(a.depth[q] > 0 && std::isfinite(a.depth[q]))) bad("secondary release '" + a.name + "': depths must be finite and > 0");
      if (!t.outside.empty() && t.outside[a.cells[q]]) bad("secondary release '" + a.name + "': a cell lies outside the domain");
    }
  }
  std::vector<std::uint8_t> taken(cfg.gauges.empty() ? 0 : t.cells(), 0);
  for (const auto& g : cfg.gauges) {
    if (g.cells.size() != g.sides.size()) bad("flux gauge '" + g.name + "': cells and sides differ in number");
    for (std::size_t k : g.cells) {
      if (k >= t.cells()) bad("flux gauge '" + g.name + "': a cell lies outside the grid");
      if (taken[k]++) bad("flux gauge '" + g.name + "': a cell belongs to two gauges (crest lines of two dams cross)");
    }
  }
  validate_resistance(t, cfg);
  validate_cover(t, cfg);
  validate_dams(t, cfg);
  cfg.material.validate();
}

}  // namespace

Solver::Solver(const Terrain2D& t, const Sh2dConfig& cfg, Sh2dState s)
    : t_(t), cfg_(cfg), geo_(SurfaceGeometry::from(t)), nx_(t.nx), ny_(t.ny), n_(t.cells()),
      T_(cfg.tile), ntx_((nx_ + T_ - 1) / T_), nty_((ny_ + T_ - 1) / T_), ntiles_(ntx_ * nty_) {
  g_ = cfg.gravity;
  qcap_ = cfg.curvature_cap * cfg.gravity;
  // The friction law, resolved once: its coefficients enter the kernels (engine/friction), and its
  // form picks them.
  fr_ = cfg.material.friction();
  mu_ = fr_.mu;
  ixi_ = fr_.inv_xi;
  switch (fr_.form()) {
    case MuForm::constant: basal_ = ixi_ > 0 ? Basal::voellmy : Basal::coulomb; break;
    case MuForm::flow: basal_ = Basal::flow; break;
    case MuForm::hysteresis: basal_ = Basal::hysteresis; break;
  }
  if (fr_.flow && ixi_ > 0) throw std::logic_error("2D solver: the kernels of mu(h, Fr) have no turbulent drag (1/xi = 0)");
  if (!cfg.resistance.empty() || !cfg.cover.empty()) {  // a constant mu (validate): Voellmy's kernels with the ground's
    const ResistanceAreas& r = cfg.resistance;
    const ErodibleCover& e = cfg.cover;
    basal_ = Basal::ground;
    cres_ = r.empty() ? std::vector<double>(n_, 0.0) : r.c;
    kdet_ = r.k_det.empty() ? std::vector<double>(n_, 0.0) : r.k_det;
    const double rho = cfg.material.density;
    ground_ = GroundRule{r.speed_min, r.speed_max, r.depth_min, r.depth_max, r.detrainment ? 1.0 : 0.0, 1.0 / rho,
                         e.ploughing ? 0.0 : 1.0 / e.erosion_energy, e.ploughing ? 1.0 : 0.0, cfg.flow_threshold};
    det_.assign(n_, 0.0);
    cover_.assign(n_, 0.0);  // the cover's mass per bed area rho_c d as flow volume per horizontal area
    if (!e.empty())
      for (std::size_t k = 0; k < n_; ++k) cover_[k] = e.density[k] * e.depth[k] / (rho * geo_.c[k]);
  }
  kap_ = cfg.material.earth_pressure == EarthPressure::active_passive;
  if (kap_) {
    const double d = std::atan(mu_), phi = cfg.material.phi;
    kx_[0] = k_x(phi, d, true);
    kx_[1] = k_x(phi, d, false);
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) ky_[a][b] = k_y(kx_[a], d, b == 0);
  }
  for (int b = 0; b < 2; ++b) {
    H_[b] = s.H;
    HU_[b] = s.HU;
    HV_[b] = s.HV;
    U_[b].resize(n_);
    V_[b].resize(n_);
    for (std::size_t k = 0; k < n_; ++k) {
      U_[b][k] = vel(H_[b][k], HU_[b][k]);
      V_[b][k] = vel(H_[b][k], HV_[b][k]);
    }
  }
  mark_cells();
  box_out_.assign(ntiles_, 0);
  if (!out_.empty())
    for (int tt = 0; tt < ntiles_; ++tt) {
      int i0, i1, j0, j1;
      tile_range(tt, i0, i1, j0, j1);
      for (int j = std::max(j0 - 2, 0); j < std::min(j1 + 2, ny_); ++j)
        for (int i = std::max(i0 - 2, 0); i < std::min(i1 + 2, nx_); ++i) box_out_[tt] |= out_[idx(i, j)];
    }
  Pxx_.resize(n_);
  Pxy_.resize(n_);
  Pyy_.resize(n_);
  Ps_.resize(n_);
  for (std::size_t k = 0; k < n_; ++k) {
    pressure(k, 1.0, 1.0, 1.0, 0.0, Pxx_[k], Pxy_[k], Pyy_[k]);
    Ps_[k] = wave_factor(Pxx_[k], Pyy_[k]);
  }
  tile_mass_.assign(ntiles_, 0);
  tile_ke_.assign(ntiles_, 0);
  tile_speed_.assign(ntiles_, 0);
  tile_rate_.assign(ntiles_, 0);
  tile_out_.assign(ntiles_, 0);
  tile_det_.assign(ntiles_, 0);
  tile_ent_.assign(ntiles_, 0);
  tile_travel_.assign(ntiles_, 0);
  tile_limited_.assign(ntiles_, 0);
  tile_wet_.assign(ntiles_, 0);
  active_flag_.assign(ntiles_, 0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  hz_.max_depth.assign(n_, 0);
  hz_.max_speed.assign(n_, 0);
  hz_.max_pressure.assign(n_, 0);
  hz_.arrival_time.assign(n_, nan);
  for (int tt = 0; tt < ntiles_; ++tt) tile_scan(tt);
  for (std::size_t k = 0; k < n_; ++k) record_hazard(k, 0.0);
  for (auto& f : filled_) f.resize(std::size_t(ntiles_));
  for (int tt = 0; tt < ntiles_; ++tt) fill_whole(tt);
  rebuild_active();
  secondary_time_.assign(cfg.secondary.size(), nan);
  set_gauges();
  volume_initial_ = sum_tiles(tile_mass_) * (t_.dx * t_.dy);
  work_.resize(std::size_t(omp_get_max_threads()));
  for (auto& w : work_) w.reserve(T_, !dam_.empty());
}

// Each waiting secondary release area that the flow has reached (a cell of it flowing at the end of
// the step) gets its thickness, at rest; the tiles it touches are scanned and activated again.
void Solver::release_secondary() {
  std::vector<std::uint8_t> touched;  // per tile; empty while no area was released
  for (std::size_t a = 0; a < cfg_.secondary.size(); ++a) {
    if (!std::isnan(secondary_time_[a])) continue;
    const auto& area = cfg_.secondary[a];
    bool reached = false;
    for (std::size_t k : area.cells) reached = reached || H_[cur_][k] * geo_.c[k] > cfg_.flow_threshold;
    if (!reached) continue;
    secondary_time_[a] = t_now_;
    if (touched.empty()) touched.assign(ntiles_, 0);
    for (std::size_t q = 0; q < area.cells.size(); ++q) {
      const std::size_t k = area.cells[q];
      const double dH = area.depth[q] / geo_.c[k];
      volume_secondary_ += dH * t_.dx * t_.dy;
      const double H = H_[cur_][k] + dH, HU = HU_[cur_][k], HV = HV_[cur_][k];
      for (int b = 0; b < 2; ++b) {  // both levels: an inactive tile holds its state in both
        H_[b][k] = H;
        HU_[b][k] = HU;
        HV_[b][k] = HV;
        U_[b][k] = vel(H, HU);
        V_[b][k] = vel(H, HV);
      }
      const int i = int(k % std::size_t(nx_)), j = int(k / std::size_t(nx_));
      touched[(j / T_) * ntx_ + i / T_] = 1;
      fill_whole((j / T_) * ntx_ + i / T_);
    }
  }
  if (touched.empty()) return;
  for (int tt = 0; tt < ntiles_; ++tt)
    if (touched[tt]) tile_scan(tt);
  rebuild_active();
}

void Solver::tile_scan(int tt) {
  int i0, i1, j0, j1;
  tile_range(tt, i0, i1, j0, j1);
  const auto &H = H_[cur_], &HU = HU_[cur_], &HV = HV_[cur_];
  double mass = 0, ke = 0, vmax = 0, rate = 0;
  bool wet = false;
  for (int j = j0; j < j1; ++j)
    for (int i = i0; i < i1; ++i) {
      const std::size_t k = idx(i, j);
      const double h = H[k], U = vel(h, HU[k]), V = vel(h, HV[k]);
      const double w = geo_.bx[k] * U + geo_.by[k] * V, sp2 = U * U + V * V + w * w;
      mass += h;
      ke += 0.5 * h * sp2;
      // The speed of flowing cells only, the same number as the maximum-speed map takes.
      if (h * geo_.c[k] > cfg_.flow_threshold) vmax = std::max(vmax, h > cfg_.dry_depth ? m3(k, HU[k], HV[k]) / h : 0.0);
      rate = std::max(rate, std::abs(U) / t_.dx + std::abs(V) / t_.dy + Ps_[k] * std::sqrt(std::max(h, 0.0)));
      wet = wet || h > cfg_.activation_depth;
    }
  tile_mass_[tt] = mass;
  tile_ke_[tt] = ke;
  tile_speed_[tt] = vmax;
  tile_rate_[tt] = rate;
  tile_wet_[tt] = wet;
}

void Solver::record_hazard(std::size_t k, double t) {
  const double H = H_[cur_][k], h = H * geo_.c[k];
  const double sp = H > cfg_.dry_depth ? m3(k, HU_[cur_][k], HV_[cur_][k]) / H : 0.0;
  hz_.max_depth[k] = std::max(hz_.max_depth[k], h);
  if (h > cfg_.flow_threshold) {
    hz_.max_speed[k] = std::max(hz_.max_speed[k], sp);
    hz_.max_pressure[k] = std::max(hz_.max_pressure[k], cfg_.material.density * sp * sp);
    if (std::isnan(hz_.arrival_time[k])) hz_.arrival_time[k] = t;
  }
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
      // are, at rest, so that the volume is kept exactly. Both time levels hold the frozen state.
      int i0, i1, j0, j1;
      tile_range(tt, i0, i1, j0, j1);
      for (int j = j0; j < j1; ++j)
        for (int i = i0; i < i1; ++i) {
          const std::size_t k = idx(i, j);
          for (int b = 0; b < 2; ++b) {
            H_[b][k] = H_[cur_][k];
            HU_[b][k] = HV_[b][k] = U_[b][k] = V_[b][k] = 0.0;
          }
        }
      tile_ke_[tt] = 0;
      tile_speed_[tt] = 0;
      fill_whole(tt);
    }
    active_flag_[tt] = next[tt];
    if (next[tt]) active_.push_back(tt);
  }
}

Sh2dCheckpoint Solver::checkpoint(const LoopState& loop) const {
  Sh2dCheckpoint cp;
  cp.nx = nx_;
  cp.ny = ny_;
  cp.tile = T_;
  cp.t = t_now_;
  cp.steps = steps_;
  cp.H = H_[cur_];
  cp.HU = HU_[cur_];
  cp.HV = HV_[cur_];
  cp.U = U_[cur_];
  cp.V = V_[cur_];
  cp.hazard.max_depth = hz_.max_depth;
  cp.hazard.max_speed = hz_.max_speed;
  cp.hazard.max_pressure = hz_.max_pressure;
  cp.hazard.arrival_time = hz_.arrival_time;
  cp.tile_mass = tile_mass_;
  cp.tile_ke = tile_ke_;
  cp.tile_speed = tile_speed_;
  cp.tile_rate = tile_rate_;
  cp.tile_out = tile_out_;
  cp.tile_travel = tile_travel_;
  cp.tile_limited = tile_limited_;
  cp.tile_wet = tile_wet_;
  cp.tile_active = active_flag_;
  cp.volume_initial = volume_initial_;
  cp.kinetic_energy_peak = loop.kinetic_energy_peak;
  cp.cell_updates = cell_updates_;
  cp.active_fraction_sum = active_sum_;
  cp.max_active_fraction = max_active_fraction_;
  cp.next_snapshot = loop.next_frame;
  cp.last_snapshot = loop.last_frame;
  cp.secondary_time = secondary_time_;
  cp.volume_secondary = volume_secondary_;
  cp.gauge_right = gauge_right_;
  cp.gauge_left = gauge_left_;
  if (!cfg_.resistance.empty()) {
    cp.detrained = det_;
    cp.tile_detrained = tile_det_;
  }
  if (!cfg_.cover.empty()) {
    cp.cover = cover_;
    cp.tile_entrained = tile_ent_;
  }
  return cp;
}

void Solver::restore(const Sh2dCheckpoint& cp) {
  auto bad = [](const std::string& m) { throw std::invalid_argument("2D solver: checkpoint " + m); };
  if (cp.nx != nx_ || cp.ny != ny_) bad("is of another grid");
  if (cp.tile != T_) bad("was taken with another tile size");
  auto cells = [&](const std::vector<double>& v) { return v.size() == n_; };
  if (!cells(cp.U) || !cells(cp.V) || !cells(cp.hazard.max_depth) || !cells(cp.hazard.max_speed) ||
      !cells(cp.hazard.max_pressure) || !cells(cp.hazard.arrival_time))
    bad("is damaged (a field has the wrong size)");
  const std::size_t nt = std::size_t(ntiles_);
  if (cp.tile_mass.size() != nt || cp.tile_ke.size() != nt || cp.tile_speed.size() != nt || cp.tile_rate.size() != nt ||
      cp.tile_out.size() != nt || cp.tile_travel.size() != nt || cp.tile_limited.size() != nt || cp.tile_wet.size() != nt ||
      cp.tile_active.size() != nt)
    bad("is damaged (a tile field has the wrong size)");
  if (!(std::isfinite(cp.t) && cp.t >= 0) || cp.steps < 0) bad("is damaged (time or step count)");
  if (cp.secondary_time.size() != cfg_.secondary.size()) bad("was taken with other secondary releases");
  if (cp.gauge_right.size() != cfg_.gauges.size() || cp.gauge_left.size() != cfg_.gauges.size())
    bad("was taken with other dams (flux gauges)");
  if (cfg_.resistance.empty() != cp.detrained.empty() ||
      (!cp.detrained.empty() && (!cells(cp.detrained) || cp.tile_detrained.size() != nt)))
    bad("was taken with other resistance areas");
  if (cfg_.cover.empty() != cp.cover.empty() || (!cp.cover.empty() && (!cells(cp.cover) || cp.tile_entrained.size() != nt)))
    bad("was taken with another erodible cover");
  // Both time levels hold the state: the level a step writes is never read before it is written,
  // and inactive tiles hold the same in both (see rebuild_active).
  cur_ = 0;
  for (int b = 0; b < 2; ++b) {
    U_[b] = cp.U;
    V_[b] = cp.V;
  }
  hz_.max_depth = cp.hazard.max_depth;
  hz_.max_speed = cp.hazard.max_speed;
  hz_.max_pressure = cp.hazard.max_pressure;
  hz_.arrival_time = cp.hazard.arrival_time;
  tile_mass_ = cp.tile_mass;
  tile_ke_ = cp.tile_ke;
  tile_speed_ = cp.tile_speed;
  tile_rate_ = cp.tile_rate;
  tile_out_ = cp.tile_out;
  tile_travel_ = cp.tile_travel;
  tile_limited_ = cp.tile_limited;
  tile_wet_ = cp.tile_wet;
  active_flag_ = cp.tile_active;
  active_.clear();
  for (int tt = 0; tt < ntiles_; ++tt)
    if (active_flag_[tt]) active_.push_back(tt);
  t_now_ = cp.t;
  steps_ = cp.steps;
  volume_initial_ = cp.volume_initial;
  cell_updates_ = cp.cell_updates;
  active_sum_ = cp.active_fraction_sum;
  max_active_fraction_ = cp.max_active_fraction;
  secondary_time_ = cp.secondary_time;
  volume_secondary_ = cp.volume_secondary;
  gauge_right_ = cp.gauge_right;
  gauge_left_ = cp.gauge_left;
  if (!cfg_.resistance.empty()) {
    det_ = cp.detrained;
    tile_det_ = cp.tile_detrained;
  }
  if (!cfg_.cover.empty()) {
    cover_ = cp.cover;
    tile_ent_ = cp.tile_entrained;
  }
}

double Solver::sum_tiles(const std::vector<double>& v) const {
  double s = 0;
  for (int tt = 0; tt < ntiles_; ++tt) s += v[tt];
  return s;
}

void Solver::not_finite(const char* what) const {
  throw std::runtime_error("2D solver: the flow state became non-finite (NaN or infinite " + std::string(what) + ") at step " +
                           std::to_string(steps_) + ", t = " + std::to_string(t_now_) +
                           " s: the release is far too thick or the numerics left their range");
}

// The step length from the fastest active tile's CFL rate, capped by dt_max and the end time.
double Solver::next_dt(double t_end) const {
  const auto& tc = cfg_.time;
  const double t = t_now_;
  double rate = 0;
  for (int tt : active_) rate = std::max(rate, tile_rate_[tt]);
  if (!std::isfinite(rate)) not_finite("depth or momentum");
  double dt = rate > 0 ? tc.cfl / rate : tc.dt_max;
  dt = std::min({dt, tc.dt_max, t_end - t});
  if (!(dt > 0) || !std::isfinite(dt)) dt = t_end - t;
  return dt;
}

// One step of every active tile (in parallel, each thread with its own work space), then the swap of
// the time levels, the step's bookkeeping and the new set of active tiles. Returns the fraction of
// the cells computed.
double Solver::step_all(double dt) {
  const double t = t_now_;
  const int na = int(active_.size());
  while (work_.size() < std::size_t(omp_get_max_threads())) {  // more threads than when the solver was built
    work_.emplace_back();
    work_.back().reserve(T_, !dam_.empty());
  }
  long ncells = 0;  // the cells computed: those of the active tiles within reach of material
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : ncells)
  for (int a = 0; a < na; ++a) ncells += step_tile(active_[a], t, dt, work_[omp_get_thread_num()]);
  cur_ = 1 - cur_;
  t_now_ += dt;
  ++steps_;
  cell_updates_ += double(ncells);
  const double frac = double(ncells) / double(n_);
  active_sum_ += frac;
  max_active_fraction_ = std::max(max_active_fraction_, frac);
  rebuild_active();
  return frac;
}

StepReport Solver::step(double t_end) {
  const double dt = next_dt(t_end);
  StepReport r;
  r.active_fraction = step_all(dt);
  if (!cfg_.gauges.empty()) measure_gauges();
  if (!cfg_.secondary.empty()) release_secondary();
  // Cheap guard on the whole state: a NaN or infinite depth shows in the volume, a NaN or infinite
  // momentum in the kinetic energy.
  const double ke = sum_tiles(tile_ke_), mass = sum_tiles(tile_mass_), cell_area = t_.dx * t_.dy;
  if (!std::isfinite(mass)) not_finite("depth");
  if (!std::isfinite(ke)) not_finite("momentum");
  r.t = t_now_;
  r.dt = dt;
  r.mass = mass * cell_area;
  r.kinetic_energy = ke * cell_area;
  for (int tt = 0; tt < ntiles_; ++tt) r.max_speed = std::max(r.max_speed, tile_speed_[tt]);
  return r;
}

Sh2dResult Solver::finish(StopReason stop, const LoopState& loop) {
  Sh2dResult res;
  auto& d = res.diag;
  const double cell_area = t_.dx * t_.dy;
  d.stop = stop;
  d.t = t_now_;
  d.steps = steps_;
  d.volume_initial = volume_initial_;
  d.volume_secondary = volume_secondary_;
  d.secondary_time = secondary_time_;
  res.gauge_right = gauge_right_;
  res.gauge_left = gauge_left_;
  d.kinetic_energy_peak = loop.kinetic_energy_peak;
  d.cell_updates = cell_updates_;
  d.max_active_fraction = max_active_fraction_;
  d.volume_final = sum_tiles(tile_mass_) * cell_area;
  d.volume_outflow = sum_tiles(tile_out_);
  d.volume_detrained = sum_tiles(tile_det_) * cell_area;
  d.volume_entrained = sum_tiles(tile_ent_) * cell_area;
  if (!cfg_.resistance.empty()) {  // as normal thickness
    res.detrained.resize(n_);
    for (std::size_t k = 0; k < n_; ++k) res.detrained[k] = det_[k] * geo_.c[k];
  }
  if (!cfg_.cover.empty()) {  // the cover's own normal depth
    res.cover.resize(n_);
    for (std::size_t k = 0; k < n_; ++k)
      res.cover[k] = cover_[k] * cfg_.material.density * geo_.c[k] / cfg_.cover.density[k];
  }
  d.mean_travel = d.volume_initial > 0 ? sum_tiles(tile_travel_) * cell_area / d.volume_initial : 0.0;
  for (int tt = 0; tt < ntiles_; ++tt) d.positivity_limited += tile_limited_[tt];
  d.mean_active_fraction = steps_ > 0 ? active_sum_ / double(steps_) : 0.0;
  // The reported maximum speed is the map's: flowing cells only.
  for (std::size_t k = 0; k < n_; ++k) d.max_speed = std::max(d.max_speed, hz_.max_speed[k]);
  hz_.final_depth.resize(n_);
  for (std::size_t k = 0; k < n_; ++k) hz_.final_depth[k] = H_[cur_][k] * geo_.c[k];
  res.hazard = std::move(hz_);
  res.state.H = std::move(H_[cur_]);
  res.state.HU = std::move(HU_[cur_]);
  res.state.HV = std::move(HV_[cur_]);
  return res;
}

}  // namespace sh2d_detail

Sh2dEngine::Sh2dEngine(const Terrain2D& terrain, const Sh2dConfig& config, Sh2dState initial) {
  sh2d_detail::validate(terrain, config, initial);
  s_ = std::make_unique<sh2d_detail::Solver>(terrain, config, std::move(initial));
}

Sh2dEngine::Sh2dEngine(const Terrain2D& terrain, const Sh2dConfig& config, const Sh2dCheckpoint& from) {
  Sh2dState st{from.H, from.HU, from.HV};
  sh2d_detail::validate(terrain, config, st);
  s_ = std::make_unique<sh2d_detail::Solver>(terrain, config, std::move(st));
  s_->restore(from);
}

Sh2dEngine::~Sh2dEngine() = default;
double Sh2dEngine::time() const { return s_->time(); }
long Sh2dEngine::steps() const { return s_->steps(); }
StepReport Sh2dEngine::step(double t_end) { return s_->step(t_end); }
double Sh2dEngine::kinetic_energy() const { return s_->kinetic_energy(); }
Sh2dStateView Sh2dEngine::state() const { return s_->state(); }
const std::vector<double>& Sh2dEngine::gauge_right() const { return s_->gauge_right(); }
const std::vector<double>& Sh2dEngine::gauge_left() const { return s_->gauge_left(); }
Sh2dCheckpoint Sh2dEngine::checkpoint(const LoopState& loop) const { return s_->checkpoint(loop); }
Sh2dResult Sh2dEngine::finish(StopReason stop, const LoopState& loop) { return s_->finish(stop, loop); }

LoopState Sh2dEngine::loop_state(const Sh2dCheckpoint& cp) {
  LoopState st;
  st.kinetic_energy_peak = cp.kinetic_energy_peak;
  st.next_frame = cp.next_snapshot;
  st.last_frame = cp.last_snapshot;
  return st;
}

LoopSchedule loop_schedule(const Sh2dConfig& c) {
  LoopSchedule s;
  s.t_end = c.time.t_end;
  s.stop_fraction = c.time.stop_fraction;
  s.max_steps = c.time.max_steps;
  s.frame_interval = c.snapshot ? c.snapshot_interval : 0.0;
  s.final_frame = true;
  s.checkpoint_interval = c.checkpoint_interval;
  s.progress_every = c.time.progress_every;
  return s;
}

namespace {

// The one loop with the configuration's hooks (snapshots, checkpoints, progress).
Sh2dResult drive(Sh2dEngine& e, const Sh2dConfig& config, LoopState loop, bool continued,
                 std::chrono::steady_clock::time_point wall0) {
  LoopHooks h;
  if (config.snapshot) h.frame = [&](double t) { config.snapshot(t, e.state()); };
  if (config.checkpoint) h.checkpoint = [&](const LoopState& st) { config.checkpoint(e.checkpoint(st)); };
  h.progress = config.time.progress;
  const auto loop0 = std::chrono::steady_clock::now();
  const StopReason stop = run_steps(e, loop_schedule(config), loop, h, continued);
  const auto loop1 = std::chrono::steady_clock::now();
  Sh2dResult res = e.finish(stop, loop);
  res.diag.loop_seconds = std::chrono::duration<double>(loop1 - loop0).count();
  res.diag.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return res;
}

}  // namespace

Sh2dResult run_sh2d(const Terrain2D& terrain, const Sh2dConfig& config, Sh2dState initial) {
  const auto wall0 = std::chrono::steady_clock::now();
  Sh2dEngine e(terrain, config, std::move(initial));
  return drive(e, config, LoopState{}, false, wall0);
}

Sh2dResult run_sh2d(const Terrain2D& terrain, const Sh2dConfig& config, const Sh2dCheckpoint& from) {
  const auto wall0 = std::chrono::steady_clock::now();
  Sh2dEngine e(terrain, config, from);
  return drive(e, config, Sh2dEngine::loop_state(from), true, wall0);
}

}  // namespace runout::engine
