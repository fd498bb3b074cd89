#pragma once
// The VOF engine's processes: the MPI communicator a distributed run spans, its rank and size, and the
// reductions a step takes over it (the time step's Courant numbers, the diagnostics' sums and bounds,
// the active region's decisions). One rank is a run of the whole mesh on one process: every call is
// then a plain copy and the engine runs as it does without MPI.
#include <mpi.h>

#include <vector>

namespace runout::engine::vof {

/// The processes of one run (MPI_COMM_WORLD of `mpirun -n N runout ...`, or MPI_COMM_SELF).
struct Comm {
  MPI_Comm comm = MPI_COMM_SELF;
  int rank = 0;
  int size = 1;

  /// The communicator's rank and size (MPI must be running: petsc_init() starts it).
  static Comm of(MPI_Comm c) {
    Comm k;
    k.comm = c;
    MPI_Comm_rank(c, &k.rank);
    MPI_Comm_size(c, &k.size);
    return k;
  }
  bool root() const { return rank == 0; }

  double max(double v) const { return reduce(v, MPI_MAX); }
  double min(double v) const { return reduce(v, MPI_MIN); }
  /// The sum over the ranks. Its rounding depends on the rank count (the partial sums differ); the
  /// engine takes it only for figures it reports, never for a value the step goes on with.
  double sum(double v) const { return reduce(v, MPI_SUM); }
  long long sum(long long v) const {
    if (size == 1) return v;
    long long r = 0;
    MPI_Allreduce(&v, &r, 1, MPI_LONG_LONG, MPI_SUM, comm);
    return r;
  }
  /// True on every rank when it is true on any.
  bool any(bool v) const {
    if (size == 1) return v;
    int in = v ? 1 : 0, out = 0;
    MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_LOR, comm);
    return out != 0;
  }
  /// Element-wise maxima of a short array (several bounds in one message).
  void max(std::vector<double>& v) const {
    if (size > 1) MPI_Allreduce(MPI_IN_PLACE, v.data(), int(v.size()), MPI_DOUBLE, MPI_MAX, comm);
  }
  /// Every rank's `mine`, one after another in the ranks' order, on every rank.
  std::vector<int> all_gather(const std::vector<int>& mine) const { return gather_all(mine, MPI_INT); }
  std::vector<double> all_gather(const std::vector<double>& mine) const { return gather_all(mine, MPI_DOUBLE); }

 private:
  template <class T>
  std::vector<T> gather_all(const std::vector<T>& mine, MPI_Datatype type) const {
    if (size == 1) return mine;
    int n = int(mine.size());
    const auto ranks = static_cast<std::size_t>(size);
    std::vector<int> counts(ranks), at(ranks, 0);
    MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
    for (std::size_t r = 1; r < counts.size(); ++r) at[r] = at[r - 1] + counts[r - 1];
    std::vector<T> all(std::size_t(at.back() + counts.back()));
    MPI_Allgatherv(mine.data(), n, type, all.data(), counts.data(), at.data(), type, comm);
    return all;
  }
  double reduce(double v, MPI_Op op) const {
    if (size == 1) return v;
    double r = 0;
    MPI_Allreduce(&v, &r, 1, MPI_DOUBLE, op, comm);
    return r;
  }
};

}  // namespace runout::engine::vof
