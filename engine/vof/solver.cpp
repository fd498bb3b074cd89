#include "engine/vof/solver.hpp"

#include <petscksp.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <span>

namespace runout::engine::vof {

namespace {

constexpr double kPi = 3.14159265358979323846;

void petsc_check(PetscErrorCode e, const char* what) {
  if (e) throw VofError(std::string("PETSc: ") + what + " failed (error " + std::to_string(int(e)) + ")");
}

// PETSc (and with it MPI) is started once per process, on first use. Signals stay the program's
// business (a worker's or a CLI run's SIGTERM/SIGINT handler stops the run at the end of a step
// with a checkpoint; a server ignores SIGPIPE): PETSc's own handlers are removed, and since removing
// them leaves the default dispositions, the ones the program had set are put back.
void petsc_init() {
  static std::once_flag once;
  std::call_once(once, [] {
    PetscBool started = PETSC_FALSE;
    PetscInitialized(&started);
    if (!started) {
      std::vector<struct sigaction> before(NSIG);
      for (int sig = 1; sig < NSIG; ++sig) sigaction(sig, nullptr, &before[std::size_t(sig)]);
      petsc_check(PetscInitializeNoArguments(), "PetscInitialize");
      PetscPopSignalHandler();
      for (int sig = 1; sig < NSIG; ++sig) {
        if (sig == SIGKILL || sig == SIGSTOP || sig == SIGCHLD) continue;
        struct sigaction now{};
        if (sigaction(sig, nullptr, &now) != 0) continue;
        if (now.sa_handler != before[std::size_t(sig)].sa_handler) sigaction(sig, &before[std::size_t(sig)], nullptr);
      }
    }
  });
}

struct Grad {  // a 2x2 (plane) or 3x3 velocity gradient, row i = d/dx_i
  double g[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
};

double comp(const Vec& v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }
void add_comp(Vec& v, int i, double a) { (i == 0 ? v.x : i == 1 ? v.y : v.z) += a; }

}  // namespace

struct VofSolver::Impl {
  VofSolver& s;
  const Mesh& m;
  int nc = 0, nf = 0, dims = 2;
  std::vector<Bc> face_bc;             // per boundary face (index f - n_internal)
  std::vector<const PatchBc*> face_pbc;
  // Faces of each cell in ascending order, stored flat (cell_faces[c] is a span of face_list).
  struct CellFaces {
    std::vector<int> start, face_list;
    std::span<const int> operator[](std::size_t c) const {
      return {face_list.data() + start[c], std::size_t(start[c + 1] - start[c])};
    }
  } cell_faces;
  bool has_dirichlet = false;
  // Pressure system.
  Mat A = nullptr;
  ::Vec x = nullptr, b = nullptr, r = nullptr, dx = nullptr;
  KSP ksp = nullptr;
  // Work arrays.
  std::vector<double> rho, rho_old, mu, A_D, rAU, rAUf, gh, ghf, alpha_phi, rho_phi;
  std::vector<double> rAtU, rAtUf;  // the consistent coefficients (VofConfig::consistent)
  std::vector<Vec> H, HbyA, bsrc;
  std::vector<double> cO, cN;
  Mat Mu = nullptr;
  ::Vec xu = nullptr, bu = nullptr;  // the momentum predictor's vectors (every cell)
  Mat Apin = nullptr;  // closed domains: the pressure matrix with cell 0 pinned
  // Copies of the operators the pressure preconditioner was built from, at the current pressure
  // solver's latest build and at its first (nullptr: none built yet), and the number of builds. A
  // checkpoint carries them, so that restore() builds the preconditioner the uninterrupted run
  // keeps using until its next refresh (remember_pc).
  Mat Apc = nullptr, Apc_first = nullptr;
  int pc_builds = 0;
  KSP kspU = nullptr;
  std::vector<std::array<double, 6>> recon_inv;  // inverse of sum Sf Sf / |Sf|: xx, xy, xz, yy, yz, zz

  // fvc::reconstruct: the cell vector whose face projections best match the face values q (sum of
  // q Sf over the faces in r).
  Vec reconstruct(int c, const Vec& r) const {
    const auto& T = recon_inv[std::size_t(c)];
    return {T[0] * r.x + T[1] * r.y + T[2] * r.z, T[1] * r.x + T[3] * r.y + T[4] * r.z, T[2] * r.x + T[4] * r.y + T[5] * r.z};
  }

  explicit Impl(VofSolver& solver) : s(solver), m(solver.mesh_), tan_phi(std::tan(solver.cfg_.phi_deg * kPi / 180)) {}
  const double tan_phi;  // the granular phase's tan(phi)
  ~Impl() {
    if (ksp) KSPDestroy(&ksp);
    if (kspU) KSPDestroy(&kspU);
    if (Mu) MatDestroy(&Mu);
    if (Apin) MatDestroy(&Apin);
    if (Apc) MatDestroy(&Apc);
    if (Apc_first) MatDestroy(&Apc_first);
    if (A) MatDestroy(&A);
    if (x) VecDestroy(&x);
    if (b) VecDestroy(&b);
    if (r) VecDestroy(&r);
    if (dx) VecDestroy(&dx);
    if (xu) VecDestroy(&xu);
    if (bu) VecDestroy(&bu);
  }

  const PatchBc& bc_of(int f) const { return *face_pbc[std::size_t(f - m.n_internal)]; }
  Bc kind_of(int f) const { return face_bc[std::size_t(f - m.n_internal)]; }

  void setup() {
    nc = m.cells();
    nf = m.faces();
    dims = m.thickness > 0 ? 2 : 3;
    face_bc.resize(std::size_t(nf - m.n_internal));
    face_pbc.resize(face_bc.size());
    for (const auto& p : m.patches) {
      const auto it = s.cfg_.bc.find(p.name);
      if (it == s.cfg_.bc.end()) throw VofError("boundary conditions: patch '" + p.name + "' has none");
      if (it->second.kind == Bc::inflow && (!it->second.inflow_velocity || !it->second.inflow_alpha))
        throw VofError("boundary conditions: inflow patch '" + p.name + "' needs a velocity and a phase-fraction profile");
      if (it->second.kind == Bc::atmosphere) has_dirichlet = true;
      for (int f = p.start; f < p.start + p.size; ++f) {
        face_bc[std::size_t(f - m.n_internal)] = it->second.kind;
        face_pbc[std::size_t(f - m.n_internal)] = &it->second;
      }
    }
    for (const auto& [name, _] : s.cfg_.bc)
      if (m.patch_index(name) < 0) throw VofError("boundary conditions: the mesh has no patch '" + name + "'");
    if (s.cfg_.rheology != "coulomb") throw VofError("rheology: unknown '" + s.cfg_.rheology + "' (valid: coulomb)");
    if (!(s.cfg_.phi_deg > 0 && s.cfg_.phi_deg < 90)) throw VofError("phi_deg must lie in (0, 90)");
    if (!(s.cfg_.momentum_rtol > 0 && s.cfg_.momentum_rtol < 1)) throw VofError("momentum_rtol must lie in (0, 1)");
    if (!(s.cfg_.consistent_alpha > 0 && s.cfg_.consistent_alpha <= 1)) throw VofError("consistent_alpha must lie in (0, 1]");
    {
      auto& cf = cell_faces;
      cf.start.assign(std::size_t(nc) + 1, 0);
      for (int f = 0; f < nf; ++f) {
        ++cf.start[std::size_t(m.owner[std::size_t(f)]) + 1];
        if (f < m.n_internal) ++cf.start[std::size_t(m.neighbour[std::size_t(f)]) + 1];
      }
      for (int c = 0; c < nc; ++c) cf.start[std::size_t(c) + 1] += cf.start[std::size_t(c)];
      cf.face_list.assign(std::size_t(cf.start[std::size_t(nc)]), 0);
      std::vector<int> next(cf.start.begin(), cf.start.end() - 1);
      for (int f = 0; f < nf; ++f) {
        cf.face_list[std::size_t(next[std::size_t(m.owner[std::size_t(f)])]++)] = f;
        if (f < m.n_internal) cf.face_list[std::size_t(next[std::size_t(m.neighbour[std::size_t(f)])]++)] = f;
      }
    }
    // Reconstruction tensors.
    recon_inv.resize(static_cast<std::size_t>(nc));
    for (int c = 0; c < nc; ++c) {
      double t[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
      for (int f : cell_faces[std::size_t(c)]) {
        const Vec& S = m.Sf[std::size_t(f)];
        const double a = m.magSf[std::size_t(f)];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) t[i][j] += comp(S, i) * comp(S, j) / a;
      }
      if (dims == 2) {  // plane meshes have no front and back faces: invert the x-y block
        const double det = t[0][0] * t[1][1] - t[0][1] * t[0][1];
        recon_inv[std::size_t(c)] = {t[1][1] / det, -t[0][1] / det, 0, t[0][0] / det, 0, 0};
      } else {
        const double a = t[0][0], b = t[0][1], cc = t[0][2], d = t[1][1], e = t[1][2], f = t[2][2];
        const double A = d * f - e * e, B = cc * e - b * f, C = b * e - cc * d;
        const double det = a * A + b * B + cc * C;
        recon_inv[std::size_t(c)] = {A / det, B / det, C / det, (a * f - cc * cc) / det, (b * cc - a * e) / det, (a * d - b * b) / det};
      }
    }
    petsc_init();
    std::vector<PetscInt> nnz(std::size_t(nc), 1);
    for (int f = 0; f < m.n_internal; ++f) {
      ++nnz[std::size_t(m.owner[std::size_t(f)])];
      ++nnz[std::size_t(m.neighbour[std::size_t(f)])];
    }
    make_pressure_ksp();  // checks the preconditioner's name early
    rho.assign(std::size_t(nc), 0);
    rho_old = rho;
    mu = rho;
    A_D = rho;
    rAU = rho;
    gh = rho;
    rAUf.assign(std::size_t(nf), 0);
    rAtU = rAU;
    rAtUf = rAUf;
    ghf = rAUf;
    alpha_phi = rAUf;
    rho_phi = rAUf;
    H.assign(std::size_t(nc), Vec{});
    HbyA = H;
    bsrc = H;
    cO.assign(std::size_t(nf), 0);
    cN = cO;
    G.assign(std::size_t(nc), Grad{});
    U_old.assign(std::size_t(nc), Vec{});
    wf1.assign(std::size_t(nf), 0);
    for (auto* v : {&wf2, &pf_phiHbyA, &pf_phig, &pf_coef, &pf_pout}) *v = wf1;
    pf_open.assign(std::size_t(nf), 0);
    wc1.assign(std::size_t(nc), 0);
    for (auto* v : {&wc2, &wc3, &wc4, &wc5, &wc6, &wc7}) *v = wc1;
    wv1.assign(std::size_t(nc), Vec{});
    pf_rec = wv1;
    pf_rec_old = wv1;
    double vsum = 0;
    for (double v : m.volume) vsum += v;
    mean_cell_size = std::cbrt(vsum / nc);
    petsc_check(MatCreateSeqAIJ(PETSC_COMM_SELF, nc, nc, 0, nnz.data(), &Mu), "MatCreateSeqAIJ");
    petsc_check(VecCreateSeq(PETSC_COMM_SELF, nc, &xu), "VecCreateSeq");
    petsc_check(VecDuplicate(xu, &bu), "VecDuplicate");
    petsc_check(KSPCreate(PETSC_COMM_SELF, &kspU), "KSPCreate");
    petsc_check(KSPSetType(kspU, KSPBCGS), "KSPSetType");
    PC pcu;
    petsc_check(KSPGetPC(kspU, &pcu), "KSPGetPC");
    petsc_check(PCSetType(pcu, PCILU), "PCSetType ilu");
    petsc_check(KSPSetTolerances(kspU, s.cfg_.momentum_rtol, 1e-300, PETSC_DEFAULT, 2000), "KSPSetTolerances");
    petsc_check(KSPSetInitialGuessNonzero(kspU, PETSC_TRUE), "KSPSetInitialGuessNonzero");
    petsc_check(KSPSetOptionsPrefix(kspU, "runout_u_"), "KSPSetOptionsPrefix");
    petsc_check(KSPSetFromOptions(kspU), "KSPSetFromOptions");
  }

