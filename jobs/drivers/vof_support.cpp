#include "jobs/drivers/vof_support.hpp"

#include <petscsys.h>

#include "engine/vof/linear/petsc.hpp"
#include "engine/vof/mpi/distributed.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <thread>

namespace runout::jobs {

std::mutex& petsc_turn() {
  static std::mutex m;
  return m;
}

std::string petsc_options() {
  PetscBool started = PETSC_FALSE;
  PetscInitialized(&started);
  if (!started) return {};
  char* all = nullptr;
  if (PetscOptionsGetAll(nullptr, &all) != 0 || !all) return {};
  std::string s(all);
  PetscFree(all);
  return s;
}

}  // namespace runout::jobs

namespace runout::jobs {

void record_distribution(const engine::vof::VofBackend& backend, long steps, v1::RunRecord& rec) {
  const auto* d = dynamic_cast<const engine::vof::DistributedVof*>(&backend);
  if (!d) return;
  const auto& comm = d->partition().parts;
  const auto t = d->take_traffic();
  const engine::vof::Comm& c = engine::vof::Comm::of(PETSC_COMM_WORLD);
  auto* out = rec.mutable_execution()->mutable_distribution();
  out->set_ranks(comm);
  out->set_cells(d->mesh().cells());
  out->set_cut_faces(d->partition().cut_faces);
  out->set_imbalance(d->partition().imbalance);
  out->set_ghost_share(double(c.sum((long long)d->part().ghosts())) / d->mesh().cells());
  const double per = 1.0 / double(std::max(1L, steps));
  out->set_exchanges_per_step(double(t.exchanges) * per);
  out->set_halo_bytes_per_step(double(c.sum(t.bytes)) * per);
  out->set_by_columns(d->part().columns.columns() > 0);
  out->set_strips(d->partition().strips);
}

LaunchRanks launch_ranks() {
  // Open MPI's mpirun, MPICH's launchers (PMI), Slurm's srun (its tasks).
  const std::pair<const char*, const char*> vars[] = {
      {"OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE"}, {"PMI_RANK", "PMI_SIZE"}, {"SLURM_PROCID", "SLURM_NTASKS"}};
  for (const auto& [r, n] : vars) {
    const char* rank = std::getenv(r);
    const char* size = std::getenv(n);
    if (rank && size) return {std::atoi(rank), std::max(1, std::atoi(size))};
  }
  return {};
}

RankScratch::RankScratch(int rank) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::temp_directory_path(ec) / ("runout-rank" + std::to_string(rank) + "-" + std::to_string(getpid()));
  fs::remove_all(dir, ec);
  fs::create_directories(dir / "out", ec);
  if (ec) {
    error_ = "cannot create " + dir.string() + ": " + ec.message();
    return;
  }
  dir_ = dir.string();
}

RankScratch::~RankScratch() {
  std::error_code ec;
  if (!dir_.empty()) std::filesystem::remove_all(dir_, ec);
}

std::string RankScratch::out_dir() const { return (std::filesystem::path(dir_) / "out").string(); }
std::string RankScratch::checkpoint_path() const { return (std::filesystem::path(dir_) / "checkpoint.h5").string(); }

std::string share_from_rank0(const std::string& bytes) {
  engine::vof::petsc_init();
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  long long n = (long long)bytes.size();
  MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, PETSC_COMM_WORLD);
  std::string out = rank == 0 ? bytes : std::string(std::size_t(n), '\0');
  for (long long at = 0; at < n;) {  // in pieces an int counts
    const int piece = int(std::min<long long>(n - at, 1 << 30));
    MPI_Bcast(out.data() + at, piece, MPI_CHAR, 0, PETSC_COMM_WORLD);
    at += piece;
  }
  return out;
}

int finish_worker_ranks(int exit_code) {
  finish_mpi(exit_code);
  return exit_code;
}

void finish_mpi(int exit_code) {
  PetscBool started = PETSC_FALSE;
  PetscInitialized(&started);
  if (!started) return;
  int size = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  if (exit_code != 0 && size > 1) {
    int rank = 0;
    MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
    if (rank > 0) std::this_thread::sleep_for(std::chrono::seconds(2));
    MPI_Abort(PETSC_COMM_WORLD, exit_code);
  }
  PetscFinalize();
}

}  // namespace runout::jobs
