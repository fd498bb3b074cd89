#pragma once
// The depth-averaged 2D solver's internals (engine/sh2d.hpp is the interface): the tile work space
// and the Solver. The scheme's equations are point kernels of one cell or face (kernels.hpp), which
// the general cell loops and the vectorised row kernels share. solver.cpp holds the set-up, the step
// over the active tiles and checkpoints (the time loop is engine/stepping.cpp's); tile.cpp one tile's
// step (the cells it computes, the order of the stages); predictor.cpp the reconstruction and the
// predictor to the half step (with the earth pressure and the start/stop law's terms); fluxes.cpp the
// face fluxes with the boundary and outflow ghosts and the dams' step faces; update.cpp the positivity
// limiter, the update with its sources and friction, the hazard maps and the tile sums; surface.cpp the
// surface geometry; cells.cpp which cells take the general loops and the flux gauges.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/sh2d.hpp"
#include "engine/sh2d/kernels.hpp"

// The vectorisable kernels are compiled twice, for AVX2 (four doubles per instruction) and for the
// baseline x86-64 (two), and the loader picks the one the CPU supports.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define RUNOUT_SIMD_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define RUNOUT_SIMD_CLONES
#endif

namespace runout::engine::sh2d_detail {

// A box of cells [i0, i1) x [j0, j1).
struct CellBox {
  int i0, i1, j0, j1;
  bool empty() const { return i1 <= i0 || j1 <= j0; }
};

// Work space of one tile's step, private to the thread computing it. A tile's step runs the whole
// scheme on its cells and a halo: predictor on the tile grown by two cells, face fluxes and the
// positivity factors on the tile grown by one, the update on the tile. The halo work is repeated by
// the neighbouring tile, bit for bit the same, so the scheme stays conservative; in exchange the
// intermediate fields never leave the cache.
struct TileWork {
  int bi0 = 0, bj0 = 0, bw = 0, bh = 0;  // box = tile grown by 2, clipped to the grid
  bool all_active = true;                // every tile the box touches is active
  bool has_outside = false;              // the box holds cells outside the domain
  std::vector<double> sHx, sux, svx, sHy, suy, svy, Hp, Up, Vp, Pxx, Pxy, Pyy, Ps, r;
  std::vector<double> held;  // 1 where friction holds the cell at rest, else 0
  // Face fluxes (mass, x-momentum, y-momentum); Fx*[(j - bj0) * (bw + 1) + (i - bi0)]: face left of
  // cell (i, j), Fy*[(j - bj0) * bw + (i - bi0)]: face below it.
  std::vector<double> Fx0, Fx1, Fx2, Fy0, Fy1, Fy2;
  // At a dam's step face (Sh2dConfig::dam_height): the wall's reaction on each side, added to the
  // face's momentum flux for that side's cell (normal, tangential; a: left/lower cell, b: right/upper);
  // written only at step faces, read only there (sized only with dams).
  std::vector<double> Wxa1, Wxa2, Wxb1, Wxb2, Wya1, Wya2, Wyb1, Wyb2;
  // One tile row's terms of the tile sums (index i - i0): kinetic energy, speed of a flowing cell
  // (else 0), CFL rate; written by the update's cell kernels, summed in cell order afterwards. And
  // the row kernel's normal depth and pressure of a flowing cell (else 0), for the hazard maps.
  std::vector<double> cell_ke, cell_speed, cell_rate, cell_h, cell_pressure;
  std::vector<double> cell_det, cell_ent;  // the depth detrained and entrained (Basal::ground)
  // One row's friction coefficients without the start/stop term and that term's weights (start_terms).
  std::vector<double> row_mu, row_w;
  Face fxf(std::size_t k) const { return Face{Fx0[k], Fx1[k], Fx2[k]}; }
  Face fyf(std::size_t k) const { return Face{Fy0[k], Fy1[k], Fy2[k]}; }
  void reserve(int T, bool dams) {
    const std::size_t n = std::size_t(T + 4) * (T + 4);
    for (auto* v : {&Wxa1, &Wxa2, &Wxb1, &Wxb2}) v->assign(dams ? std::size_t(T + 5) * (T + 4) : 0, 0.0);
    for (auto* v : {&Wya1, &Wya2, &Wyb1, &Wyb2}) v->assign(dams ? std::size_t(T + 4) * (T + 5) : 0, 0.0);
    for (auto* v : {&sHx, &sux, &svx, &sHy, &suy, &svy, &Hp, &Up, &Vp, &Pxx, &Pxy, &Pyy, &Ps, &r}) v->assign(n, 0.0);
    held.assign(n, 0.0);
    for (auto* v : {&Fx0, &Fx1, &Fx2}) v->assign(std::size_t(T + 5) * (T + 4), 0.0);
    for (auto* v : {&Fy0, &Fy1, &Fy2}) v->assign(std::size_t(T + 4) * (T + 5), 0.0);
    for (auto* v : {&cell_ke, &cell_speed, &cell_rate, &cell_h, &cell_pressure, &cell_det, &cell_ent}) v->assign(std::size_t(T), 0.0);
    for (auto* v : {&row_mu, &row_w}) v->assign(std::size_t(T + 4), 0.0);
  }
  std::size_t at(int i, int j) const { return std::size_t(j - bj0) * bw + (i - bi0); }
  std::size_t fx(int i, int j) const { return std::size_t(j - bj0) * (bw + 1) + (i - bi0); }
  std::size_t fy(int i, int j) const { return std::size_t(j - bj0) * bw + (i - bi0); }
};

// Where the predictor writes a run of cells of the box, from box index q on.
struct PredictorOut {
  double *sHx, *sux, *svx, *sHy, *suy, *svy, *Hp, *Up, *Vp, *Pxx, *Pxy, *Pyy, *Ps, *held;
  RUNOUT_KERNEL PredictorOut(TileWork& w, std::size_t q)
      : sHx(&w.sHx[q]), sux(&w.sux[q]), svx(&w.svx[q]), sHy(&w.sHy[q]), suy(&w.suy[q]), svy(&w.svy[q]), Hp(&w.Hp[q]),
        Up(&w.Up[q]), Vp(&w.Vp[q]), Pxx(&w.Pxx[q]), Pxy(&w.Pxy[q]), Pyy(&w.Pyy[q]), Ps(&w.Ps[q]), held(&w.held[q]) {}
  RUNOUT_KERNEL void put(std::ptrdiff_t t, const Slopes& s, const Predicted& p, double pxx, double pxy, double pyy,
                         double ps) const {
    sHx[t] = s.Hx;
    sux[t] = s.ux;
    svx[t] = s.vx;
    sHy[t] = s.Hy;
    suy[t] = s.uy;
    svy[t] = s.vy;
    Hp[t] = p.Hp;
    Up[t] = p.Up;
    Vp[t] = p.Vp;
    Pxx[t] = pxx;
    Pxy[t] = pxy;
    Pyy[t] = pyy;
    Ps[t] = ps;
    held[t] = p.held;
  }
};

class Solver {
 public:
  Solver(const Terrain2D& t, const Sh2dConfig& cfg, Sh2dState s);