  void update_gravity(double t) {
    const Vec g = s.cfg_.gravity(t);
    if (gravity_set && g.x == g_last.x && g.y == g_last.y && g.z == g_last.z) return;
    gravity_set = true;
    g_last = g;
    for (int c = 0; c < nc; ++c) gh[std::size_t(c)] = dot(g, m.centre[std::size_t(c)]);
    for (int f = 0; f < nf; ++f) ghf[std::size_t(f)] = dot(g, m.Cf[std::size_t(f)]);
    gh_ref = 1e300;
    for (int f = m.n_internal; f < nf; ++f)
      if (kind_of(f) == Bc::atmosphere) gh_ref = std::min(gh_ref, ghf[std::size_t(f)]);
    if (gh_ref == 1e300)  // a closed domain: the level is zero at its highest cell
      for (int c = 0; c < nc; ++c) gh_ref = std::min(gh_ref, gh[std::size_t(c)]);
  }

  // Outside the domain's openings, and outside the active region, is air at rest: hydrostatic,
  // p = rho_air g.(x - x_ref), zero at the highest point open to the atmosphere (x_ref). On an
  // opening next to active cell a, p_rgh_b = p_b - rho_a g.x_b. (Taking p = 0 all along a vertical
  // opening instead drives air through it: the air inside is hydrostatic, and the 1.5 Pa across a
  // 15 cm opening set up a circulation that grew to 5 m/s while the material rested.)
  double still_air_p(double g_dot_x) const { return s.cfg_.rho2 * (g_dot_x - gh_ref); }
  double outside_p_rgh(int f, int a) const {
    const double g = ghf[std::size_t(f)];
    return still_air_p(g) - rho[std::size_t(a)] * g;
  }
  // What the Coulomb viscosity and the Coulomb bed conditions subtract from p at a point with
  // g.x = g_dot_x (VofConfig::coulomb_pressure): nothing, or the still air's pressure there.
  double coulomb_level(double g_dot_x) const { return s.cfg_.coulomb_pressure == CoulombPressure::excess ? still_air_p(g_dot_x) : 0.0; }
  // The pressure on a wall face, as OpenFOAM's p.boundaryField() under the buoyantPressure
  // condition (p_rgh the cell's, the density the cell's, gh the face's): the bed pressure the
  // Coulomb conditions need (listing B.2), not the cell centre's, which in a flow one or two cells
  // deep is half of it or less; less coulomb_level(). Written as the cell's pressure p (from the
  // last pressure solve) carried hydrostatically to the face, p_P + rho_P (gh_f - gh_P): the same
  // as p_rgh_P + rho_P gh_f while the density is the one p was formed with, and independent of the
  // mesh's origin when it is not (at the start of a step the density is already the new one; the
  // form p_rgh_P + rho_P gh_f then added (rho_new - rho_old) g.x_f: estimated 1.4 kPa for a PVC
  // cell filling by 0.1 in a step 2 m from the origin of a 50 deg chute, where the bed pressure is
  // about 100 Pa).
  double wall_pressure(int f, int o) const {
    return s.p_[std::size_t(o)] + rho[std::size_t(o)] * (ghf[std::size_t(f)] - gh[std::size_t(o)]) - coulomb_level(ghf[std::size_t(f)]);
  }
  // The confining pressure of the Coulomb viscosity in cell c: p less coulomb_level().
  double confining_pressure(int c) const { return s.p_[std::size_t(c)] - coulomb_level(gh[std::size_t(c)]); }
  // The last pressure's and the buoyancy's force per area on an internal face, along Sf:
  // -ghf snGrad(rho) - snGrad(p_rgh) (the momentum predictor's and the consistent coupling's F_old).
  double face_force(int f) const {
    const int o = m.owner[std::size_t(f)], nb = m.neighbour[std::size_t(f)];
    const double dl = m.delta_coeff[std::size_t(f)];
    return -ghf[std::size_t(f)] * (rho[std::size_t(nb)] - rho[std::size_t(o)]) * dl - (s.p_rgh_[std::size_t(nb)] - s.p_rgh_[std::size_t(o)]) * dl;
  }
  // The same on an opening (atmosphere, edge of the active region), out of the active cell a, with
  // the outside's p_rgh pout.
  double opening_force(int f, int a, double pout) const { return -(pout - s.p_rgh_[std::size_t(a)]) * m.delta_coeff[std::size_t(f)]; }
  double gh_ref = 0;
  Vec g_last;
  bool gravity_set = false;

  void update_rho(std::vector<double>& r) const {
    const auto& a = s.alpha_;
    for (int c : halo_cells) {
      const double al = std::clamp(a[std::size_t(c)], 0.0, 1.0);
      r[std::size_t(c)] = al * s.cfg_.rho1 + (1 - al) * s.cfg_.rho2;
    }
  }

  // Boundary value of alpha on face f (zero gradient; air enters through the atmosphere).
  double alpha_b(int f) const {
    const int o = m.owner[std::size_t(f)];
    switch (kind_of(f)) {
      case Bc::inflow: return bc_of(f).inflow_alpha(m.Cf[std::size_t(f)]);
      case Bc::atmosphere: return s.phi_[std::size_t(f)] < 0 ? 0.0 : s.alpha_[std::size_t(o)];
      default: return s.alpha_[std::size_t(o)];
    }
  }

  // Gauss gradient of the velocity per cell (boundary values from the conditions).
  // Only faces of the active region contribute (the air beyond rests); the result is kept in G.
  void velocity_gradient() {
    for (int c : halo_cells) G[std::size_t(c)] = Grad{};
    for (int f : active_faces) {
      const int o = m.owner[std::size_t(f)];
      const Vec S = m.Sf[std::size_t(f)];
      Vec Uf;
      if (f < m.n_internal) {
        const double w = m.weight[std::size_t(f)];
        Uf = w * s.U_[std::size_t(o)] + (1 - w) * s.U_[std::size_t(m.neighbour[std::size_t(f)])];
      } else {
        Uf = boundary_velocity(f);
      }
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const double v = comp(S, i) * comp(Uf, j);
          G[std::size_t(o)].g[i][j] += v;
          if (f < m.n_internal) G[std::size_t(m.neighbour[std::size_t(f)])].g[i][j] -= v;
        }
    }
    for (int c : halo_cells)
      for (auto& row : G[std::size_t(c)].g)
        for (double& v : row) v /= m.volume[std::size_t(c)];
  }

  // The velocity on a boundary face.
  Vec boundary_velocity(int f) const {
    const int o = m.owner[std::size_t(f)];
    const Vec Up = s.U_[std::size_t(o)];
    const Vec n = (1.0 / m.magSf[std::size_t(f)]) * m.Sf[std::size_t(f)];
    switch (kind_of(f)) {
      case Bc::wall: return {};
      case Bc::inflow: return bc_of(f).inflow_velocity(m.Cf[std::size_t(f)]);
      case Bc::outflow: return Up;
      case Bc::symmetry: return Up - dot(Up, n) * n;
      case Bc::coulomb_friction:  // material slides (its friction is a force, build_momentum); air sticks
        return s.alpha_[std::size_t(o)] >= 0.5 ? Up - dot(Up, n) * n : Vec{};
      case Bc::atmosphere: {
        // pressureInletOutletVelocity: zero gradient out, the flux's normal velocity in.
        const double ph = s.phi_[std::size_t(f)];
        return ph >= 0 ? Up : (ph / m.magSf[std::size_t(f)]) * n;
      }
      case Bc::coulomb_slip: {
        const Vec ut = Up - dot(Up, n) * n;
        const double mag = norm(ut);
        double vf = 1.0;  // stick
        if (s.alpha_[std::size_t(o)] >= 0.5) {
          const double mub = mu[std::size_t(o)];
          const double pb = wall_pressure(f, o);
          vf = std::clamp(bc_of(f).tan_delta / m.delta_coeff[std::size_t(f)] * pb / std::max(1e-300, mub * mag), 0.0, 1.0);
        }
        return (1 - vf) * ut;
      }
    }
    return {};
  }

  // The mixture viscosity on boundary face f of cell o with the boundary velocity Ub, as OpenFOAM
  // evaluates a strain-rate-dependent viscosity on a patch: the strain rate from the cell's gradient
  // with its normal part replaced by the face's (Ub - U_o) / d (gaussGrad's boundary correction),
  // the pressure the face's (wall_pressure), the phase fraction the face's (alpha_b: the cell's on
  // walls, zero gradient; the inflow's on an inflow).
  double boundary_mu(int f, int o, const Vec& Ub) const {
    const Vec n = (1.0 / m.magSf[std::size_t(f)]) * m.Sf[std::size_t(f)];
    const Vec sn = m.delta_coeff[std::size_t(f)] * (Ub - s.U_[std::size_t(o)]);
    Grad gb = G[std::size_t(o)];
    auto& g = gb.g;
    for (int j = 0; j < 3; ++j) {
      double nG = 0;
      for (int i = 0; i < 3; ++i) nG += comp(n, i) * g[i][j];
      for (int i = 0; i < 3; ++i) g[i][j] += comp(n, i) * (comp(sn, j) - nG);
    }
    const double nu1 = coulomb_nu(wall_pressure(f, o), strain_rate(gb));
    const double al = std::clamp(alpha_b(f), 0.0, 1.0);
    return al * s.cfg_.rho1 * nu1 + (1 - al) * s.cfg_.rho2 * s.cfg_.nu2;
  }

  // |strain rate| = sqrt(2 D:D), D the symmetric part of the velocity gradient (OpenFOAM's
  // strainRate(), sqrt(2) |symm(grad U)|).
  static double strain_rate(const Grad& gr) {
    const auto& g = gr.g;
    double dd = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double d = 0.5 * (g[i][j] + g[j][i]);
        dd += d * d;
      }
    return std::sqrt(2 * dd);
  }
  // The granular phase's Coulomb viscosity tan(phi) p / (rho |strain rate|) for the confining
  // pressure p, clipped to [nu_min, nu_max] (listing B.1).
  double coulomb_nu(double p, double sr) const {
    const double nu = tan_phi * p / (s.cfg_.rho1 * std::max(sr, 1e-300));
    return std::clamp(std::isfinite(nu) ? nu : s.cfg_.nu_max, s.cfg_.nu_min, s.cfg_.nu_max);
  }

  void update_viscosity() {
    velocity_gradient();
    for (int c : active_cells) {
      s.nu1_[std::size_t(c)] = coulomb_nu(confining_pressure(c), strain_rate(G[std::size_t(c)]));
      const double al = std::clamp(s.alpha_[std::size_t(c)], 0.0, 1.0);
      mu[std::size_t(c)] = al * s.cfg_.rho1 * s.nu1_[std::size_t(c)] + (1 - al) * s.cfg_.rho2 * s.cfg_.nu2;
    }
  }

