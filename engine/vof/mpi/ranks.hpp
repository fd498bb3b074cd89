#pragma once
// A part of a distributed run as the engine's parts see it (docs/design/parallel.md): which cells of
// its mesh are the rank's own (the first `owned`; the rest are ghosts, the other ranks' cells next to
// its own), the exchange that gives the ghosts their owners' values, the reductions, and what the
// exchanges moved. The default is a run on one process: every cell its own, nothing exchanged.
#include <climits>
#include <vector>

#include "engine/vof/mpi/halo.hpp"

namespace runout::engine::vof {

class Ranks {
 public:
  Ranks() = default;
  Ranks(Halo halo, int owned) : halo_(std::move(halo)), owned_(owned) {}

  bool distributed() const { return halo_.comm().size > 1; }
  const Comm& comm() const { return halo_.comm(); }
  const Halo& halo() const { return halo_; }
  /// Cell c is this rank's own (its values are computed here; a ghost's come from its owner).
  bool own(int c) const { return c < owned_; }
  int owned(int cells) const { return owned_ < cells ? owned_ : cells; }

  /// The ghosts' values of a cell field from their owners.
  template <class T>
  void sync(std::vector<T>& v) const {
    if (!distributed()) return;
    halo_.exchange(v);
    ++exchanges_;
    bytes_ += halo_.bytes_per_exchange(int(sizeof(T)));
  }
  /// The exchanges and the bytes this rank sent since the counters were last taken.
  struct Traffic {
    long long exchanges = 0, bytes = 0;
  };
  Traffic take_traffic() const {
    const Traffic t{exchanges_, bytes_};
    exchanges_ = bytes_ = 0;
    return t;
  }

 private:
  Halo halo_;
  int owned_ = INT_MAX;
  mutable long long exchanges_ = 0, bytes_ = 0;
};

}  // namespace runout::engine::vof
