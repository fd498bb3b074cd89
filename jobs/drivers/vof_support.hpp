#pragma once
// What the VOF engine's set-ups (laboratory and terrain) share: PETSc's turn and its options.
#include <mutex>
#include <string>

#include "engine/vof/backend.hpp"
#include "runout/v1/run_record.pb.h"
#include "jobs/drivers/run.hpp"

namespace runout::jobs {

/// PETSc keeps process-wide state and is not thread-safe: in a server with several workers, VOF
/// runs take turns by holding this (depth-averaged runs are not affected).
std::mutex& petsc_turn();

/// PETSc's options database as the run used it (PETSC_OPTIONS and the engine's defaults); empty
/// before PETSc started.
std::string petsc_options();

/// The run record's `execution.distribution` when `backend` ran split over MPI ranks (collective:
/// every rank calls it); steps: the run's steps.
void record_distribution(const engine::vof::VofBackend& backend, long steps, v1::RunRecord& rec);

/// This process's place under an MPI launcher (`mpirun -n N`, `srun` with N tasks), read from the
/// launcher's environment before MPI starts: {0, 1} when the program runs alone. A 3D run then
/// splits over the N processes (engine/vof/mpi/distributed.hpp).
struct LaunchRanks {
  int rank = 0, size = 1;
};
LaunchRanks launch_ranks();

/// At the end of a program that may have run split over MPI ranks: PETSc finished, and with it MPI
/// when PETSc started it (a launcher reports a process that ends without it as failed). A failure
/// (exit_code != 0) on one rank of several aborts them all with that code: the others would wait
/// for it in their next exchange. A rank other than 0 waits two seconds before it aborts, so that
/// rank 0, when it failed alike (bad input fails every rank), says why (its message, a worker's
/// outcome) before the launcher ends it.
void finish_mpi(int exit_code);

/// The private folder of a rank other than 0 of a run split over MPI ranks: the rank runs the same
/// set-up and outputs as rank 0 into it (TMPDIR/runout-rank<R>-<pid>; its results in out/, its
/// checkpoint beside), and the folder goes with this. error() says why it could not be made.
class RankScratch {
 public:
  explicit RankScratch(int rank);
  ~RankScratch();
  RankScratch(const RankScratch&) = delete;
  RankScratch& operator=(const RankScratch&) = delete;
  const std::string& error() const { return error_; }
  std::string out_dir() const;
  std::string checkpoint_path() const;

 private:
  std::string dir_, error_;
};

/// Under a launcher: rank 0's `bytes` on every rank (MPI started through PETSc first). A worker's
/// task reaches rank 0 alone (mpirun and srun --input=0 give the others no standard input).
std::string share_from_rank0(const std::string& bytes);

/// finish_mpi(exit_code), then exit_code: a worker's last word under a launcher.
int finish_worker_ranks(int exit_code);

}  // namespace runout::jobs