  // Phase fraction: explicit, upwind plus a limited correction toward central differencing with
  // interface compression (Zalesak FCT keeps every cell within its neighbours' bounds and [0, 1]).
  void solve_alpha(double dt) {
    auto& a = s.alpha_;
    const int n = std::max(1, s.cfg_.alpha_subcycles);
    const double dts = dt / n;
    // Only faces of the active region carry flux; alpha changes only in its cells and their
    // neighbours (halo_cells).
    for (int f : active_faces) alpha_phi[std::size_t(f)] = 0;
    auto& FL = wf1;
    auto& AF = wf2;
    auto &amax = wc1, &amin = wc2, &Pp = wc3, &Pm = wc4, &Rp = wc5, &Rm = wc6, &aL = wc7;
    auto& ga = wv1;
    const double delta_n = 1e-8 / mean_cell_size;
    for (int sub = 0; sub < n; ++sub) {
      // Interface normal per cell (Gauss gradient of alpha).
      for (int c : halo_cells) ga[std::size_t(c)] = Vec{};
      for (int f : active_faces) {
        const int o = m.owner[std::size_t(f)];
        const double af = f < m.n_internal ? m.weight[std::size_t(f)] * a[std::size_t(o)] +
                                                 (1 - m.weight[std::size_t(f)]) * a[std::size_t(m.neighbour[std::size_t(f)])]
                                           : alpha_b(f);
        ga[std::size_t(o)] = ga[std::size_t(o)] + af * m.Sf[std::size_t(f)];
        if (f < m.n_internal) ga[std::size_t(m.neighbour[std::size_t(f)])] = ga[std::size_t(m.neighbour[std::size_t(f)])] - af * m.Sf[std::size_t(f)];
      }
      for (int c : halo_cells) ga[std::size_t(c)] = (1.0 / m.volume[std::size_t(c)]) * ga[std::size_t(c)];
      for (int c : halo_cells) amax[std::size_t(c)] = amin[std::size_t(c)] = a[std::size_t(c)];
      for (int f : active_faces) {
        const int o = m.owner[std::size_t(f)];
        const double ph = s.phi_[std::size_t(f)];
        if (f < m.n_internal) {
          const int nb = m.neighbour[std::size_t(f)];
          const double ao = a[std::size_t(o)], an = a[std::size_t(nb)];
          FL[std::size_t(f)] = ph * (ph >= 0 ? ao : an);
          // Central value and compression flux.
          const double w = m.weight[std::size_t(f)];
          const double ac = w * ao + (1 - w) * an;
          Vec gf = w * ga[std::size_t(o)] + (1 - w) * ga[std::size_t(nb)];
          // Unit interface normal; deltaN = 1e-8 / (mean cell size) only keeps the division finite.
          const double nS = dot(gf, m.Sf[std::size_t(f)]) / (norm(gf) + delta_n);
          const double phir = s.cfg_.c_alpha * std::abs(ph) / m.magSf[std::size_t(f)] * nS;
          const double a_up = phir >= 0 ? ao : an, b_up = phir >= 0 ? 1 - an : 1 - ao;
          const double FH = ph * ac + phir * a_up * b_up;
          AF[std::size_t(f)] = FH - FL[std::size_t(f)];
          amax[std::size_t(o)] = std::max(amax[std::size_t(o)], an);
          amin[std::size_t(o)] = std::min(amin[std::size_t(o)], an);
          amax[std::size_t(nb)] = std::max(amax[std::size_t(nb)], ao);
          amin[std::size_t(nb)] = std::min(amin[std::size_t(nb)], ao);
        } else {
          const double ab = ph >= 0 ? a[std::size_t(o)] : alpha_b(f);
          FL[std::size_t(f)] = ph * ab;
          AF[std::size_t(f)] = 0;
          if (ph < 0) {
            amax[std::size_t(o)] = std::max(amax[std::size_t(o)], ab);
            amin[std::size_t(o)] = std::min(amin[std::size_t(o)], ab);
          }
        }
      }
      // Low-order update and the limiter.
      for (int c : halo_cells) {
        aL[std::size_t(c)] = a[std::size_t(c)] * m.volume[std::size_t(c)];
        Pp[std::size_t(c)] = Pm[std::size_t(c)] = 0;
      }
      for (int f : active_faces) {
        const int o = m.owner[std::size_t(f)];
        aL[std::size_t(o)] -= dts * FL[std::size_t(f)];
        if (f < m.n_internal) {
          const int nb = m.neighbour[std::size_t(f)];
          aL[std::size_t(nb)] += dts * FL[std::size_t(f)];
          const double A = AF[std::size_t(f)];
          // A > 0 takes from the owner, gives to the neighbour.
          if (A > 0) {
            Pm[std::size_t(o)] += A;
            Pp[std::size_t(nb)] += A;
          } else {
            Pp[std::size_t(o)] -= A;
            Pm[std::size_t(nb)] -= A;
          }
        }
      }
      for (int c : halo_cells) {
        const double V = m.volume[std::size_t(c)];
        const double lo = aL[std::size_t(c)] / V;
        const double up = std::clamp(amax[std::size_t(c)], 0.0, 1.0), dn = std::clamp(amin[std::size_t(c)], 0.0, 1.0);
        const double Qp = std::max(0.0, (up - lo) * V / dts), Qm = std::max(0.0, (lo - dn) * V / dts);
        Rp[std::size_t(c)] = Pp[std::size_t(c)] > 0 ? std::min(1.0, Qp / Pp[std::size_t(c)]) : 1.0;
        Rm[std::size_t(c)] = Pm[std::size_t(c)] > 0 ? std::min(1.0, Qm / Pm[std::size_t(c)]) : 1.0;
      }
      for (int f : active_faces) {
        double F = FL[std::size_t(f)];
        if (f < m.n_internal) {
          const int o = m.owner[std::size_t(f)], nb = m.neighbour[std::size_t(f)];
          const double A = AF[std::size_t(f)];
          const double lam = A > 0 ? std::min(Rm[std::size_t(o)], Rp[std::size_t(nb)]) : std::min(Rp[std::size_t(o)], Rm[std::size_t(nb)]);
          F += lam * A;
          const double dA = lam * A * dts;
          aL[std::size_t(o)] -= dA;
          aL[std::size_t(nb)] += dA;
        }
        alpha_phi[std::size_t(f)] += F / n;
      }
      for (int c : halo_cells) a[std::size_t(c)] = aL[std::size_t(c)] / m.volume[std::size_t(c)];
    }
    for (int f : active_faces)
      rho_phi[std::size_t(f)] = alpha_phi[std::size_t(f)] * (s.cfg_.rho1 - s.cfg_.rho2) + s.phi_[std::size_t(f)] * s.cfg_.rho2;
  }

  // Viscosity on an internal face: the cells' mixture viscosities interpolated linearly (interFoam's
  // twoPhaseMixture::muf(), which weights each phase's interpolated viscosity by the face's phase
  // fraction, gave the same B2 figures to the third digit under PISO).
  double face_mu(int f) const {
    const double w = m.weight[std::size_t(f)];
    return w * mu[std::size_t(m.owner[std::size_t(f)])] + (1 - w) * mu[std::size_t(m.neighbour[std::size_t(f)])];
  }

