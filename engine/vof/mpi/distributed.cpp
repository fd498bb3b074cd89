#include "engine/vof/mpi/distributed.hpp"

#include <algorithm>

#include "engine/vof/error.hpp"
#include "engine/vof/solver.hpp"

namespace runout::engine::vof {

namespace {

enum Field : unsigned { kAlpha = 1, kU = 2, kP = 4, kNu = 8, kPhi = 16, kAphi = 32, kPface = 64 };

// The part's configuration: the rank rim's faces are walls (only ghosts touch them), the part's own
// columns, the whole mesh's cell size, and the coupled inflows asked with the whole mesh's faces.
VofConfig part_config(const VofConfig& cfg, const Mesh& whole, const MeshPart& part) {
  VofConfig c = cfg;
  c.bc[kRankRim].kind = Bc::wall;
  c.column_friction.columns = part.columns;
  if (c.mean_cell_size <= 0) c.mean_cell_size = whole.mean_cell_size();
  for (auto& [name, bc] : c.bc)
    if (bc.timed_inflow) {
      bc.timed_inflow = [inner = bc.timed_inflow, fg = part.face_global](int f, double t0, double t1, Vec& u, double& a) {
        return inner(fg[std::size_t(f)], t0, t1, u, a);
      };
    }
  return c;
}

// The pressure preconditioner's state as it stands (a run on one rank: its part is the whole mesh).
void copy_pc(const VofState& from, VofState& to) {
  to.steps_since_pc = from.steps_since_pc;
  to.pc_builds = from.pc_builds;
  to.pc_rows = from.pc_rows;
  to.pc_cols = from.pc_cols;
  to.pc_values = from.pc_values;
  to.pc_first_values = from.pc_first_values;
}

// The pressure preconditioner's operators of the ranks' rows (each rank's: its own region cells in
// ascending order, columns as cells of its part; VofSolver::state) as the whole region's compressed
// rows: rows and columns by the whole region's cells in ascending order, the format of a run on one
// process (VofState). st.active_cells is the whole region.
void gather_pc(const VofState& ps, const MeshPart& part, const Comm& comm, int whole_cells, VofState& st) {
  std::vector<int> ids;      // (row, column) as cells of the whole mesh
  std::vector<double> vals;  // (value at the latest build, value at the first)
  const std::size_t rows = ps.pc_rows.empty() ? 0 : ps.pc_rows.size() - 1;
  for (std::size_t k = 0; k < rows; ++k) {
    const int row = part.cell_global[std::size_t(ps.active_cells[k])];
    for (int e = ps.pc_rows[k]; e < ps.pc_rows[k + 1]; ++e) {
      const int c = ps.pc_cols[std::size_t(e)];
      if (c < 0 || std::size_t(c) >= part.cell_global.size()) throw VofError("state: the pressure operator names a cell outside the rank's part");
      ids.insert(ids.end(), {row, part.cell_global[std::size_t(c)]});
      vals.insert(vals.end(), {ps.pc_values[std::size_t(e)], ps.pc_first_values[std::size_t(e)]});
    }
  }
  const std::vector<int> all_ids = comm.all_gather(ids);
  const std::vector<double> all_vals = comm.all_gather(vals);
  std::vector<int> at(std::size_t(whole_cells), -1);  // a cell's place in the whole region
  for (std::size_t k = 0; k < st.active_cells.size(); ++k) at[std::size_t(st.active_cells[k])] = int(k);
  struct Entry {
    int row, col;
    double v, first;
  };
  std::vector<Entry> e(all_ids.size() / 2);
  for (std::size_t q = 0; q < e.size(); ++q) {
    e[q] = {at[std::size_t(all_ids[2 * q])], at[std::size_t(all_ids[2 * q + 1])], all_vals[2 * q], all_vals[2 * q + 1]};
    if (e[q].row < 0 || e[q].col < 0) throw VofError("state: the pressure operator names a cell outside the active region");
  }
  std::sort(e.begin(), e.end(), [](const Entry& a, const Entry& b) { return a.row != b.row ? a.row < b.row : a.col < b.col; });
  st.pc_rows.assign(1, 0);
  std::size_t q = 0;
  for (int r = 0; r < int(st.active_cells.size()); ++r) {
    for (; q < e.size() && e[q].row == r; ++q) {
      st.pc_cols.push_back(e[q].col);
      st.pc_values.push_back(e[q].v);
      st.pc_first_values.push_back(e[q].first);
    }
    st.pc_rows.push_back(int(st.pc_cols.size()));
  }
}

// The whole region's compressed rows (a checkpoint's, written on any rank count) as this rank's:
// the rows of its own region cells in ascending order, columns as cells of its part. local: a
// whole-mesh cell's number in the part (-1: not in it).
void scatter_pc(const VofState& st, const MeshPart& part, const std::vector<int>& local, VofState& ps) {
  ps.steps_since_pc = st.steps_since_pc;
  ps.pc_builds = st.pc_builds;
  if (st.pc_builds <= 0) return;
  const std::size_t n = st.active_cells.size();
  if (st.pc_rows.size() != n + 1 || st.pc_cols.size() != st.pc_values.size() || st.pc_first_values.size() != st.pc_values.size() ||
      st.pc_rows.back() != int(st.pc_cols.size()))
    throw VofError("restore: the checkpoint's pressure operator does not match its active region");
  std::vector<int> at(local.size(), -1);
  for (std::size_t k = 0; k < n; ++k) at[std::size_t(st.active_cells[k])] = int(k);
  ps.pc_rows.assign(1, 0);
  for (int c : ps.active_cells) {
    if (c >= part.owned) break;  // (own cells first: the part numbers them before its ghosts)
    const int k = at[std::size_t(part.cell_global[std::size_t(c)])];
    const int k0 = st.pc_rows[std::size_t(k)], k1 = st.pc_rows[std::size_t(k) + 1];
    if (k0 < 0 || k1 < k0 || std::size_t(k1) > st.pc_cols.size()) throw VofError("restore: the checkpoint's pressure operator is damaged");
    for (int e = k0; e < k1; ++e) {
      const int j = st.pc_cols[std::size_t(e)];
      const int lc = j >= 0 && std::size_t(j) < n ? local[std::size_t(st.active_cells[std::size_t(j)])] : -1;
      if (lc < 0) throw VofError("restore: the checkpoint's pressure operator is damaged (it couples cells that are not neighbours)");
      ps.pc_cols.push_back(lc);
      ps.pc_values.push_back(st.pc_values[std::size_t(e)]);
      ps.pc_first_values.push_back(st.pc_first_values[std::size_t(e)]);
    }
    ps.pc_rows.push_back(int(ps.pc_cols.size()));
  }
}

}  // namespace

DistributedVof::DistributedVof(Mesh whole, VofConfig cfg, Comm comm) : whole_(std::move(whole)) {
  partition_ = partition_cells(whole_, cfg.column_friction.columns, comm.size, cfg.gravity(cfg.t_start));
  part_ = mesh_part(whole_, partition_, comm.rank, cfg.column_friction.columns);
  std::vector<int> face_rank(std::size_t(whole_.faces()));
  for (int f = 0; f < whole_.faces(); ++f) face_rank[std::size_t(f)] = partition_.part[std::size_t(whole_.owner[f])];
  owned_faces_ = owned_by(face_rank, comm.size);
  for (int f = 0; f < part_.mesh.faces(); ++f)
    if (part_.mesh.owner[f] < part_.owned) my_faces_.push_back(f);
  solver_ = std::make_unique<VofSolver>(part_.mesh, part_config(cfg, whole_, part_), Ranks(Halo(comm, part_.halo, part_.owned_cells), part_.owned));
}

DistributedVof::~DistributedVof() = default;

template <class T>
const std::vector<T>& DistributedVof::cells(std::vector<T>& cache, int k, const std::vector<T>& local) const {
  if (!(fresh_ & unsigned(k))) {
    ranks().halo().gather(local, cache);
    fresh_ |= unsigned(k);
  }
  return cache;
}

const std::vector<double>& DistributedVof::faces(std::vector<double>& cache, int k, const std::vector<double>& local) const {
  if (!(fresh_ & unsigned(k))) {
    std::vector<double> mine(my_faces_.size());
    for (std::size_t i = 0; i < my_faces_.size(); ++i) mine[i] = local[std::size_t(my_faces_[i])];
    cache.resize(std::size_t(whole_.faces()));
    gather_owned(ranks().comm(), owned_faces_, mine.data(), cache.data(), sizeof(double));
    fresh_ |= unsigned(k);
  }
  return cache;
}

void DistributedVof::initialise(const std::vector<double>& alpha, const std::vector<Vec>& U) {
  if (alpha.size() != std::size_t(whole_.cells()))
    throw VofError("initialise: alpha has " + std::to_string(alpha.size()) + " values for " + std::to_string(whole_.cells()) + " cells");
  if (!U.empty() && U.size() != alpha.size()) throw VofError("initialise: velocity size does not match the mesh");
  std::vector<double> a(part_.cell_global.size());
  std::vector<Vec> u(U.empty() ? 0 : a.size());
  for (std::size_t c = 0; c < a.size(); ++c) {
    a[c] = alpha[std::size_t(part_.cell_global[c])];
    if (!U.empty()) u[c] = U[std::size_t(part_.cell_global[c])];
  }
  solver_->initialise(a, u);
  stale();
}

// The whole mesh's state from the ranks' own cells and faces; the active region as the whole
// mesh's cell numbers; the pressure preconditioner's operators as the whole region's rows (so that a
// run continued on the same rank count builds the same blocks, and on any other its own from the
// same operator).
VofState DistributedVof::state() const {
  const VofState ps = solver_->state();
  VofState st;
  st.t = ps.t;
  st.dt = ps.dt;
  const Halo& h = ranks().halo();
  h.gather(ps.alpha, st.alpha);
  h.gather(ps.p_rgh, st.p_rgh);
  h.gather(ps.p, st.p);
  h.gather(ps.nu1, st.nu1);
  h.gather(ps.mu, st.mu);
  h.gather(ps.U, st.U);
  std::vector<double> phi;
  faces(phi, 0, ps.phi);  // (k = 0: never cached)
  st.phi = std::move(phi);
  std::vector<int> mine(std::size_t(part_.owned), 0), whole;
  for (int c : ps.active_cells)
    if (c < part_.owned) mine[std::size_t(c)] = 1;
  h.gather(mine, whole);
  for (int c = 0; c < whole_.cells(); ++c)
    if (whole[std::size_t(c)]) st.active_cells.push_back(c);
  if (!ranks().distributed()) {  // one rank: its part is the whole mesh, its format the whole's
    copy_pc(ps, st);
    return st;
  }
  st.steps_since_pc = ps.steps_since_pc;  // (every rank's alike: the refresh is decided with the matrix)
  st.pc_builds = ps.pc_builds;
  if (ps.pc_builds > 0) gather_pc(ps, part_, ranks().comm(), whole_.cells(), st);
  return st;
}

void DistributedVof::restore(const VofState& st) {
  const auto nc = std::size_t(whole_.cells()), nf = std::size_t(whole_.faces());
  if (st.alpha.size() != nc || st.p_rgh.size() != nc || st.p.size() != nc || st.nu1.size() != nc || st.mu.size() != nc ||
      st.U.size() != nc || st.phi.size() != nf)
    throw VofError("restore: the checkpoint's fields do not match the mesh (" + std::to_string(nc) + " cells, " + std::to_string(nf) +
                   " faces)");
  VofState ps;
  ps.t = st.t;
  ps.dt = st.dt;
  for (int g : part_.cell_global) {
    ps.alpha.push_back(st.alpha[std::size_t(g)]);
    ps.p_rgh.push_back(st.p_rgh[std::size_t(g)]);
    ps.p.push_back(st.p[std::size_t(g)]);
    ps.nu1.push_back(st.nu1[std::size_t(g)]);
    ps.mu.push_back(st.mu[std::size_t(g)]);
    ps.U.push_back(st.U[std::size_t(g)]);
  }
  for (int g : part_.face_global) ps.phi.push_back(st.phi[std::size_t(g)]);
  std::vector<int> local(nc, -1);
  for (std::size_t c = 0; c < part_.cell_global.size(); ++c) local[std::size_t(part_.cell_global[c])] = int(c);
  for (int g : st.active_cells) {
    if (g < 0 || std::size_t(g) >= nc) throw VofError("restore: the checkpoint's active region names a cell outside the mesh");
    if (local[std::size_t(g)] >= 0) ps.active_cells.push_back(local[std::size_t(g)]);
  }
  std::sort(ps.active_cells.begin(), ps.active_cells.end());
  if (ranks().distributed())
    scatter_pc(st, part_, local, ps);
  else
    copy_pc(st, ps);  // one rank: the whole mesh's format is its own
  solver_->restore(ps);
  stale();
}

StepStats DistributedVof::step(double t_limit) {
  const StepStats st = solver_->step(t_limit);
  stale();
  return st;
}

double DistributedVof::time() const { return solver_->time(); }
const Ranks& DistributedVof::ranks() const { return solver_->ranks(); }
Ranks::Traffic DistributedVof::take_traffic() const { return ranks().take_traffic(); }
const std::vector<double>& DistributedVof::alpha() const { return cells(alpha_, kAlpha, solver_->alpha()); }
const std::vector<Vec>& DistributedVof::velocity() const { return cells(U_, kU, solver_->velocity()); }
const std::vector<double>& DistributedVof::pressure() const { return cells(p_, kP, solver_->pressure()); }
const std::vector<double>& DistributedVof::viscosity() const { return cells(nu_, kNu, solver_->viscosity()); }
const std::vector<double>& DistributedVof::face_flux() const { return faces(phi_, kPhi, solver_->face_flux()); }
const std::vector<double>& DistributedVof::granular_flux() const { return faces(aphi_, kAphi, solver_->granular_flux()); }
const BedLoad& DistributedVof::bed_load() const { return solver_->bed_load(); }

// Every boundary face's pressure, from the rank that owns its cell, gathered at the first call after
// a step (internal faces hold 0).
double DistributedVof::face_pressure(int f) const {
  if (!(fresh_ & kPface)) {
    std::vector<double> local(std::size_t(part_.mesh.faces()), 0.0);
    for (int k : my_faces_)
      if (k >= part_.mesh.n_internal) local[std::size_t(k)] = solver_->face_pressure(k);
    faces(pface_, kPface, local);
  }
  return pface_[std::size_t(f)];
}

}  // namespace runout::engine::vof
