#pragma once
// The non-depth-averaged engine (dissertation ch. 4.1): granular material and air as two
// incompressible, immiscible phases in one set of Navier-Stokes equations on a face-addressed
// finite-volume mesh, in the interFoam family:
//   * collocated variables, face fluxes from the pressure equation (Rhie-Chow through the PISO flux
//     predictor), the p_rgh formulation (p = p_rgh + rho g.x), eqs. 4.54-4.63;
//   * the phase fraction alpha transported explicitly with interface compression (eq. 4.51-4.53,
//     c_alpha) and a flux-corrected-transport limiter (Zalesak) that keeps alpha within the local
//     bounds and [0, 1], with sub-cycles;
//   * Euler implicit time derivative; the momentum matrix (upwind convection of the mass flux,
//     implicit viscous term, explicit transpose part in divergence form, by default with the
//     harmonic face viscosity) is built once per step and
//     each PISO corrector rebuilds H/A from the latest velocity and solves the pressure equation, as
//     the dissertation ran it (no momentum predictor, 9 correctors). Each corrector is one
//     Jacobi-like sweep of the viscous coupling, so the number of correctors and the step size set
//     how stiff the material behaves (docs/design/vof.md). The optional predictor (momentum_predictor)
//     solves the momentum matrix with the last pressure first; on B2 it lets the pressure in the
//     granular phase swing to -75 kPa and the material flow like a liquid, so it stays off.
//   * the granular phase's viscosity by name (VofConfig::rheology; models/): the Coulomb viscosity
//     nu = tan(phi) p / (rho_g |strain rate|) clipped to [nu_min, nu_max] (listing B.1); air
//     Newtonian, mixture mu = alpha rho1 nu1 + (1 - alpha) rho2 nu2 (mixture.hpp);
//   * boundary conditions one class each, by name (bc/): wall (stick), Coulomb slip wall (listing
//     B.2), Coulomb friction, inflow (velocity and fill profile), outflow, symmetry, atmosphere
//     (total pressure 0; air flows in, anything flows out);
//   * Courant-number time-step control for velocity and interface (eqs. 4.64-4.65);
//   * gravity may depend on time (rotating box).
// Linear systems through PETSc KSP (linear/; pressure: CG with GAMG or hypre BoomerAMG, by name); a
// solver that does not converge is an error.
// The code: solver.cpp (the step), alpha_eqn, momentum_eqn (+ momentum_predictor), pressure_eqn,
// active_region and hydrostatics, over the finite-volume vocabulary of fv/ (cell and face fields,
// interpolate, grad, reconstruct, FvMatrix) and the fields of fields.hpp; the configuration in
// config.hpp, the error in error.hpp, a checkpoint's state in state.hpp.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/vof/column_friction.hpp"
#include "engine/vof/config.hpp"
#include "engine/vof/error.hpp"
#include "engine/vof/mesh.hpp"
#include "engine/vof/backend.hpp"
#include "engine/vof/mpi/ranks.hpp"
#include "engine/vof/state.hpp"

namespace runout::engine::vof {

class VofSolver final : public VofBackend {
 public:
  /// ranks: a part of a run split over MPI ranks (mesh: the part's cells, own then ghosts;
  /// docs/design/parallel.md); by default the whole run on this process.
  VofSolver(Mesh mesh, VofConfig cfg, Ranks ranks = {});
  ~VofSolver();
  VofSolver(const VofSolver&) = delete;
  VofSolver& operator=(const VofSolver&) = delete;

  /// Initial state: alpha per cell (velocity zero unless set); computes the hydrostatic pressure.
  void initialise(const std::vector<double>& alpha, const std::vector<Vec>& U = {}) override;
  /// The state for a checkpoint; taking it changes nothing in the run.
  VofState state() const override;
  /// Continue from a checkpoint (in place of initialise()); sizes must match the mesh.
  void restore(const VofState& st) override;
  /// One time step of the length chosen by the Courant control, never past t_limit.
  StepStats step(double t_limit = 1e300) override;
  /// Step until `t_end` through the run loop (engine/stepping.hpp); `hook` is called after every
  /// step and may return false to stop.
  void run(double t_end, const std::function<bool(const StepStats&)>& hook = {});

  const Mesh& mesh() const override { return mesh_; }
  /// The ranks the run is split over (its halo's traffic counters).
  const Ranks& ranks() const { return ranks_; }
  double time() const override { return t_; }
  const std::vector<double>& alpha() const override;
  const std::vector<Vec>& velocity() const override;
  const std::vector<double>& pressure() const override;   ///< full pressure p [Pa]
  const std::vector<double>& viscosity() const override;  ///< granular-phase nu [m2/s]
  const std::vector<double>& face_flux() const override;
  /// Granular volume flux per face [m3/s] over the last step (alpha times the face flux, limited).
  const std::vector<double>& granular_flux() const override;
  /// What the bed carried at the last momentum build (VofConfig::column_friction; zero without it).
  const BedLoad& bed_load() const override;
  double face_pressure(int f) const override;

 private:
  struct Impl;  // the fields, the equations and their solvers (engine/vof/solver.cpp)
  Mesh mesh_;
  VofConfig cfg_;
  Ranks ranks_;
  double t_ = 0, dt_ = 0;
  std::unique_ptr<Impl> impl_;
};

}  // namespace runout::engine::vof