  // Momentum matrix (both velocity components share it): diagonal A_D, the neighbour coefficients of
  // each internal face (cO: owner row, cN: neighbour row; A_D U_P - sum c U_nb = bsrc) and the
  // sources. Boundary values and the transpose viscous part are taken from the current velocity.
  void build_momentum(double dt) {
    for (int c : halo_cells) {
      const double V = m.volume[std::size_t(c)];
      A_D[std::size_t(c)] = rho[std::size_t(c)] * V / dt;
      bsrc[std::size_t(c)] = (rho_old[std::size_t(c)] * V / dt) * U_old[std::size_t(c)];
    }
    // Transpose part of the viscous stress, explicit and in divergence form as interFoam has it:
    // sum over faces of mu_f (grad U)^T_f . Sf. (The equivalent cell form (grad U) . grad mu, with
    // mu jumping nine orders of magnitude across the interface, moved a heap that should rest.)
    // The face viscosity is interpolated linearly or taken as the harmonic mean, or the part is left
    // out (VofConfig::viscous_transpose; validation.md B1 and B2 for what each does).
    if (s.cfg_.viscous_transpose != Transpose::off) {
      const bool harmonic = s.cfg_.viscous_transpose == Transpose::harmonic;
      for (int f : active_faces) {
        const int o = m.owner[std::size_t(f)];
        const bool in = f < m.n_internal;
        const int nb = in ? m.neighbour[std::size_t(f)] : o;
        const double w = in ? m.weight[std::size_t(f)] : 1.0;
        const double mo = mu[std::size_t(o)], mn = mu[std::size_t(nb)];
        const double muf = harmonic ? mo * mn / (w * mn + (1 - w) * mo) : (in ? face_mu(f) : mo);
        const Vec& S = m.Sf[std::size_t(f)];
        Vec t;
        for (int i = 0; i < 3; ++i) {
          double v = 0;
          for (int j = 0; j < 3; ++j) v += (w * G[std::size_t(o)].g[i][j] + (1 - w) * G[std::size_t(nb)].g[i][j]) * comp(S, j);
          add_comp(t, i, muf * v);
        }
        bsrc[std::size_t(o)] = bsrc[std::size_t(o)] + t;
        if (in) bsrc[std::size_t(nb)] = bsrc[std::size_t(nb)] - t;
      }
    }
    const bool limited = s.cfg_.momentum_convection == Convection::limited_linear;
    for (int f : active_faces) {
      const int o = m.owner[std::size_t(f)];
      const double F = rho_phi[std::size_t(f)];
      if (f < m.n_internal) {
        const int nb = m.neighbour[std::size_t(f)];
        const double w = m.weight[std::size_t(f)];
        const double muf = face_mu(f);
        const double D = muf * m.magSf[std::size_t(f)] * m.delta_coeff[std::size_t(f)];
        // Row o: + max(F,0) U_o + min(F,0) U_nb + D (U_o - U_nb); row nb: the flux out of nb is -F.
        A_D[std::size_t(o)] += std::max(F, 0.0) + D;
        cO[std::size_t(f)] = D - std::min(F, 0.0);
        A_D[std::size_t(nb)] += std::max(-F, 0.0) + D;
        cN[std::size_t(f)] = D - std::min(-F, 0.0);
        // limitedLinearV 1 (interFoam's damBreak): the face value moves from upwind towards the
        // linear one by a TVD limiter of one ratio per face (the vector's own direction), as a
        // deferred correction on the right-hand side, so the matrix stays upwind.
        if (limited && F != 0) {
          const Vec Uo = s.U_[std::size_t(o)], Un = s.U_[std::size_t(nb)];
          const Vec dU = Un - Uo;
          const double gf = dot(dU, dU);
          if (gf > 0) {
            const Vec d = m.centre[std::size_t(nb)] - m.centre[std::size_t(o)];
            const auto& g = G[std::size_t(F > 0 ? o : nb)].g;
            Vec dg;
            for (int j = 0; j < 3; ++j) {
              double v = 0;
              for (int i = 0; i < 3; ++i) v += comp(d, i) * g[i][j];
              add_comp(dg, j, v);
            }
            const double gc = dot(dU, dg);
            const double r = std::abs(gc) >= 1000 * gf ? 2 * 1000 * (gc > 0 ? 1 : -1) - 1 : 2 * gc / gf - 1;
            const double lim = std::clamp(2 * r, 0.0, 1.0);
            const Vec Ulin = w * Uo + (1 - w) * Un;
            const Vec corr = (F * lim) * (Ulin - (F > 0 ? Uo : Un));
            bsrc[std::size_t(o)] = bsrc[std::size_t(o)] - corr;
            bsrc[std::size_t(nb)] = bsrc[std::size_t(nb)] + corr;
          }
        }
      } else {
        const Bc k = kind_of(f);
        const Vec Ub = boundary_velocity(f);
        // A symmetry plane carries no shear: no viscous term (its normal velocity is held by the flux).
        if (k == Bc::wall || k == Bc::coulomb_slip || k == Bc::inflow || (k == Bc::coulomb_friction && s.alpha_[std::size_t(o)] < 0.5)) {
          // Walls and inflows take the viscosity evaluated on the face (VofConfig::wall_viscosity);
          // the Coulomb slip wall keeps the cell's, from which its slip fraction is computed.
          const bool face_mu_here = s.cfg_.wall_viscosity == WallViscosity::face && k != Bc::coulomb_slip;
          const double D = (face_mu_here ? boundary_mu(f, o, Ub) : mu[std::size_t(o)]) * m.magSf[std::size_t(f)] * m.delta_coeff[std::size_t(f)];
          A_D[std::size_t(o)] += D;
          bsrc[std::size_t(o)] = bsrc[std::size_t(o)] + D * Ub;
        } else if (k == Bc::coulomb_friction) {
          // tan(delta) p |Sf| against the sliding velocity, implicit in the velocity: a drag of
          // tan(delta) p |Sf| / |u_t| (at most the creep speed's), so that the force's magnitude is
          // the friction while the material slides and material held by less comes to rest.
          const Vec n = (1.0 / m.magSf[std::size_t(f)]) * m.Sf[std::size_t(f)];
          const Vec ut = s.U_[std::size_t(o)] - dot(s.U_[std::size_t(o)], n) * n;
          const PatchBc& pb = bc_of(f);
          const double drag = pb.tan_delta * std::max(wall_pressure(f, o), 0.0) * m.magSf[std::size_t(f)] / std::max(norm(ut), pb.friction_creep_speed);
          // The drag sits on the diagonal, which both components share; the part it would put on
          // the velocity normal to the bed is given back explicitly, so that it acts along the bed.
          A_D[std::size_t(o)] += drag;
          bsrc[std::size_t(o)] = bsrc[std::size_t(o)] + (drag * dot(s.U_[std::size_t(o)], n)) * n;
        }
        if (F >= 0) {
          A_D[std::size_t(o)] += F;  // leaves with the cell's velocity
        } else {
          bsrc[std::size_t(o)] = bsrc[std::size_t(o)] + (-F) * Ub;  // brings the boundary's velocity
        }
      }
    }
    for (int c : halo_cells) rAU[std::size_t(c)] = m.volume[std::size_t(c)] / A_D[std::size_t(c)];  // 1 / A per unit volume [m3 s/kg]
    for (int f : active_faces) {
      const int o = m.owner[std::size_t(f)];
      rAUf[std::size_t(f)] = f < m.n_internal ? m.weight[std::size_t(f)] * rAU[std::size_t(o)] +
                                                    (1 - m.weight[std::size_t(f)]) * rAU[std::size_t(m.neighbour[std::size_t(f)])]
                                              : rAU[std::size_t(o)];
    }
    if (s.cfg_.consistent) {
      // SIMPLEC: 1 / (A - H1), H1 the sum of the neighbour coefficients; where the viscous coupling
      // dominates, A - H1 leaves the transient term (and the walls' share). Floored at half the
      // transient term, where the mass flux leaving a cell exceeds what enters. Only in cells that
      // are mostly material: in the air next to it, 1 / (A - H1) is the light phase's dt / rho, a
      // thousand times the material's, and the linear face value between the two made a flat layer
      // at rest unstable (a round-off disturbance grew to 0.1 m/s in 0.3 s, test
      // VofSolver.FlatLayerStaysAtRestWithTheConsistentCoupling); the air keeps 1/A.
      auto& H1 = wc1;
      for (int c : halo_cells) H1[std::size_t(c)] = 0;
      for (int f : active_faces) {
        if (f >= m.n_internal) break;
        H1[std::size_t(m.owner[std::size_t(f)])] += cO[std::size_t(f)];
        H1[std::size_t(m.neighbour[std::size_t(f)])] += cN[std::size_t(f)];
      }
      for (int c : halo_cells) {
        const double V = m.volume[std::size_t(c)];
        rAtU[std::size_t(c)] = s.alpha_[std::size_t(c)] < s.cfg_.consistent_alpha ? rAU[std::size_t(c)]
                                                              : V / std::max(A_D[std::size_t(c)] - H1[std::size_t(c)], 0.5 * rho[std::size_t(c)] * V / dt);
      }
      for (int f : active_faces) {
        const int o = m.owner[std::size_t(f)];
        rAtUf[std::size_t(f)] = f < m.n_internal ? m.weight[std::size_t(f)] * rAtU[std::size_t(o)] +
                                                       (1 - m.weight[std::size_t(f)]) * rAtU[std::size_t(m.neighbour[std::size_t(f)])]
                                                 : rAtU[std::size_t(o)];
      }
    }
  }

  // H = sources + neighbour coefficients x the current velocity; HbyA = H / A_D.
  void compute_H() {
    const auto& U = s.U_;
    for (int c : halo_cells) H[std::size_t(c)] = bsrc[std::size_t(c)];
    for (int f : active_faces) {
      if (f >= m.n_internal) break;  // active_faces is sorted: internal faces first
      const int o = m.owner[std::size_t(f)], nb = m.neighbour[std::size_t(f)];
      H[std::size_t(o)] = H[std::size_t(o)] + cO[std::size_t(f)] * U[std::size_t(nb)];
      H[std::size_t(nb)] = H[std::size_t(nb)] + cN[std::size_t(f)] * U[std::size_t(o)];
    }
    for (int c : halo_cells) HbyA[std::size_t(c)] = (1.0 / A_D[std::size_t(c)]) * H[std::size_t(c)];
  }

  // Momentum predictor: solve the momentum matrix with the last pressure and buoyancy forces,
  // so that the viscous coupling (the Coulomb viscosity reaches 1e2 m2/s) is converged every step.
  int predict() {
    // Force per cell: V reconstruct(-ghf snGrad(rho) - snGrad(p_rgh)) |Sf|, over the active region;
    // a face to the air at rest outside it is an opening with the outside's pressure, as in the
    // pressure equation.
    const auto& ix = active_index;
    auto& rec = pf_rec;
    for (int c : active_cells) rec[std::size_t(c)] = Vec{};
    for (int f : active_faces) {
      const int o = m.owner[std::size_t(f)];
      const bool ao = ix[std::size_t(o)] >= 0;
      double q = 0;  // force per area, normal to the face (along Sf)
      if (f < m.n_internal) {
        const int nb = m.neighbour[std::size_t(f)];
        const bool an = ix[std::size_t(nb)] >= 0;
        if (ao && an) {
          q = face_force(f);
          rec[std::size_t(o)] = rec[std::size_t(o)] + q * m.Sf[std::size_t(f)];
          rec[std::size_t(nb)] = rec[std::size_t(nb)] + q * m.Sf[std::size_t(f)];
        } else {
          const int c = ao ? o : nb;
          const double sg = ao ? 1 : -1;  // Sf out of c
          q = opening_force(f, c, outside_p_rgh(f, c));  // out of c
          rec[std::size_t(c)] = rec[std::size_t(c)] + (sg * q) * m.Sf[std::size_t(f)];
        }
      } else if (ao && kind_of(f) == Bc::atmosphere) {
        q = opening_force(f, o, outside_p_rgh(f, o));
        rec[std::size_t(o)] = rec[std::size_t(o)] + q * m.Sf[std::size_t(f)];
      }  // walls and inflow: the pressure gradient normal to them is balanced (fixed flux)
    }
    // The matrix over every cell, cells outside the active region (or not predicted) as rows of the
    // identity with their velocity (zero for the air at rest outside the region). Every face's entries are set, zero where they are not
    // used, so that the matrix keeps the whole mesh's nonzero structure from one assembly to the next.
    // Under the consistent coupling only the material's cells (alpha >= consistent_alpha) are
    // predicted; the air around them keeps its velocity (the cells' coefficients to it go to the
    // right-hand side), as under PISO. Predicting the air too let the cell-reconstructed buoyancy
    // force drive air currents over a resting heap's stair-stepped surface (0.1 m/s) that dragged
    // it along at 2 mm/s (docs/design/vof.md).
    const bool material_only = s.cfg_.consistent;
    auto solved = [&](int c) {
      return ix[std::size_t(c)] >= 0 && (!material_only || s.alpha_[std::size_t(c)] >= s.cfg_.consistent_alpha);
    };
    auto& known = pf_known;
    known.assign(std::size_t(nc), Vec{});
    petsc_check(MatZeroEntries(Mu), "MatZeroEntries");
    for (int f = 0; f < m.n_internal; ++f) {
      const PetscInt o = m.owner[std::size_t(f)], nb = m.neighbour[std::size_t(f)];
      const bool so = solved(int(o)), sn = solved(int(nb));
      const bool both = so && sn;
      const PetscScalar a = both ? -cO[std::size_t(f)] : 0.0, c = both ? -cN[std::size_t(f)] : 0.0;
      petsc_check(MatSetValues(Mu, 1, &o, 1, &nb, &a, INSERT_VALUES), "MatSetValues");
      petsc_check(MatSetValues(Mu, 1, &nb, 1, &o, &c, INSERT_VALUES), "MatSetValues");
      if (so && !sn && ix[std::size_t(nb)] >= 0) known[std::size_t(o)] = known[std::size_t(o)] + cO[std::size_t(f)] * s.U_[std::size_t(nb)];
      if (sn && !so && ix[std::size_t(o)] >= 0) known[std::size_t(nb)] = known[std::size_t(nb)] + cN[std::size_t(f)] * s.U_[std::size_t(o)];
    }
    for (PetscInt c = 0; c < nc; ++c) {
      const PetscScalar d = solved(int(c)) ? A_D[std::size_t(c)] : 1.0;
      petsc_check(MatSetValues(Mu, 1, &c, 1, &c, &d, INSERT_VALUES), "MatSetValues");
    }
    petsc_check(MatAssemblyBegin(Mu, MAT_FINAL_ASSEMBLY), "MatAssembly");
    petsc_check(MatAssemblyEnd(Mu, MAT_FINAL_ASSEMBLY), "MatAssembly");
    petsc_check(KSPSetOperators(kspU, Mu, Mu), "KSPSetOperators");
    int its_total = 0;
    for (int comp_i = 0; comp_i < dims; ++comp_i) {
      for (int c = 0; c < nc; ++c) {
        double src = 0, x0 = 0;
        if (solved(c)) {
          const Vec F = reconstruct(c, rec[std::size_t(c)]);
          src = comp(bsrc[std::size_t(c)], comp_i) + m.volume[std::size_t(c)] * comp(F, comp_i) + comp(known[std::size_t(c)], comp_i);
          x0 = comp(s.U_[std::size_t(c)], comp_i);
        } else if (ix[std::size_t(c)] >= 0) {
          src = x0 = comp(s.U_[std::size_t(c)], comp_i);
        }
        VecSetValue(bu, c, src, INSERT_VALUES);
        VecSetValue(xu, c, x0, INSERT_VALUES);
      }
      VecAssemblyBegin(bu);
      VecAssemblyEnd(bu);
      VecAssemblyBegin(xu);
      VecAssemblyEnd(xu);
      petsc_check(KSPSolve(kspU, bu, xu), "KSPSolve (momentum)");
      KSPConvergedReason reason;
      KSPGetConvergedReason(kspU, &reason);
      PetscInt k = 0;
      KSPGetIterationNumber(kspU, &k);
      its_total += int(k);
      if (reason < 0)
        throw VofError("momentum solver (BiCGStab + ILU) did not converge at t = " + std::to_string(s.t_) + " s: reason " +
                       std::to_string(int(reason)));
      const PetscScalar* xv;
      VecGetArrayRead(xu, &xv);
      for (int c : active_cells) (comp_i == 0 ? s.U_[std::size_t(c)].x : comp_i == 1 ? s.U_[std::size_t(c)].y : s.U_[std::size_t(c)].z) = xv[c];
      VecRestoreArrayRead(xu, &xv);
    }
    return its_total;
  }