  // The engine's side of the run loop (engine/sh2d.hpp, Sh2dEngine).
  StepReport step(double t_end);
  double time() const { return t_now_; }
  long steps() const { return steps_; }
  double kinetic_energy() const { return sum_tiles(tile_ke_) * (t_.dx * t_.dy); }
  Sh2dStateView state() const { return Sh2dStateView{H_[cur_], HU_[cur_], HV_[cur_]}; }
  const std::vector<double>& gauge_right() const { return gauge_right_; }
  const std::vector<double>& gauge_left() const { return gauge_left_; }
  /// The whole state between two steps, with the loop's running figures.
  Sh2dCheckpoint checkpoint(const LoopState& loop) const;
  /// Take up a checkpoint's state (after construction from its depths and momenta).
  void restore(const Sh2dCheckpoint& cp);
  /// The diagnostics of the run and its results (maps, final state), moved out of the solver.
  Sh2dResult finish(StopReason stop, const LoopState& loop);

 private:
  std::size_t idx(int i, int j) const { return std::size_t(j) * nx_ + i; }
  void tile_range(int tt, int& i0, int& i1, int& j0, int& j1) const {
    const int ti = tt % ntx_, tj = tt / ntx_;
    i0 = ti * T_;
    i1 = std::min(i0 + T_, nx_);
    j0 = tj * T_;
    j1 = std::min(j0 + T_, ny_);
  }
  bool cell_active(int i, int j) const { return active_flag_[(j / T_) * ntx_ + i / T_]; }
  bool outside(int i, int j) const { return !out_.empty() && out_[idx(i, j)]; }
  // The cell or one of its four neighbours lies outside the domain (such cells take the general loop).
  bool near_outside(std::size_t k) const { return !near_out_.empty() && near_out_[k]; }
  // Whether the face between cells k and m is a dam's step (their dam heights differ).
  bool step_face(std::size_t k, std::size_t m) const { return !dam_.empty() && dam_[k] != dam_[m]; }
  // The cell takes the general loops of the predictor and the update (near the outside, next to a
  // dam's step, a flux gauge's cell); the row kernels take the others.
  bool general(std::size_t k) const { return !general_.empty() && general_[k]; }
  double vel(double H, double M) const { return H > cfg_.dry_depth ? M / H : 0.0; }

