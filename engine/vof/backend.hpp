#pragma once
// The 3D engine as everything outside engine/vof sees it: the set-ups, the run loop's stepping, the
// frames, the laboratory monitors, the terrain's hazard maps and the checkpoints use this interface,
// never the solver's class. A back end (the CPU solver of solver.cpp, or the same split over MPI
// ranks, mpi/distributed.cpp) implements it and is made by make_vof_backend.
#include <memory>
#include <vector>

#include "engine/vof/config.hpp"
#include "engine/vof/mesh.hpp"
#include "engine/vof/state.hpp"
#include "engine/vof/stats.hpp"

namespace runout::engine::vof {

class VofBackend {
 public:
  virtual ~VofBackend() = default;
  /// Initial state: alpha per cell (velocity zero unless set); computes the hydrostatic pressure.
  virtual void initialise(const std::vector<double>& alpha, const std::vector<Vec>& U = {}) = 0;
  /// The state for a checkpoint; taking it changes nothing in the run.
  virtual VofState state() const = 0;
  /// Continue from a checkpoint (in place of initialise()); sizes must match the mesh.
  virtual void restore(const VofState& st) = 0;
  /// One time step of the length chosen by the Courant control, never past t_limit.
  virtual StepStats step(double t_limit) = 0;

  virtual const Mesh& mesh() const = 0;
  virtual double time() const = 0;
  virtual const std::vector<double>& alpha() const = 0;
  virtual const std::vector<Vec>& velocity() const = 0;
  virtual const std::vector<double>& pressure() const = 0;   ///< full pressure p [Pa]
  virtual const std::vector<double>& viscosity() const = 0;  ///< granular-phase nu [m2/s]
  virtual const std::vector<double>& face_flux() const = 0;
  /// Granular volume flux per face [m3/s] over the last step (alpha times the face flux, limited).
  virtual const std::vector<double>& granular_flux() const = 0;
  /// What the bed carried at the last momentum build (VofConfig::column_friction; zero without it).
  virtual const BedLoad& bed_load() const = 0;
  /// The pressure on boundary face f less the still air's there [Pa]: the cell's pressure carried
  /// hydrostatically to the face (as the Coulomb walls read it), the load a wall or a structure feels.
  virtual double face_pressure(int f) const = 0;
  /// Whether v holds on any of the processes that run this back end together (a run split over MPI
  /// ranks decides to stop on every rank alike); v itself on one process.
  virtual bool any(bool v) const { return v; }
};

/// The back end for a mesh and configuration: the CPU solver, split over the ranks of MPI_COMM_WORLD
/// when the program runs under `mpirun -n N` with N > 1 (DistributedVof); a bad configuration is a
/// VofError.
std::unique_ptr<VofBackend> make_vof_backend(Mesh mesh, VofConfig cfg);

}  // namespace runout::engine::vof