  // The active region (docs/design/vof.md, "Skipping air far from the material"): cells with material
  // (alpha > active_alpha), cells with an inflow face, and `active_layers` layers of cells around
  // them. Only these take part in the pressure equation; the rest is air at rest under the
  // atmosphere's hydrostatic pressure, and faces to it act as openings. The region is rebuilt when
  // material comes within two layers of its edge, so it keeps its shape (and the pressure
  // preconditioner) for many steps. Returns true when it changed.
  bool update_active(bool force) {
    const int layers = s.cfg_.active_layers;
    if (layers <= 0) {
      if (n_active == nc && !force) return false;
      std::vector<int> all(std::size_t(nc), 0);
      set_region(all);
      return true;
    }
    // Cheap check first: material, and two layers around it, must lie inside the region. Material
    // can appear only where faces of the region carry flux, so the cells next to it (halo_cells)
    // are the only candidates; marks carry a stamp instead of being cleared.
    if (!force && n_active > 0) {
      if (++stamp == 0) {
        std::fill(mark.begin(), mark.end(), 0u);
        stamp = 1;
      }
      std::vector<int>& front = bfs_a;
      std::vector<int>& next = bfs_b;
      front.clear();
      for (int c : halo_cells)
        if (s.alpha_[std::size_t(c)] > s.cfg_.active_alpha) {
          mark[std::size_t(c)] = stamp;
          front.push_back(c);
        }
      bool inside = true;
      for (int k = 0; k <= std::min(2, layers) && inside; ++k) {
        next.clear();
        for (int c : front) {
          if (active_index[std::size_t(c)] < 0) {
            inside = false;
            break;
          }
          for (int f : cell_faces[std::size_t(c)]) {
            if (f >= m.n_internal) continue;
            const int other = m.owner[std::size_t(f)] == c ? m.neighbour[std::size_t(f)] : m.owner[std::size_t(f)];
            if (mark[std::size_t(other)] != stamp) {
              mark[std::size_t(other)] = stamp;
              next.push_back(other);
            }
          }
        }
        front.swap(next);
      }
      if (inside) return false;
    }
    // Distance in layers from the material (BFS over faces), up to `layers`.
    std::vector<int> d(std::size_t(nc), -1), front, next;
    for (int c = 0; c < nc; ++c)
      if (s.alpha_[std::size_t(c)] > s.cfg_.active_alpha) {
        d[std::size_t(c)] = 0;
        front.push_back(c);
      }
    for (int f = m.n_internal; f < nf; ++f)
      if (kind_of(f) == Bc::inflow) {
        const int o = m.owner[std::size_t(f)];
        if (d[std::size_t(o)] < 0) {
          d[std::size_t(o)] = 0;
          front.push_back(o);
        }
      }
    for (int k = 1; k <= layers && !front.empty(); ++k) {
      next.clear();
      for (int c : front)
        for (int f : cell_faces[std::size_t(c)]) {
          if (f >= m.n_internal) continue;
          const int other = m.owner[std::size_t(f)] == c ? m.neighbour[std::size_t(f)] : m.owner[std::size_t(f)];
          if (d[std::size_t(other)] < 0) {
            d[std::size_t(other)] = k;
            next.push_back(other);
          }
        }
      front.swap(next);
    }
    // Air beyond the layers joins the reservoir only where it connects to an atmosphere opening
    // through other such cells: an enclosed pocket (under a lid, in a closed box) keeps its volume,
    // so it stays in the computation.
    {
      std::vector<int> stack;
      std::vector<char> out(std::size_t(nc), 0);
      for (int f = m.n_internal; f < nf; ++f)
        if (kind_of(f) == Bc::atmosphere) {
          const int o = m.owner[std::size_t(f)];
          if (d[std::size_t(o)] < 0 && !out[std::size_t(o)]) {
            out[std::size_t(o)] = 1;
            stack.push_back(o);
          }
        }
      while (!stack.empty()) {
        const int c = stack.back();
        stack.pop_back();
        for (int f : cell_faces[std::size_t(c)]) {
          if (f >= m.n_internal) continue;
          const int other = m.owner[std::size_t(f)] == c ? m.neighbour[std::size_t(f)] : m.owner[std::size_t(f)];
          if (d[std::size_t(other)] < 0 && !out[std::size_t(other)]) {
            out[std::size_t(other)] = 1;
            stack.push_back(other);
          }
        }
      }
      for (int c = 0; c < nc; ++c)
        if (d[std::size_t(c)] < 0 && !out[std::size_t(c)]) d[std::size_t(c)] = layers + 1;
    }
    set_region(d);
    return true;
  }

  // Make the cells with d >= 0 the active region: its cells, the cells next to it, its faces; the
  // air outside at rest; no flux between resting cells; the material outside the halo, which no
  // flux can reach, summed once.
  void set_region(const std::vector<int>& d) {
    active_index.assign(std::size_t(nc), -1);
    active_cells.clear();
    for (int c = 0; c < nc; ++c)
      if (d[std::size_t(c)] >= 0) {
        active_index[std::size_t(c)] = int(active_cells.size());
        active_cells.push_back(c);
      }
    n_active = int(active_cells.size());
    std::vector<char> in_halo(std::size_t(nc), 0);
    active_faces.clear();
    for (int f = 0; f < nf; ++f) {
      const int o = m.owner[std::size_t(f)];
      const bool ao = active_index[std::size_t(o)] >= 0;
      const bool an = f < m.n_internal && active_index[std::size_t(m.neighbour[std::size_t(f)])] >= 0;
      if (ao || an) {
        active_faces.push_back(f);
        in_halo[std::size_t(o)] = 1;
        if (f < m.n_internal) in_halo[std::size_t(m.neighbour[std::size_t(f)])] = 1;
      } else {
        s.phi_[std::size_t(f)] = 0;
        alpha_phi[std::size_t(f)] = rho_phi[std::size_t(f)] = 0;
      }
    }
    // Cells joining the halo start from their resting state (their old-time values are stale).
    if (halo_flag.size() != std::size_t(nc)) halo_flag.assign(std::size_t(nc), 0);
    for (int c = 0; c < nc; ++c)
      if (in_halo[std::size_t(c)] && !halo_flag[std::size_t(c)]) {
        if (active_index[std::size_t(c)] < 0) s.U_[std::size_t(c)] = Vec{};
        rho_old[std::size_t(c)] = rho[std::size_t(c)];
        U_old[std::size_t(c)] = s.U_[std::size_t(c)];
        const double al = std::clamp(s.alpha_[std::size_t(c)], 0.0, 1.0);
        mu[std::size_t(c)] = al * s.cfg_.rho1 * s.nu1_[std::size_t(c)] + (1 - al) * s.cfg_.rho2 * s.cfg_.nu2;
      }
    halo_flag = in_halo;
    halo_cells.clear();
    frozen_volume = 0;
    frozen_min = 1e300;
    frozen_max = -1e300;
    for (int c = 0; c < nc; ++c) {
      if (in_halo[std::size_t(c)]) {
        halo_cells.push_back(c);
      } else {
        const double a = s.alpha_[std::size_t(c)];
        frozen_volume += a * m.volume[std::size_t(c)];
        frozen_min = std::min(frozen_min, a);
        frozen_max = std::max(frozen_max, a);
      }
      if (active_index[std::size_t(c)] < 0) {  // air at rest outside the region
        s.U_[std::size_t(c)] = Vec{};
        s.p_[std::size_t(c)] = still_air_p(gh[std::size_t(c)]);
        s.p_rgh_[std::size_t(c)] = s.p_[std::size_t(c)] - rho[std::size_t(c)] * gh[std::size_t(c)];
      }
    }
    if (mark.size() != std::size_t(nc)) mark.assign(std::size_t(nc), 0u);
  }