  // Pi = g [c^4 Kx d d^T + c^2 Ky s s^T], d the downslope unit vector (or (dx, dy) on flat ground).
  void pressure(std::size_t k, double Kx, double Ky, double ddx, double ddy, double& pxx, double& pxy,
                double& pyy) const {
    const double bx = geo_.bx[k], by = geo_.by[k], c = geo_.c[k], gb = std::hypot(bx, by);
    if (gb > 1e-12) {
      ddx = bx / gb;
      ddy = by / gb;
    }
    const double a = g_ * c * c * c * c * Kx, b = g_ * c * c * Ky;
    pxx = a * ddx * ddx + b * ddy * ddy;
    pxy = (a - b) * ddx * ddy;
    pyy = a * ddy * ddy + b * ddx * ddx;
  }

  // The constants of a step the point kernels read.
  StepConstants constants() const {
    return StepConstants{g_, qcap_, cfg_.dry_depth, cfg_.curvature ? 1.0 : 0.0, fr_, ground_};
  }
  // sqrt(Pxx)/dx + sqrt(Pyy)/dy: the gravity-wave part of the CFL rate, per sqrt(H).
  double wave_factor(double pxx, double pyy) const { return std::sqrt(pxx) / t_.dx + std::sqrt(pyy) / t_.dy; }
  double m3(std::size_t k, double MU, double MV) const { return speed3(geo_.bx[k], geo_.by[k], MU, MV); }

  // A step's parts (solver.cpp): its length, one step of every active tile, the guard on the state.
  double next_dt(double t_end) const;
  double step_all(double dt);
  [[noreturn]] void not_finite(const char* what) const;
  double sum_tiles(const std::vector<double>& v) const;
  void tile_scan(int tt);
  void release_secondary();
  void record_hazard(std::size_t k, double t);
  void rebuild_active();
  void mark_cells();
  void set_gauges();
  long step_tile(int tt, double t, double dt, TileWork& w);  // returns the cells it computed
  CellBox material_box(int i0, int i1, int j0, int j1) const;
  void clear_outside(int tt, const CellBox& c);
  void fill_whole(int tt);
  template <Limiter L>
  void predictor(TileWork& w, double dt) const;
  template <Limiter L, Basal B>
  void predictor_cells(TileWork& w, double dt) const;
  void earth_pressure(std::size_t k, int i, int j, double U, double V, double& Pxx, double& Pxy, double& Pyy,
                      double& Ps) const;
  template <Limiter L, Basal B>
  void predictor_row(TileWork& w, int j, int ia, int ib, double dt) const;
  void start_terms(int n, std::size_t k0, const double* H, const double* U, const double* V, TileWork& w) const;
  void faces(TileWork& w, int ci0, int ci1, int cj0, int cj1) const;
  template <bool X>
  Face face(TileWork& w, int ia, int ja, int ib, int jb, bool lo, bool hi, Boundary2D blo, Boundary2D bhi) const;
  template <bool X>
  Face dam_face(TileWork& w, int ia, int ja, int ib, int jb, bool held) const;
  template <bool X>
  void no_reaction(TileWork& w, int ib, int jb) const;
  long positivity(TileWork& w, int i0, int i1, int j0, int j1, double dt) const;
  void update(int tt, TileWork& w, const CellBox& c, double t, double dt);
  template <Basal B>
  void update_cells(int tt, TileWork& w, const CellBox& c, double t, double dt);
  template <Basal B>
  void update_cell(TileWork& w, int i, int j, int i0, double t1, double dt, double& out);
  template <Basal B>
  void update_row(TileWork& w, int j, int ia, int ib, int i0, double t1, double dt);
  template <Basal B, bool Row = false>
  void update_run(TileWork& w, int j, int ia, int ib, int i0, double t1, double dt, double sw, double se, double ss,
                  double sn, double smu, double swt, double wu, double wv);

