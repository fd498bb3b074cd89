#pragma once
// The exchanges of a distributed run: a rank's ghost cells (the other ranks' cells that share a face
// with its own) take their owners' values of a cell field, and the ranks' own cells gathered into
// the whole mesh's field (what the run's outputs read). Both move the values' bytes unchanged, so
// a ghost holds its owner's value bit for bit.
#include <type_traits>
#include <vector>

#include "engine/vof/mpi/comm.hpp"

namespace runout::engine::vof {

/// Who sends which cells to whom: per neighbouring rank (ascending), the rank's own cells that are
/// the neighbour's ghosts and the ghosts it owns, both in ascending order of the cells' numbers in
/// the whole mesh, so that the two sides agree without a message.
struct HaloPlan {
  std::vector<int> ranks;
  std::vector<std::vector<int>> send, recv;  ///< local cell numbers, per neighbour
  long long cells_sent() const;
};

/// The ranks' own cells in the whole mesh: rank r owns global cells order[offset[r] .. offset[r+1]),
/// ascending, which are its local cells 0, 1, ...
struct OwnedCells {
  std::vector<int> order, offset;
};

/// The whole mesh's field on every rank from each rank's values of its own elements (`mine`, in the
/// order `owned` lists them).
void gather_owned(const Comm& comm, const OwnedCells& owned, const void* mine, void* global, std::size_t size);

class Halo {
 public:
  Halo() = default;
  Halo(Comm comm, HaloPlan plan, OwnedCells owned) : comm_(comm), plan_(std::move(plan)), owned_(std::move(owned)) {}

  const Comm& comm() const { return comm_; }
  const HaloPlan& plan() const { return plan_; }

  /// Every ghost's value from its owner (a field over the part's cells, owned first).
  template <class T>
  void exchange(std::vector<T>& v) const {
    static_assert(std::is_trivially_copyable_v<T>);
    if (comm_.size > 1) exchange_bytes(v.data(), sizeof(T));
  }
  /// The whole mesh's field from each rank's own cells (the first `owned` values of `local`), on
  /// every rank.
  template <class T>
  void gather(const std::vector<T>& local, std::vector<T>& global) const {
    static_assert(std::is_trivially_copyable_v<T>);
    global.resize(owned_.order.size());
    gather_owned(comm_, owned_, local.data(), global.data(), sizeof(T));
  }
  /// Bytes moved by one exchange of a field of `bytes` per cell, this rank's sends.
  long long bytes_per_exchange(int bytes) const { return plan_.cells_sent() * bytes; }

 private:
  void exchange_bytes(void* data, std::size_t size) const;

  Comm comm_;
  HaloPlan plan_;
  OwnedCells owned_;
};

}  // namespace runout::engine::vof