  // The pressure solver: CG with an algebraic multigrid preconditioner. Made anew whenever the
  // active region changes (GAMG keeps its coarse levels' solvers, whose sizes would not fit).
  void make_pressure_ksp() {
    if (ksp) KSPDestroy(&ksp);
    petsc_check(KSPCreate(PETSC_COMM_SELF, &ksp), "KSPCreate");
    petsc_check(KSPSetType(ksp, KSPCG), "KSPSetType");
    PC pc;
    petsc_check(KSPGetPC(ksp, &pc), "KSPGetPC");
    if (s.cfg_.pressure_pc == "gamg") {
      petsc_check(PCSetType(pc, PCGAMG), "PCSetType gamg");
      // The 1/A of the two phases differ a thousandfold: GAMG's default Chebyshev smoothers, with their
      // estimated eigenvalue bounds, then made the preconditioner indefinite for CG now and then.
      // Damped Jacobi smoothing (Richardson, scale 0.6) is symmetric and stays positive definite.
      // (Defaults only: a user's PETSc options with the same names are kept.)
      for (const auto& [name, value] : {std::pair<const char*, const char*>{"-runout_p_mg_levels_ksp_type", "richardson"},
                                        {"-runout_p_mg_levels_pc_type", "jacobi"},
                                        {"-runout_p_mg_levels_ksp_richardson_scale", "0.6"},
                                        {"-runout_p_mg_levels_ksp_max_it", "2"}}) {
        PetscBool set = PETSC_FALSE;
        PetscOptionsHasName(nullptr, nullptr, name, &set);
        if (!set) PetscOptionsSetValue(nullptr, name, value);
      }
    } else if (s.cfg_.pressure_pc == "hypre") {
      if (PCSetType(pc, PCHYPRE)) throw VofError("pressure_pc: this PETSc has no hypre (valid here: gamg)");
      petsc_check(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType");
    } else {
      throw VofError("pressure_pc: unknown '" + s.cfg_.pressure_pc + "' (valid: gamg, hypre)");
    }
    petsc_check(KSPSetTolerances(ksp, s.cfg_.pressure_rtol, 1e-300, PETSC_DEFAULT, 2000), "KSPSetTolerances");
    petsc_check(KSPSetNormType(ksp, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
    // PETSc options with the prefix runout_p_ (PETSC_OPTIONS) set the preconditioner's details; the
    // relative tolerances are set again for each solve (VofConfig::pressure_rtol*).
    petsc_check(KSPSetOptionsPrefix(ksp, "runout_p_"), "KSPSetOptionsPrefix");
    petsc_check(KSPSetFromOptions(ksp), "KSPSetFromOptions");
  }

  // Keep copies of the operators the pressure preconditioner was built from: the first build of
  // this system's solver and the latest. PETSc's GAMG keeps the prolongators of its first build
  // and later builds only form the coarse operators anew (Galerkin), so the preconditioner in use
  // depends on both.
  void remember_pc(Mat Ap) {
    if (!Apc_first) petsc_check(MatDuplicate(Ap, MAT_COPY_VALUES, &Apc_first), "MatDuplicate");
    if (Apc) MatDestroy(&Apc);
    petsc_check(MatDuplicate(Ap, MAT_COPY_VALUES, &Apc), "MatDuplicate");
    ++pc_builds;
  }

  // The pressure solver's cross-step state for a checkpoint: the refresh counter and the operators
  // the preconditioner was built from (compressed rows; both share the active region's structure).
  void save_pc(VofState& st) const {
    st.steps_since_pc = steps_since_pc;
    st.pc_builds = pc_builds > 1 ? 2 : pc_builds;
    st.pc_rows.clear();
    st.pc_cols.clear();
    st.pc_first_values.clear();
    st.pc_values.clear();
    if (!Apc) return;
    PetscInt n = 0;
    petsc_check(MatGetSize(Apc, &n, nullptr), "MatGetSize");
    st.pc_rows.push_back(0);
    for (PetscInt i = 0; i < n; ++i) {
      PetscInt nc1 = 0, nc0 = 0;
      const PetscInt *c1 = nullptr, *c0 = nullptr;
      const PetscScalar *v1 = nullptr, *v0 = nullptr;
      petsc_check(MatGetRow(Apc, i, &nc1, &c1, &v1), "MatGetRow");
      petsc_check(MatGetRow(Apc_first, i, &nc0, &c0, &v0), "MatGetRow");
      const bool same = nc0 == nc1 && std::equal(c0, c0 + nc0, c1);
      for (PetscInt k = 0; same && k < nc1; ++k) {
        st.pc_cols.push_back(int(c1[k]));
        st.pc_values.push_back(double(v1[k]));
        st.pc_first_values.push_back(double(v0[k]));
      }
      petsc_check(MatRestoreRow(Apc_first, i, &nc0, &c0, &v0), "MatRestoreRow");
      petsc_check(MatRestoreRow(Apc, i, &nc1, &c1, &v1), "MatRestoreRow");
      if (!same) throw VofError("state: the pressure preconditioner's operators differ in structure");
      st.pc_rows.push_back(int(st.pc_cols.size()));
    }
  }

  // Set the pressure operator's values from compressed rows (the structure the active region's
  // system has) and assemble it.
  void set_operator(Mat M, const VofState& st, const std::vector<double>& values) {
    for (int i = 0; i < n_active; ++i) {
      const int k0 = st.pc_rows[std::size_t(i)], k1 = st.pc_rows[std::size_t(i) + 1];
      if (k0 < 0 || k1 < k0 || std::size_t(k1) > st.pc_cols.size()) throw VofError("restore: the checkpoint's pressure operator is damaged");
      for (int k = k0; k < k1; ++k) {
        const PetscInt r0 = i, c0 = st.pc_cols[std::size_t(k)];
        if (c0 < 0 || c0 >= n_active) throw VofError("restore: the checkpoint's pressure operator is damaged");
        const PetscScalar v = values[std::size_t(k)];
        if (MatSetValues(M, 1, &r0, 1, &c0, &v, INSERT_VALUES))
          throw VofError("restore: the checkpoint's pressure operator does not fit the active region's system");
      }
    }
    petsc_check(MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY), "MatAssembly");
    petsc_check(MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY), "MatAssembly");
  }

  // After make_pressure_system() for the restored region: the refresh counter, and the
  // preconditioner built as the run that wrote the checkpoint built it (from the operator of the
  // solver's first build, then, if it was rebuilt since, from the latest one), placed where that
  // run had it (A, or Apin in a closed domain), so that the following steps, which reassemble the
  // operator and keep or refresh the preconditioner, are that run's.
  void restore_pc(const VofState& st) {
    steps_since_pc = st.steps_since_pc;
    if (st.pc_builds <= 0) return;  // none built yet: the system stays fresh
    if (st.pc_rows.size() != std::size_t(n_active) + 1 || st.pc_cols.size() != st.pc_values.size() ||
        st.pc_first_values.size() != st.pc_values.size() || st.pc_rows.back() != int(st.pc_cols.size()))
      throw VofError("restore: the checkpoint's pressure operator does not match its active region");
    const bool closed = !has_dirichlet && n_active == nc;  // the preconditioner was built from Apin
    for (int build = 0; build < std::min(st.pc_builds, 2); ++build) {
      const auto& values = build == 0 ? st.pc_first_values : st.pc_values;
      Mat Ap = A;
      if (closed) {
        if (!Apin) {
          set_operator(A, st, values);
          petsc_check(MatDuplicate(A, MAT_COPY_VALUES, &Apin), "MatDuplicate");
        } else {
          set_operator(Apin, st, values);
        }
        Ap = Apin;
      } else {
        set_operator(A, st, values);
      }
      petsc_check(KSPSetOperators(ksp, Ap, Ap), "KSPSetOperators");
      petsc_check(KSPSetReusePreconditioner(ksp, PETSC_FALSE), "KSPSetReusePreconditioner");
      petsc_check(KSPSetUp(ksp), "KSPSetUp");  // what KSPSolve does before it iterates
      petsc_check(KSPSetUpOnBlocks(ksp), "KSPSetUpOnBlocks");
      remember_pc(Ap);
    }
    pc_builds = st.pc_builds;
    system_fresh = false;
  }

  // (Re)create the pressure system for the current active region.
  void make_pressure_system() {
    if (A) MatDestroy(&A);
    if (Apin) MatDestroy(&Apin);
    if (Apc) MatDestroy(&Apc);
    if (Apc_first) MatDestroy(&Apc_first);
    pc_builds = 0;
    for (::Vec* v : {&x, &b, &r, &dx})
      if (*v) VecDestroy(v);
    std::vector<PetscInt> nnz(std::size_t(std::max(1, n_active)), 1);
    for (int f = 0; f < m.n_internal; ++f) {
      const int io = active_index[std::size_t(m.owner[std::size_t(f)])], in = active_index[std::size_t(m.neighbour[std::size_t(f)])];
      if (io >= 0 && in >= 0) {
        ++nnz[std::size_t(io)];
        ++nnz[std::size_t(in)];
      }
    }
    petsc_check(MatCreateSeqAIJ(PETSC_COMM_SELF, n_active, n_active, 0, nnz.data(), &A), "MatCreateSeqAIJ");
    petsc_check(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
    petsc_check(VecCreateSeq(PETSC_COMM_SELF, n_active, &x), "VecCreateSeq");
    petsc_check(VecDuplicate(x, &b), "VecDuplicate");
    petsc_check(VecDuplicate(x, &r), "VecDuplicate");
    petsc_check(VecDuplicate(x, &dx), "VecDuplicate");
    make_pressure_ksp();
    system_fresh = true;
  }

  // One pressure correction: solve laplacian(rAUf, p_rgh) = div(phiHbyA) on the active region and
  // correct fluxes and velocities. Returns the iterations.
  int pressure_correct(bool initial, bool reuse = false, bool final = true) {
    petsc_check(KSPSetTolerances(ksp, final ? s.cfg_.pressure_rtol : s.cfg_.pressure_rtol_intermediate, 1e-300, PETSC_DEFAULT, 2000),
                "KSPSetTolerances");
    const bool closed = !has_dirichlet && n_active == nc;  // no opening anywhere: the level is free
    const auto& ix = active_index;
    // Per face: the flux predicted from H/A (oriented with Sf), its buoyancy part, the Laplacian
    // coefficient and, for an opening (atmosphere patch or the edge of the active region), the
    // side of the active cell (+1 owner, -1 neighbour) and the pressure outside.
    auto &phiHbyA = pf_phiHbyA, &phig = pf_phig, &coef = pf_coef, &pout = pf_pout;
    auto& open = pf_open;
    // The consistent coupling (VofConfig::consistent): the pressure equation and the correction take
    // 1/(A - H1); the part of the last pressure's force that 1/A would have carried, (1/A -
    // 1/(A - H1)) F_old, stays in the predicted flux and velocity (SIMPLEC).
    const bool cons = s.cfg_.consistent && !initial;
    const auto& rA = cons ? rAtU : rAU;
    const auto& rAf = cons ? rAtUf : rAUf;
    auto& rec_old = pf_rec_old;
    if (cons)
      for (int c : active_cells) rec_old[std::size_t(c)] = Vec{};
    // Within a step 1/A, the density and the active region do not change (reuse: a later
    // corrector of the step), and with them neither which faces are openings, the Laplacian
    // coefficients, the buoyancy fluxes nor the outside pressures: those are set by the step's
    // first call. Every call forms the predicted flux from the correctors' H/A.
    if (!reuse)
      for (int f : active_faces) {
        phig[std::size_t(f)] = coef[std::size_t(f)] = pout[std::size_t(f)] = 0;
        open[std::size_t(f)] = 0;
        const int o = m.owner[std::size_t(f)];
        const bool ao = ix[std::size_t(o)] >= 0;
        if (f < m.n_internal) {
          const int nb = m.neighbour[std::size_t(f)];
          const bool an = ix[std::size_t(nb)] >= 0;
          if (ao && an) {
            phig[std::size_t(f)] = -ghf[std::size_t(f)] * (rho[std::size_t(nb)] - rho[std::size_t(o)]) * m.delta_coeff[std::size_t(f)] *
                                   m.magSf[std::size_t(f)] * rAf[std::size_t(f)];
            coef[std::size_t(f)] = rAf[std::size_t(f)] * m.magSf[std::size_t(f)] * m.delta_coeff[std::size_t(f)];
          } else if (ao || an) {
            const int a = ao ? o : nb;
            open[std::size_t(f)] = ao ? 1 : -1;
            coef[std::size_t(f)] = rA[std::size_t(a)] * m.magSf[std::size_t(f)] * m.delta_coeff[std::size_t(f)];
            pout[std::size_t(f)] = outside_p_rgh(f, a);
          }
        } else if (ao && kind_of(f) == Bc::atmosphere) {
          open[std::size_t(f)] = 1;
          coef[std::size_t(f)] = rAf[std::size_t(f)] * m.magSf[std::size_t(f)] * m.delta_coeff[std::size_t(f)];
          pout[std::size_t(f)] = outside_p_rgh(f, o);
        }
      }
    for (int f : active_faces) {
      const int o = m.owner[std::size_t(f)];
      const signed char op = open[std::size_t(f)];
      double ph = 0;
      if (f < m.n_internal) {
        const int nb = m.neighbour[std::size_t(f)];
        if (op == 0) {  // both cells active (an active face that is no opening)
          const double w = m.weight[std::size_t(f)];
          const Vec Hf = w * HbyA[std::size_t(o)] + (1 - w) * HbyA[std::size_t(nb)];
          ph = initial ? 0.0 : dot(Hf, m.Sf[std::size_t(f)]);
          if (cons) {
            const double Fold = face_force(f);
            ph += (rAUf[std::size_t(f)] - rAtUf[std::size_t(f)]) * Fold * m.magSf[std::size_t(f)];
            rec_old[std::size_t(o)] = rec_old[std::size_t(o)] + Fold * m.Sf[std::size_t(f)];
            rec_old[std::size_t(nb)] = rec_old[std::size_t(nb)] + Fold * m.Sf[std::size_t(f)];
          }
        } else {
          const int a = op > 0 ? o : nb;
          ph = initial ? 0.0 : dot(HbyA[std::size_t(a)], m.Sf[std::size_t(f)]);
          if (cons) {
            const double sg = op;
            const double Fout = opening_force(f, a, pout[std::size_t(f)]);  // out of a
            ph += sg * (rAU[std::size_t(a)] - rAtU[std::size_t(a)]) * Fout * m.magSf[std::size_t(f)];
            rec_old[std::size_t(a)] = rec_old[std::size_t(a)] + (sg * Fout) * m.Sf[std::size_t(f)];
          }
        }
      } else if (ix[std::size_t(o)] >= 0) {
        const Bc k = kind_of(f);
        if (k == Bc::inflow) ph = dot(bc_of(f).inflow_velocity(m.Cf[std::size_t(f)]), m.Sf[std::size_t(f)]);
        else if (k == Bc::outflow || k == Bc::atmosphere)
          ph = initial ? 0.0 : dot(HbyA[std::size_t(o)], m.Sf[std::size_t(f)]);
        if (k == Bc::atmosphere && cons) {
          const double Fout = opening_force(f, o, pout[std::size_t(f)]);
          ph += (rAU[std::size_t(o)] - rAtU[std::size_t(o)]) * Fout * m.magSf[std::size_t(f)];
          rec_old[std::size_t(o)] = rec_old[std::size_t(o)] + Fout * m.Sf[std::size_t(f)];
        }
      }
      phiHbyA[std::size_t(f)] = ph + phig[std::size_t(f)];
    }
    // Assemble M p = rhs. Within a step the matrix does not change (1/A is built once per step):
    // later correctors keep it and its preconditioner and assemble only the right-hand side.
    if (!reuse) petsc_check(MatZeroEntries(A), "MatZeroEntries");
    // The diagonal is kept from the step's first call (the closed domain's pinning needs it then too).
    auto &diag = pf_diag, &rhs = pf_rhs;
    if (!reuse) diag.assign(std::size_t(n_active), 0.0);
    rhs.assign(std::size_t(n_active), 0.0);
    for (int f : active_faces) {
      const double c = coef[std::size_t(f)];
      const int io = ix[std::size_t(m.owner[std::size_t(f)])];
      if (open[std::size_t(f)] != 0) {
        const int ia = open[std::size_t(f)] > 0 ? io : ix[std::size_t(m.neighbour[std::size_t(f)])];
        const double sg = open[std::size_t(f)];
        rhs[std::size_t(ia)] -= sg * phiHbyA[std::size_t(f)];
        if (!reuse) diag[std::size_t(ia)] += c;
        rhs[std::size_t(ia)] += c * pout[std::size_t(f)];
        continue;
      }
      if (io < 0) continue;
      rhs[std::size_t(io)] -= phiHbyA[std::size_t(f)];
      if (f < m.n_internal) {
        const int in = ix[std::size_t(m.neighbour[std::size_t(f)])];
        rhs[std::size_t(in)] += phiHbyA[std::size_t(f)];
        if (!reuse) {
          diag[std::size_t(io)] += c;
          diag[std::size_t(in)] += c;
          const PetscInt r0 = io, c0 = in;
          const PetscScalar v = -c;
          petsc_check(MatSetValues(A, 1, &r0, 1, &c0, &v, INSERT_VALUES), "MatSetValues");
          petsc_check(MatSetValues(A, 1, &c0, 1, &r0, &v, INSERT_VALUES), "MatSetValues");
        }
      }
    }
    {
      PetscScalar *bv, *xv;
      petsc_check(VecGetArray(b, &bv), "VecGetArray");
      petsc_check(VecGetArray(x, &xv), "VecGetArray");
      for (int k = 0; k < n_active; ++k) {
        if (!reuse) {
          const PetscInt r0 = k;
          const PetscScalar v = diag[std::size_t(k)];
          petsc_check(MatSetValues(A, 1, &r0, 1, &r0, &v, INSERT_VALUES), "MatSetValues");
        }
        bv[k] = rhs[std::size_t(k)];
        xv[k] = s.p_rgh_[std::size_t(active_cells[std::size_t(k)])];
      }
      VecRestoreArray(b, &bv);
      VecRestoreArray(x, &xv);
    }
    if (!reuse) {
      petsc_check(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY), "MatAssembly");
      petsc_check(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY), "MatAssembly");
    }
    PetscInt its = 0;
    auto timed_solve = [&](Mat Ap) {
      petsc_check(KSPSetOperators(ksp, Ap, Ap), "KSPSetOperators");
      const auto t_ksp = std::chrono::steady_clock::now();
      petsc_check(KSPSolve(ksp, r, dx), "KSPSolve");
      ksp_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t_ksp).count();
    };
    for (int pass = 0; pass < (initial ? 3 : 1); ++pass) {
      petsc_check(MatMult(A, x, r), "MatMult");
      petsc_check(VecAYPX(r, -1.0, b), "VecAYPX");  // r = b - A x
      petsc_check(VecSet(dx, 0.0), "VecSet");
      const bool same = (reuse || pass > 0) && !system_fresh;  // passes of the initial solve share the matrix too
      // The preconditioner is rebuilt every pressure_pc_refresh steps (GAMG: the coarse operators
      // from the current matrix, with the prolongators of the solver's first build) and made anew
      // whenever the active region changes; in between, the last one preconditions the new matrix
      // (still symmetric positive definite).
      bool keep_pc = same;
      // (Counted per step: the outer correctors after a step's first keep it.)
      if (!same && !initial && !system_fresh) keep_pc = later_outer || ++steps_since_pc < std::max(1, s.cfg_.pressure_pc_refresh);
      if (!keep_pc) steps_since_pc = 0;
      Mat Ap = A;
      if (closed) {
        // A closed domain: the correction is fixed to zero in cell 0 (its row and column replaced
        // by the diagonal), which leaves a nonsingular system with the same solution up to the
        // constant that the pressure level below takes care of.
        if (!same) {
          if (Apin) petsc_check(MatCopy(A, Apin, SAME_NONZERO_PATTERN), "MatCopy");
          else petsc_check(MatDuplicate(A, MAT_COPY_VALUES, &Apin), "MatDuplicate");
          const PetscInt row0 = 0;
          petsc_check(MatZeroRowsColumns(Apin, 1, &row0, diag[0], dx, r), "MatZeroRowsColumns");
        } else {
          petsc_check(VecSetValue(r, 0, 0.0, INSERT_VALUES), "VecSetValue");  // dx_0 = 0
          VecAssemblyBegin(r);
          VecAssemblyEnd(r);
        }
        Ap = Apin;
      }
      system_fresh = false;
      petsc_check(KSPSetReusePreconditioner(ksp, keep_pc ? PETSC_TRUE : PETSC_FALSE), "KSPSetReusePreconditioner");
      timed_solve(Ap);
      if (!keep_pc) remember_pc(Ap);
      KSPConvergedReason reason;
      KSPGetConvergedReason(ksp, &reason);
      PetscInt k = 0;
      KSPGetIterationNumber(ksp, &k);
      its += k;
      if (reason < 0 && keep_pc) {
        // The kept preconditioner no longer fits the matrix (the viscosity changed by orders of
        // magnitude somewhere): build it anew and solve again.
        petsc_check(VecSet(dx, 0.0), "VecSet");
        petsc_check(KSPSetReusePreconditioner(ksp, PETSC_FALSE), "KSPSetReusePreconditioner");
        timed_solve(Ap);
        remember_pc(Ap);
        KSPGetConvergedReason(ksp, &reason);
        KSPGetIterationNumber(ksp, &k);
        its += k;
        steps_since_pc = 0;
      }
      if (reason < 0)
        throw VofError("pressure solver (CG + " + s.cfg_.pressure_pc + ") did not converge at t = " + std::to_string(s.t_) +
                       " s: reason " + std::to_string(int(reason)) + " after " + std::to_string(int(k)) + " iterations");
      petsc_check(VecAXPY(x, 1.0, dx), "VecAXPY");
    }
    {
      const PetscScalar* xv;
      VecGetArrayRead(x, &xv);
      for (int k = 0; k < n_active; ++k) s.p_rgh_[std::size_t(active_cells[std::size_t(k)])] = xv[k];
      VecRestoreArrayRead(x, &xv);
    }
    // Fluxes and velocities.
    auto& rec = pf_rec;
    for (int c : active_cells) rec[std::size_t(c)] = Vec{};
    for (int f : active_faces) {
      const int o = m.owner[std::size_t(f)];
      const signed char op = open[std::size_t(f)];
      if (op != 0) {
        // An opening: the flux out of the active cell a follows its pressure and the outside's.
        const int a = op > 0 ? o : m.neighbour[std::size_t(f)];
        const double sg = op;
        const double pflux_out = -coef[std::size_t(f)] * (pout[std::size_t(f)] - s.p_rgh_[std::size_t(a)]);
        s.phi_[std::size_t(f)] = phiHbyA[std::size_t(f)] + sg * pflux_out;
        if (rA[std::size_t(a)] > 0) {
          const double q = pflux_out / rA[std::size_t(a)] / m.magSf[std::size_t(f)];
          rec[std::size_t(a)] = rec[std::size_t(a)] + (q * sg) * m.Sf[std::size_t(f)];
        }
        continue;
      }
      double pflux = 0;
      if (f < m.n_internal) {
        const int nb = m.neighbour[std::size_t(f)];
        pflux = -coef[std::size_t(f)] * (s.p_rgh_[std::size_t(nb)] - s.p_rgh_[std::size_t(o)]);
      }
      s.phi_[std::size_t(f)] = phiHbyA[std::size_t(f)] + pflux;
      if (f < m.n_internal && rAf[std::size_t(f)] > 0) {
        const double q = (phig[std::size_t(f)] + pflux) / rAf[std::size_t(f)] / m.magSf[std::size_t(f)];
        rec[std::size_t(o)] = rec[std::size_t(o)] + q * m.Sf[std::size_t(f)];
        rec[std::size_t(m.neighbour[std::size_t(f)])] = rec[std::size_t(m.neighbour[std::size_t(f)])] + q * m.Sf[std::size_t(f)];
      }
    }
    if (!initial)
      for (int c : active_cells) {
        const Vec R = reconstruct(c, rec[std::size_t(c)]);
        s.U_[std::size_t(c)] = HbyA[std::size_t(c)] + rA[std::size_t(c)] * R;
        if (cons) s.U_[std::size_t(c)] = s.U_[std::size_t(c)] + (rAU[std::size_t(c)] - rAtU[std::size_t(c)]) * reconstruct(c, rec_old[std::size_t(c)]);
      }
    for (int c : active_cells) s.p_[std::size_t(c)] = s.p_rgh_[std::size_t(c)] + rho[std::size_t(c)] * gh[std::size_t(c)];
    if (closed) {
      // A closed domain fixes the pressure only up to a constant, but the Coulomb viscosity needs the
      // pressure itself: it is zero in the highest cell (along gravity), the top of the air.
      int top = 0;
      for (int c = 1; c < nc; ++c)
        if (gh[std::size_t(c)] < gh[std::size_t(top)]) top = c;
      const double pmin = s.p_[std::size_t(top)];
      for (int c = 0; c < nc; ++c) {
        s.p_[std::size_t(c)] -= pmin;
        s.p_rgh_[std::size_t(c)] -= pmin;
      }
      const PetscScalar shift = -pmin;
      VecShift(x, shift);
    }
    return int(its);
  }

  std::vector<Vec> U_old;

  int steps_since_pc = 0;
  bool later_outer = false;  // in an outer corrector after the step's first
  double ksp_seconds = 0;  // time in KSPSolve since step() last took it
  std::vector<int> active_index;  // per cell: its row in the pressure system, -1 outside the active region
  std::vector<int> active_cells;  // the active region
  std::vector<int> halo_cells;    // the active region and the cells next to it (alpha may change there)
  std::vector<int> active_faces;  // faces of active cells, in ascending order (internal faces first)
  double frozen_volume = 0, frozen_min = 0, frozen_max = 0;  // material outside the halo (unchanging)
  std::vector<unsigned> mark;     // the quick region check's marks
  std::vector<char> halo_flag;    // membership of halo_cells
  unsigned stamp = 0;
  std::vector<int> bfs_a, bfs_b;
  int n_active = 0;
  double mean_cell_size = 0;
  // Work arrays (sized once; only entries of the active region are touched).
  std::vector<Grad> G;            // velocity gradient
  std::vector<double> wf1, wf2, wc1, wc2, wc3, wc4, wc5, wc6, wc7;
  std::vector<Vec> wv1;
  std::vector<double> pf_phiHbyA, pf_phig, pf_coef, pf_pout;  // pressure_correct's per-face values
  std::vector<signed char> pf_open;
  std::vector<double> pf_diag, pf_rhs;  // pressure_correct's per-row values
  std::vector<Vec> pf_rec, pf_rec_old, pf_known;
  bool system_fresh = true;  // the pressure system was just (re)created
};