  const Terrain2D& t_;
  const Sh2dConfig& cfg_;
  SurfaceGeometry geo_;
  int nx_, ny_;
  std::size_t n_;
  int T_, ntx_, nty_, ntiles_;
  double g_ = 9.81, mu_ = 0, ixi_ = 0, qcap_ = 9.81;
  BasalFriction fr_;             // the law's coefficients (engine/friction)
  Basal basal_ = Basal::coulomb;  // the kernels it takes
  bool kap_ = false;
  double kx_[2] = {1, 1}, ky_[2][2] = {{1, 1}, {1, 1}};
  // State at t (index cur_) and t + dt (1 - cur_); U, V the velocity (zero where dry).
  std::vector<double> H_[2], HU_[2], HV_[2], U_[2], V_[2];
  int cur_ = 0;
  std::vector<std::uint8_t> out_, near_out_;  // empty when every cell is inside
  std::vector<double> dam_;                   // per cell the dam height [m]; empty without dams
  std::vector<std::uint8_t> general_;         // see general(); empty when every cell takes the rows
  std::vector<std::uint8_t> box_out_;         // per tile: its box (tile grown by 2) holds outside cells
  std::vector<double> Pxx_, Pxy_, Pyy_;  // pressure coefficients for K = 1 (also the start values)
  std::vector<double> Ps_;                // wave_factor of those
  std::vector<double> tile_mass_, tile_ke_, tile_speed_, tile_rate_, tile_out_, tile_travel_;
  // Resistance areas (Basal::ground): the drag coefficient and detrainment per cell, their rule, the
  // depth detrained per cell so far (as H) and per tile the volume as H summed (times the cell area).
  std::vector<double> cres_, kdet_, det_, tile_det_;
  // The erodible cover (Basal::ground): what is left per cell (as H of flow: the flow volume it would
  // make per horizontal area) and per tile the volume taken up (as H summed).
  std::vector<double> cover_, tile_ent_;
  GroundRule ground_{};
  std::vector<long> tile_limited_;
  std::vector<std::uint8_t> tile_wet_, active_flag_;
  std::vector<int> active_;
  // Per time level and tile: the box of the tile's cells that may hold material or momentum in that
  // level; every other cell of the tile is empty there (see clear_outside).
  std::vector<CellBox> filled_[2];
  HazardMaps hz_;
  // The run's running figures (members so that a checkpoint can carry them).
  double t_now_ = 0, active_sum_ = 0;
  long steps_ = 0;
  double cell_updates_ = 0, max_active_fraction_ = 0, volume_initial_ = 0;
  std::vector<TileWork> work_;  // per OpenMP thread
  std::vector<double> secondary_time_;  // per secondary release area: when released, NaN while waiting
  double volume_secondary_ = 0;
  std::vector<double> gauge_right_, gauge_left_;  // per flux gauge: the volume that left each way so far
  // Per cell: its slot among the gauges' cells (-1: none); per slot its gauge, face sides and the
  // volume its update sent right and left in the step (written by the cell's own update only).
  std::vector<int> gauge_slot_;
  std::vector<int> slot_gauge_;
  std::vector<std::array<std::int8_t, 4>> slot_sides_;
  std::vector<double> slot_right_, slot_left_;
  bool gauge_cell(std::size_t k) const { return !gauge_slot_.empty() && gauge_slot_[k] >= 0; }
  void measure_gauges();
};

}  // namespace runout::engine::sh2d_detail
