#include "engine/vof/mpi/halo.hpp"

#include <cstring>

namespace runout::engine::vof {

long long HaloPlan::cells_sent() const {
  long long n = 0;
  for (const auto& s : send) n += (long long)s.size();
  return n;
}

// One message each way per neighbour: the sends packed in the plan's order, the receives unpacked
// into the ghosts in theirs.
void Halo::exchange_bytes(void* data, std::size_t size) const {
  auto* bytes = static_cast<unsigned char*>(data);
  const std::size_t nn = plan_.ranks.size();
  std::vector<std::vector<unsigned char>> out(nn), in(nn);
  std::vector<MPI_Request> req;
  req.reserve(2 * nn);
  for (std::size_t k = 0; k < nn; ++k) {
    in[k].resize(plan_.recv[k].size() * size);
    req.emplace_back();
    MPI_Irecv(in[k].data(), int(in[k].size()), MPI_BYTE, plan_.ranks[k], 71, comm_.comm, &req.back());
  }
  for (std::size_t k = 0; k < nn; ++k) {
    out[k].resize(plan_.send[k].size() * size);
    for (std::size_t i = 0; i < plan_.send[k].size(); ++i) std::memcpy(&out[k][i * size], bytes + std::size_t(plan_.send[k][i]) * size, size);
    req.emplace_back();
    MPI_Isend(out[k].data(), int(out[k].size()), MPI_BYTE, plan_.ranks[k], 71, comm_.comm, &req.back());
  }
  MPI_Waitall(int(req.size()), req.data(), MPI_STATUSES_IGNORE);
  for (std::size_t k = 0; k < nn; ++k)
    for (std::size_t i = 0; i < plan_.recv[k].size(); ++i) std::memcpy(bytes + std::size_t(plan_.recv[k][i]) * size, &in[k][i * size], size);
}

void gather_owned(const Comm& comm, const OwnedCells& owned, const void* local, void* global, std::size_t size) {
  const int n = comm.size;
  const std::size_t total = owned.order.size();
  std::vector<unsigned char> all(total * size);
  if (n == 1) {
    std::memcpy(all.data(), local, total * size);
  } else {
    // Counted in values, not bytes (a type of one value's bytes): a whole mesh's field of tensors
    // passes 2^31 bytes at 30 million cells.
    MPI_Datatype value;
    MPI_Type_contiguous(int(size), MPI_BYTE, &value);
    MPI_Type_commit(&value);
    std::vector<int> counts(static_cast<std::size_t>(n)), displs(static_cast<std::size_t>(n));
    for (int r = 0; r < n; ++r) {
      counts[std::size_t(r)] = owned.offset[std::size_t(r) + 1] - owned.offset[std::size_t(r)];
      displs[std::size_t(r)] = owned.offset[std::size_t(r)];
    }
    MPI_Allgatherv(local, counts[std::size_t(comm.rank)], value, all.data(), counts.data(), displs.data(), value, comm.comm);
    MPI_Type_free(&value);
  }
  auto* g = static_cast<unsigned char*>(global);
  for (std::size_t i = 0; i < total; ++i) std::memcpy(g + std::size_t(owned.order[i]) * size, &all[i * size], size);
}

}  // namespace runout::engine::vof