VofSolver::VofSolver(Mesh mesh, VofConfig cfg) : mesh_(std::move(mesh)), cfg_(std::move(cfg)) {
  impl_ = std::make_unique<Impl>(*this);
  impl_->setup();
  const auto n = std::size_t(mesh_.cells());
  alpha_.assign(n, 0);
  p_rgh_.assign(n, 0);
  p_.assign(n, 0);
  nu1_.assign(n, cfg_.nu_max);
  U_.assign(n, Vec{});
  phi_.assign(std::size_t(mesh_.faces()), 0);
  dt_ = cfg_.dt_initial;
  impl_->set_region(std::vector<int>(n, 0));  // until initialise() finds the material, every cell counts
}

VofSolver::~VofSolver() = default;

void VofSolver::initialise(const std::vector<double>& alpha, const std::vector<Vec>& U) {
  auto& I = *impl_;
  if (alpha.size() != alpha_.size()) throw VofError("initialise: alpha has " + std::to_string(alpha.size()) + " values for " + std::to_string(alpha_.size()) + " cells");
  alpha_ = alpha;
  for (double& a : alpha_)
    if (!(a >= 0 && a <= 1)) throw VofError("initialise: alpha must lie in [0, 1]");
  if (!U.empty()) {
    if (U.size() != U_.size()) throw VofError("initialise: velocity size does not match the mesh");
    U_ = U;
  }
  I.update_gravity(t_);
  I.update_rho(I.rho);
  // Hydrostatic pressure: the pressure equation with no velocity and unit rAU.
  std::fill(I.rAUf.begin(), I.rAUf.end(), 1.0);
  std::fill(I.rAU.begin(), I.rAU.end(), 1.0);
  std::fill(I.HbyA.begin(), I.HbyA.end(), Vec{});
  I.n_active = 0;
  I.update_active(true);
  I.make_pressure_system();
  I.pressure_correct(true);
  std::fill(phi_.begin(), phi_.end(), 0.0);
  // Inflow faces carry their flux from the start, and the fluxes inside start divergence-free: the
  // potential flow that carries the inflow to the openings (the same equation without gravity).
  // Starting from zero inside instead piled the first step's inflow into the inflow cells (alpha
  // up to 1.03 in B4).
  bool inflow = false;
  for (int f = mesh_.n_internal; f < mesh_.faces(); ++f)
    if (I.kind_of(f) == Bc::inflow) {
      phi_[std::size_t(f)] = dot(I.bc_of(f).inflow_velocity(mesh_.Cf[std::size_t(f)]), mesh_.Sf[std::size_t(f)]);
      inflow = true;
    }
  if (inflow && I.has_dirichlet) {
    const auto p_rgh = p_rgh_, p = p_;
    std::fill(I.gh.begin(), I.gh.end(), 0.0);
    std::fill(I.ghf.begin(), I.ghf.end(), 0.0);
    I.gh_ref = 0;
    I.pressure_correct(true);
    p_rgh_ = p_rgh;
    p_ = p;
    I.gravity_set = false;
    I.update_gravity(t_);
  }
  I.update_viscosity();
}

