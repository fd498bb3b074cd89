// The VOF solver: its parts, the initial state, checkpoints, and one time step (PISO, or PIMPLE with
// outer correctors) written as the algorithm.
#include "engine/vof/solver.hpp"
#include "engine/vof/stepping.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <unordered_map>

#include "engine/vof/active_region.hpp"
#include "engine/vof/alpha_eqn.hpp"
#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/fields.hpp"
#include "engine/vof/hydrostatics.hpp"
#include "engine/vof/linear/petsc.hpp"
#include "engine/vof/mixture.hpp"
#include "engine/vof/models/granular_viscosity.hpp"
#include "engine/vof/momentum_eqn.hpp"
#include "engine/vof/mpi/distributed.hpp"
#include "engine/vof/pressure_eqn.hpp"

namespace runout::engine::vof {

namespace {

void check_config(const VofConfig& c) {
  if (!(c.side_walls.width >= 0 && c.side_walls.tan_delta >= 0 && c.side_walls.creep_speed > 0))
    throw VofError("side_walls: the width and the friction must be >= 0, the creep speed > 0");
  if (!(c.column_friction.tan_delta >= 0 && c.column_friction.creep_speed > 0))
    throw VofError("column_friction: the friction must be >= 0, the creep speed > 0");
  if (!(c.momentum_rtol > 0 && c.momentum_rtol < 1)) throw VofError("momentum_rtol must lie in (0, 1)");
  if (!(c.consistent_alpha > 0 && c.consistent_alpha <= 1)) throw VofError("consistent_alpha must lie in (0, 1]");
}

// The whole mesh's (a part of a distributed run is given it: VofConfig::mean_cell_size).
double mean_cell_size(const Mesh& m, const VofConfig& c) { return c.mean_cell_size > 0 ? c.mean_cell_size : m.mean_cell_size(); }

}  // namespace

struct VofSolver::Impl {
  Impl(const Mesh& mesh, const VofConfig& config, const Ranks& ranks_of_run)
      : m(mesh),
        cfg(config),
        ranks(ranks_of_run),
        dims(mesh.thickness > 0 ? 2 : 3),
        bcs(mesh, config.bc),
        viscosity(make_granular_viscosity(config)),
        mixture(config),
        hydrostatics(mesh, config, F, ranks),
        bc_ctx{mesh, F, hydrostatics, *viscosity, mixture, config.wall_viscosity},
        region(mesh, cell_faces, config, bcs, F, hydrostatics, mixture, ranks),
        pressure_solver(config, ranks),
        alpha_eqn(mesh, config, bc_ctx, bcs, region, mean_cell_size(mesh, config)),
        UEqn(mesh, config, bc_ctx, bcs, region, reconstruct, dims),
        pEqn(mesh, config, bc_ctx, bcs, region, reconstruct, pressure_solver) {
    check_config(cfg);
    if (cfg.column_friction.columns.columns() > 0) check_columns(m, cfg.column_friction.columns);
    cell_faces.build(m);
    reconstruct.build(m, cell_faces, dims);
    petsc_init();
    pressure_solver.make_ksp();  // checks the preconditioner's name early
    F.resize(m.cells(), m.faces(), cfg.nu_max);
    hydrostatics.resize();
    div.assign(m.cells(), 0);
    UEqn.setup_predictor();
  }

  const Mesh& m;
  const VofConfig& cfg;
  const Ranks& ranks;  // the run's ranks: this part's own cells, the ghosts' exchange
  const int dims;
  Fields F;
  Boundaries bcs;
  std::unique_ptr<GranularViscosity> viscosity;
  Mixture mixture;
  CellFaces cell_faces;
  Reconstruction reconstruct;
  Hydrostatics hydrostatics;
  BcContext bc_ctx;
  ActiveRegion region;
  PressureSolver pressure_solver;
  AlphaEqn alpha_eqn;
  MomentumEqn UEqn;
  PressureEqn pEqn;
  CellField<double> div;  // the divergence of the fluxes (diagnostics)

  struct Courant {
    double co = 0, alpha_co = 0, air_co = 0;
  };

