#pragma once
// The 3D engine split over the MPI ranks of a run (`mpirun -n N runout run ...`; docs/design/
// parallel.md), as everything outside engine/vof sees it: a VofBackend of the whole mesh. Each rank
// steps its part (VofSolver over a MeshPart); the whole mesh's fields, which the set-ups, monitors,
// maps, frames and checkpoints read, are gathered from the ranks' own cells when first read after a
// step, on every rank. The field accessors are therefore collective: every rank runs the same
// set-up and reads the same fields in the same order (the drivers do; only rank 0 keeps the files).
// A checkpoint is the whole mesh's state, so a run continues on any rank count.
#include <memory>

#include "engine/vof/backend.hpp"
#include "engine/vof/mpi/mesh_part.hpp"
#include "engine/vof/mpi/ranks.hpp"

namespace runout::engine::vof {

class VofSolver;

class DistributedVof final : public VofBackend {
 public:
  /// The whole mesh and configuration, split over the ranks of `comm` (whole columns where
  /// cfg.column_friction has columns).
  DistributedVof(Mesh whole, VofConfig cfg, Comm comm);
  ~DistributedVof() override;

  void initialise(const std::vector<double>& alpha, const std::vector<Vec>& U = {}) override;
  VofState state() const override;
  void restore(const VofState& st) override;
  StepStats step(double t_limit) override;

  const Mesh& mesh() const override { return whole_; }
  double time() const override;
  const std::vector<double>& alpha() const override;
  const std::vector<Vec>& velocity() const override;
  const std::vector<double>& pressure() const override;
  const std::vector<double>& viscosity() const override;
  const std::vector<double>& face_flux() const override;
  const std::vector<double>& granular_flux() const override;
  const BedLoad& bed_load() const override;
  double face_pressure(int f) const override;
  bool any(bool v) const override { return ranks().comm().any(v); }

  const MeshPart& part() const { return part_; }
  const Partition& partition() const { return partition_; }
  /// The halo's exchanges and bytes this rank sent since last asked.
  Ranks::Traffic take_traffic() const;
  /// The run's ranks (the solver's: its halo and traffic counters).
  const Ranks& ranks() const;

 private:
  template <class T>
  const std::vector<T>& cells(std::vector<T>& cache, int k, const std::vector<T>& local) const;
  const std::vector<double>& faces(std::vector<double>& cache, int k, const std::vector<double>& local) const;
  void stale() const { fresh_ = 0; }

  Mesh whole_;
  Partition partition_;
  MeshPart part_;
  OwnedCells owned_faces_;           // every rank's faces (those whose owner cell is its own)
  std::vector<int> my_faces_;        // this rank's own faces, local numbers, ascending in the whole mesh
  std::unique_ptr<VofSolver> solver_;
  // The whole mesh's fields as last gathered, and which are fresh (a bit per field).
  mutable std::vector<double> alpha_, p_, nu_, phi_, aphi_, pface_;
  mutable std::vector<Vec> U_;
  mutable unsigned fresh_ = 0;
};

}  // namespace runout::engine::vof