const std::vector<double>& VofSolver::granular_flux() const { return impl_->alpha_phi; }

VofState VofSolver::state() const {
  const auto& I = *impl_;
  VofState st;
  st.t = t_;
  st.dt = dt_;
  st.alpha = alpha_;
  st.p_rgh = p_rgh_;
  st.p = p_;
  st.nu1 = nu1_;
  st.mu = I.mu;
  st.phi = phi_;
  st.U = U_;
  st.active_cells = I.active_cells;
  I.save_pc(st);
  return st;
}

void VofSolver::restore(const VofState& st) {
  auto& I = *impl_;
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
  alpha_ = st.alpha;
  p_rgh_ = st.p_rgh;
  p_ = st.p;
  nu1_ = st.nu1;
  phi_ = st.phi;
  U_ = st.U;
  I.gravity_set = false;
  I.update_gravity(t_);
  {
    // rho from alpha everywhere (outside the halo it was last computed from the same alpha).
    std::vector<int> all(nc, 0);
    I.set_region(all);
    I.update_rho(I.rho);
  }
  std::vector<int> d(nc, -1);
  for (int c : st.active_cells) d[std::size_t(c)] = 0;
  I.set_region(d);
  // The resting air's values as the run left them (they seed the solvers when cells join the region).
  p_rgh_ = st.p_rgh;
  p_ = st.p;
  U_ = st.U;
  I.mu = st.mu;
  I.make_pressure_system();
  I.restore_pc(st);
}

StepStats VofSolver::step() {
  using clk = std::chrono::steady_clock;
  const auto t0 = clk::now();
  auto& I = *impl_;
  const auto& m = mesh_;
  StepStats st;
  // 1. Time step from the Courant numbers of the last step (eqs. 4.64-4.65).
  double co = 0, aco = 0, air_co = 0;
  for (int c : I.active_cells) {
    double sum = 0;
    for (int f : I.cell_faces[std::size_t(c)]) sum += std::abs(phi_[std::size_t(f)]);
    const double cc = 0.5 * sum / m.volume[std::size_t(c)] * dt_;
    const double a = alpha_[std::size_t(c)];
    if (a > cfg_.material_alpha) {
      co = std::max(co, cc);
    } else {
      air_co = std::max(air_co, cc);
    }
    if (a > 0.01 && a < 0.99) aco = std::max(aco, cc);
  }
  {
    const double fac = std::min({cfg_.max_co / std::max(co, 1e-30), cfg_.max_alpha_co / std::max(aco, 1e-30),
                                 cfg_.max_air_co / std::max(air_co, 1e-30)});
    const double grow = std::min(std::min(fac, 1.0 + 0.1 * fac), 1.2);
    dt_ = std::min(grow * dt_, cfg_.dt_max);
  }
  dt_ = std::min(dt_, std::max(1e-12, t_limit_ - t_));
  t_ += dt_;
  st.t = t_;
  st.dt = dt_;
  I.update_gravity(t_);
  for (int c : I.halo_cells) {
    I.rho_old[std::size_t(c)] = I.rho[std::size_t(c)];
    I.U_old[std::size_t(c)] = U_[std::size_t(c)];
  }
  // 2-3. Phase fraction (uses the last fluxes), then the mixture density.
  I.solve_alpha(dt_);
  I.update_rho(I.rho);
  if (I.update_active(false)) I.make_pressure_system();
  st.active_cells = I.n_active;
  // 5-6. Momentum matrix and PISO correctors.
  double t_p = 0;
  I.ksp_seconds = 0;
  const int n_outer = std::max(1, cfg_.n_outer_correctors), n_corr = std::max(1, cfg_.n_correctors);
  for (int outer = 0; outer < n_outer; ++outer) {
    I.later_outer = outer > 0;
    if (outer > 0) I.update_viscosity();  // from the latest velocity and pressure (it takes the gradient)
    else I.velocity_gradient();
    I.build_momentum(dt_);
    if (cfg_.momentum_predictor) st.momentum_iterations += I.predict();
    for (int k = 0; k < n_corr; ++k) {
      I.compute_H();
      const auto tp = clk::now();
      st.pressure_iterations += I.pressure_correct(false, k > 0, outer + 1 == n_outer && k + 1 == n_corr);
      t_p += std::chrono::duration<double>(clk::now() - tp).count();
    }
  }
  I.later_outer = false;
  I.update_viscosity();
  // Diagnostics.
  st.alpha_min = 1e300;
  st.alpha_max = -1e300;
  // Over the halo; the material beyond it does not change (its sums were taken with the region).
  auto& div = I.wc1;
  for (int c : I.halo_cells) div[std::size_t(c)] = 0;
  for (int f : I.active_faces) {
    div[std::size_t(m.owner[std::size_t(f)])] += phi_[std::size_t(f)];
    if (f < m.n_internal) div[std::size_t(m.neighbour[std::size_t(f)])] -= phi_[std::size_t(f)];
  }
  st.granular_volume = I.frozen_volume;
  if (I.halo_cells.size() < std::size_t(m.cells())) {
    st.alpha_min = I.frozen_min;
    st.alpha_max = I.frozen_max;
  }
  for (int c : I.halo_cells) {
    const double a = alpha_[std::size_t(c)];
    st.alpha_min = std::min(st.alpha_min, a);
    st.alpha_max = std::max(st.alpha_max, a);
    st.granular_volume += a * m.volume[std::size_t(c)];
    if (a > 0.5) st.max_speed = std::max(st.max_speed, norm(U_[std::size_t(c)]));
    if (I.active_index[std::size_t(c)] >= 0)  // the air at rest outside the active region is a reservoir
      st.divergence = std::max(st.divergence, std::abs(div[std::size_t(c)]) / m.volume[std::size_t(c)]);
    if (!std::isfinite(a) || !std::isfinite(U_[std::size_t(c)].x) || !std::isfinite(U_[std::size_t(c)].y) || !std::isfinite(U_[std::size_t(c)].z))
      throw VofError("the solution is no longer finite at t = " + std::to_string(t_) + " s (cell " + std::to_string(c) + ")");
  }
  st.co = co;
  st.alpha_co = aco;
  st.air_co = air_co;
  st.seconds_pressure = t_p;
  st.seconds_pressure_solve = I.ksp_seconds;
  st.seconds_total = std::chrono::duration<double>(clk::now() - t0).count();
  return st;
}

void VofSolver::run(double t_end, const std::function<bool(const StepStats&)>& hook) {
  t_limit_ = t_end;
  while (t_ < t_end - 1e-12) {
    const auto st = step();
    if (hook && !hook(st)) break;
  }
  t_limit_ = 1e300;
}

}  // namespace runout::engine::vof