  void update_gravity(double t, bool force = false) {
    hydrostatics.update(t, [&](int f) { return bcs[f].opening_at(f); }, force);
  }
  void update_rho() {
    for (int c : region.halo) F.rho[c] = mixture.rho(F.alpha[c]);
    ranks.sync(F.rho);
  }
  void keep_old_time() {
    for (int c : region.halo) {
      F.rho_old[c] = F.rho[c];
      F.U_old[c] = F.U[c];
    }
  }
  Courant courant(double dt) const;
  double next_dt(const Courant& co, double dt, double time_left, const char*& limit) const;
  void initial_pressure(double t);
  void diagnostics(StepStats& st, double t);
};

// The Courant numbers of the last step's fluxes (eqs. 4.64-4.65): in the material, at the
// interface and in the air.
VofSolver::Impl::Courant VofSolver::Impl::courant(double dt) const {
  Courant k;
  for (int c : region.cells) {
    if (!ranks.own(c)) continue;
    double sum = 0;
    for (int f : cell_faces[c]) sum += std::abs(F.phi[f]);
    const double cc = 0.5 * sum / m.volume[c] * dt;
    const double a = F.alpha[c];
    if (a > cfg.material_alpha) {
      k.co = std::max(k.co, cc);
    } else {
      k.air_co = std::max(k.air_co, cc);
    }
    if (a > 0.01 && a < 0.99) k.alpha_co = std::max(k.alpha_co, cc);
  }
  if (ranks.distributed()) {
    std::vector<double> v{k.co, k.alpha_co, k.air_co};
    ranks.comm().max(v);
    k = {v[0], v[1], v[2]};
  }
  return k;
}

// The next step's length: the Courant numbers' targets, growing by at most 20 % a step, at most
// dt_max, and not beyond the end of run(); `limit` names what set it.
double VofSolver::Impl::next_dt(const Courant& co, double dt, double time_left, const char*& limit) const {
  const double f_mat = cfg.max_co / std::max(co.co, 1e-30), f_int = cfg.max_alpha_co / std::max(co.alpha_co, 1e-30),
               f_air = cfg.max_air_co / std::max(co.air_co, 1e-30);
  const double fac = std::min({f_mat, f_int, f_air});
  const double grow = std::min(std::min(fac, 1.0 + 0.1 * fac), 1.2);
  limit = grow == 1.2 ? "growth" : fac == f_mat ? "material" : fac == f_int ? "interface" : "air";
  if (grow * dt >= cfg.dt_max) limit = "largest step";
  dt = std::min(grow * dt, cfg.dt_max);
  if (time_left < dt) limit = "end time";
  return std::min(dt, std::max(1e-12, time_left));
}

// Hydrostatic pressure: the pressure equation with no velocity and unit 1/A. Inflow faces carry
// their flux from the start, and the fluxes inside start divergence-free: the potential flow that
// carries the inflow to the openings (the same equation without gravity). Starting from zero
// inside instead piled the first step's inflow into the inflow cells (alpha up to 1.03 in B4).
void VofSolver::Impl::initial_pressure(double t) {
  bc_ctx.t0 = bc_ctx.t1 = bc_ctx.tp0 = bc_ctx.tp1 = t;
  bcs.begin_step(bc_ctx);
  UEqn.unit_coefficients();
  region.clear();
  region.update(true);
  pEqn.make_system();
  pEqn.correct(F, UEqn, {.initial = true, .final = true}, t);
  std::fill(F.phi.begin(), F.phi.end(), 0.0);
  bool inflow = false;
  for (int f = m.n_internal; f < m.faces(); ++f)
    if (const auto q = bcs[f].fixed_flux(bc_ctx, f)) {
      F.phi[f] = *q;
      inflow = true;
    }
  if (ranks.comm().any(inflow) && bcs.has_opening()) {
    const auto p_rgh = F.p_rgh, p = F.p;
    hydrostatics.zero();
    pEqn.correct(F, UEqn, {.initial = true, .final = true}, t);
    F.p_rgh = p_rgh;
    F.p = p;
    update_gravity(t);
  }
}

// Over the halo; the material beyond it does not change (its sums were taken with the region).
// Split over ranks, over each rank's own cells, then over the ranks.
void VofSolver::Impl::diagnostics(StepStats& st, double t) {
  for (int c : region.halo) div[c] = 0;
  for (int f : region.faces) {
    div[m.owner[f]] += F.phi[f];
    if (internal(m, f)) div[m.neighbour[f]] -= F.phi[f];
  }
  st.alpha_min = region.frozen_min;  // (1e300 and -1e300 where no cell lies outside the halo)
  st.alpha_max = region.frozen_max;
  double volume = ranks.distributed() ? 0.0 : region.frozen_volume;  // (one process: the sum in the order it always had)
  int bad = -1;
  for (int c : region.halo) {
    if (!ranks.own(c)) continue;
    const double a = F.alpha[c];
    const Vec& U = F.U[c];
    st.alpha_min = std::min(st.alpha_min, a);
    st.alpha_max = std::max(st.alpha_max, a);
    volume += a * m.volume[c];
    if (a > 0.5) st.max_speed = std::max(st.max_speed, norm(U));
    if (region.active(c))  // the air at rest outside the active region is a reservoir
      st.divergence = std::max(st.divergence, std::abs(div[c]) / m.volume[c]);
    if (bad < 0 && (!std::isfinite(a) || !std::isfinite(U.x) || !std::isfinite(U.y) || !std::isfinite(U.z))) bad = c;
  }
  st.granular_volume = volume;
  if (ranks.distributed()) {
    const Comm& comm = ranks.comm();
    std::vector<double> hi{-st.alpha_min, st.alpha_max, st.max_speed, st.divergence};
    comm.max(hi);
    st.alpha_min = -hi[0];
    st.alpha_max = hi[1];
    st.max_speed = hi[2];
    st.divergence = hi[3];
    st.granular_volume = region.frozen_volume + comm.sum(volume);
  }
  if (ranks.comm().any(bad >= 0))
    throw VofError("the solution is no longer finite at t = " + std::to_string(t) + " s" + (bad >= 0 ? " (cell " + std::to_string(bad) + ")" : ""));
}

VofSolver::VofSolver(Mesh mesh, VofConfig cfg, Ranks ranks) : mesh_(std::move(mesh)), cfg_(std::move(cfg)), ranks_(std::move(ranks)) {
  impl_ = std::make_unique<Impl>(mesh_, cfg_, ranks_);
  dt_ = cfg_.dt_initial;
  impl_->region.set(std::vector<int>(mesh_.cells(), 0));  // until initialise() finds the material, every cell counts
}

VofSolver::~VofSolver() = default;

std::unique_ptr<VofBackend> make_vof_backend(Mesh mesh, VofConfig cfg) {
  petsc_init();
  const Comm world = Comm::of(PETSC_COMM_WORLD);
  if (world.size > 1) return std::make_unique<DistributedVof>(std::move(mesh), std::move(cfg), world);
  return std::make_unique<VofSolver>(std::move(mesh), std::move(cfg));
}

const std::vector<double>& VofSolver::alpha() const { return impl_->F.alpha; }
const std::vector<Vec>& VofSolver::velocity() const { return impl_->F.U; }
const std::vector<double>& VofSolver::pressure() const { return impl_->F.p; }
const std::vector<double>& VofSolver::viscosity() const { return impl_->F.nu1; }
const std::vector<double>& VofSolver::face_flux() const { return impl_->F.phi; }
const std::vector<double>& VofSolver::granular_flux() const { return impl_->F.alpha_phi; }
const BedLoad& VofSolver::bed_load() const { return impl_->UEqn.bed_load; }
double VofSolver::face_pressure(int f) const {
  const auto& I = *impl_;
  const int o = mesh_.owner[std::size_t(f)];
  const auto& hs = I.hydrostatics;
  return carried_hydrostatically(I.F.p[o], I.F.rho[o], hs.gh(o), hs.ghf(f)) - hs.still_air_p(hs.ghf(f));
}

void VofSolver::initialise(const std::vector<double>& alpha, const std::vector<Vec>& U) {
  auto& I = *impl_;
  auto& F = I.F;
  if (alpha.size() != F.alpha.size())
    throw VofError("initialise: alpha has " + std::to_string(alpha.size()) + " values for " + std::to_string(F.alpha.size()) + " cells");
  F.alpha = alpha;
  for (double a : F.alpha)
    if (!(a >= 0 && a <= 1)) throw VofError("initialise: alpha must lie in [0, 1]");
  t_ = cfg_.t_start;
  if (!U.empty()) {
    if (U.size() != F.U.size()) throw VofError("initialise: velocity size does not match the mesh");
    F.U = U;
  }
  I.update_gravity(t_);
  I.update_rho();
  I.initial_pressure(t_);
  I.UEqn.update_viscosity(F);
}

VofState VofSolver::state() const {
  const auto& I = *impl_;
  const auto& F = I.F;
  VofState st;
  st.t = t_;
  st.dt = dt_;
  st.alpha = F.alpha;
  st.p_rgh = F.p_rgh;
  st.p = F.p;
  st.nu1 = F.nu1;
  st.mu = F.mu;
  st.phi = F.phi;
  st.U = F.U;
  st.active_cells = I.region.cells;
  if (!ranks_.distributed()) {
    I.pressure_solver.save_pc(st);
    return st;
  }
  // A rank's part names the columns by its cells (own and ghosts); DistributedVof::state makes the
  // whole region's rows of them.
  std::unordered_map<PetscInt, int> cell_of;
  for (int c : I.region.cells) cell_of[PetscInt(I.region.global_row[c])] = c;
  PressureSolver::PcColumns cols;
  cols.stored = [&](PetscInt j) {
    const auto it = cell_of.find(j);
    return it == cell_of.end() ? -1 : it->second;
  };
  I.pressure_solver.save_pc(st, cols);
  return st;
}

void VofSolver::restore(const VofState& st) {
  auto& I = *impl_;
  auto& F = I.F;
  const auto nc = std::size_t(mesh_.cells()), nf = std::size_t(mesh_.faces());
  if (st.alpha.size() != nc || st.p_rgh.size() != nc || st.p.size() != nc || st.nu1.size() != nc || st.mu.size() != nc ||
      st.U.size() != nc || st.phi.size() != nf)
    throw VofError("restore: the checkpoint's fields do not match the mesh (" + std::to_string(nc) + " cells, " + std::to_string(nf) +
                   " faces)");
  for (int c : st.active_cells)
    if (c < 0 || std::size_t(c) >= nc) throw VofError("restore: the checkpoint's active region names a cell outside the mesh");
  if (!(st.t >= 0 && st.dt > 0)) throw VofError("restore: the checkpoint's time or time step is not valid");
  t_ = st.t;
  dt_ = st.dt;
  F.alpha = st.alpha;
  F.p_rgh = st.p_rgh;
  F.p = st.p;
  F.nu1 = st.nu1;
  F.phi = st.phi;
  F.U = st.U;
  I.bc_ctx.t0 = I.bc_ctx.tp0 = t_ - dt_;  // the conditions as in the step that led here
  I.bc_ctx.t1 = I.bc_ctx.tp1 = t_;
  I.bcs.begin_step(I.bc_ctx);
  I.update_gravity(t_, true);
  // rho from alpha everywhere (outside the halo it was last computed from the same alpha).
  I.region.set(std::vector<int>(nc, 0));
  I.update_rho();
  std::vector<int> d(nc, -1);
  for (int c : st.active_cells) d[c] = 0;
  I.region.set(d);
  // The resting air's values as the run left them (they seed the solvers when cells join the region).
  F.p_rgh = st.p_rgh;
  F.p = st.p;
  F.U = st.U;
  F.mu = st.mu;
  I.pEqn.make_system();
  PressureSolver::PcColumns cols;  // a rank's part: its cells (VofSolver::state)
  if (ranks_.distributed())
    cols.system = [&](int c) { return c >= 0 && std::size_t(c) < nc ? PetscInt(I.region.global_row[c]) : PetscInt(-1); };
  I.pressure_solver.restore_pc(st, !I.bcs.has_opening() && I.region.whole_mesh(), cols);
}

// One step: the phase fraction with the last fluxes, then the momentum matrix and the pressure
// correctors (PISO; PIMPLE with outer correctors), then the viscosity of the new velocity.
StepStats VofSolver::step(double t_limit) {
  using clk = std::chrono::steady_clock;
  const auto t0 = clk::now();
  auto& I = *impl_;
  auto& F = I.F;
  StepStats st;
  const auto co = I.courant(dt_);  // of the last step's fluxes
  const char* limit = "";
  dt_ = I.next_dt(co, dt_, t_limit - t_, limit);
  t_ += dt_;
  I.bc_ctx.tp0 = I.bc_ctx.t0;  // the step whose pressure solve gave the fluxes alpha is carried by
  I.bc_ctx.tp1 = I.bc_ctx.t1;
  I.bc_ctx.t0 = t_ - dt_;
  I.bc_ctx.t1 = t_;
  I.bcs.begin_step(I.bc_ctx);
  // A coupled inflow that starts in this step must find its cells in the region before alpha moves.
  if (!I.region.seeds_inside() && I.region.update(true)) I.pEqn.make_system();
  I.update_gravity(t_);
  I.keep_old_time();

  I.alpha_eqn.solve(F, dt_, cfg_.gravity(t_));  // alpha, alpha_phi, rho_phi
  I.update_rho();             // rho(alpha)
  if (I.region.update(false)) I.pEqn.make_system();

  double t_p = 0;
  I.pressure_solver.ksp_seconds = 0;
  const int n_outer = std::max(1, cfg_.n_outer_correctors), n_corr = std::max(1, cfg_.n_correctors);
  for (int outer = 0; outer < n_outer; ++outer) {
    I.pressure_solver.later_outer = outer > 0;
    if (outer > 0) I.UEqn.update_viscosity(F);  // grad U, nu1 and mu from the latest velocity and pressure
    else I.UEqn.velocity_gradient(F);
    I.UEqn.build(F, dt_);  // ddt(rho, U) + div(rho_phi, U) - laplacian(mu_f, U) = div(mu_f (grad U)^T) + boundaries
    I.hydrostatics.update_non_orthogonal_force(I.cell_faces, I.region.faces, I.region.halo);  // the last pressure's force (non-orthogonal meshes)
    if (cfg_.momentum_predictor) st.momentum_iterations += I.UEqn.predict(F, t_);
    for (int k = 0; k < n_corr; ++k) {
      I.UEqn.update_HbyA(F);
      if (cfg_.consistent && k > 0) I.hydrostatics.update_non_orthogonal_force(I.cell_faces, I.region.faces, I.region.halo);
      const auto tp = clk::now();
      const bool final = outer + 1 == n_outer && k + 1 == n_corr;
      st.pressure_iterations += I.pEqn.correct(F, I.UEqn, {.reuse = k > 0, .final = final}, t_);  // p_rgh, phi, U
      t_p += std::chrono::duration<double>(clk::now() - tp).count();
    }
  }
  I.pressure_solver.later_outer = false;
  I.UEqn.update_viscosity(F);

  st.t = t_;
  st.dt = dt_;
  st.co = co.co;
  st.alpha_co = co.alpha_co;
  st.air_co = co.air_co;
  st.dt_limit = limit;
  st.active_cells = int(I.region.n_active_total);
  I.diagnostics(st, t_);
  st.seconds_pressure = t_p;
  st.seconds_pressure_solve = I.pressure_solver.ksp_seconds;
  st.seconds_total = std::chrono::duration<double>(clk::now() - t0).count();
  return st;
}

void VofSolver::run(double t_end, const std::function<bool(const StepStats&)>& hook) {
  VofStepping e(*this);
  LoopSchedule schedule;
  schedule.t_end = t_end;
  schedule.progress_every = 1;
  LoopHooks h;
  if (hook) h.progress = [&](const Progress&) { return hook(e.last()); };
  LoopState loop;
  run_steps(e, schedule, loop, h, false);
}

}  // namespace runout::engine::vof
