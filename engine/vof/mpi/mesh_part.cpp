#include "engine/vof/mpi/mesh_part.hpp"

#include <algorithm>
#include <map>
#include <set>

namespace runout::engine::vof {

namespace {

// The part's cells: its own in ascending order, then its ghosts in ascending order; -1 elsewhere.
std::vector<int> local_cells(const Mesh& m, const std::vector<int>& part, int rank, MeshPart& out) {
  const int nc = m.cells();
  std::vector<int> local(std::size_t(nc), -1);
  std::vector<char> ghost(std::size_t(nc), 0);
  for (int c = 0; c < nc; ++c)
    if (part[std::size_t(c)] == rank) {
      local[std::size_t(c)] = int(out.cell_global.size());
      out.cell_global.push_back(c);
    }
  out.owned = int(out.cell_global.size());
  for (int f = 0; f < m.n_internal; ++f) {
    const int o = m.owner[f], n = m.neighbour[f];
    if (part[std::size_t(o)] == rank && part[std::size_t(n)] != rank) ghost[std::size_t(n)] = 1;
    if (part[std::size_t(n)] == rank && part[std::size_t(o)] != rank) ghost[std::size_t(o)] = 1;
  }
  for (int c = 0; c < nc; ++c)
    if (ghost[std::size_t(c)]) {
      local[std::size_t(c)] = int(out.cell_global.size());
      out.cell_global.push_back(c);
    }
  return local;
}

// The part's faces in the order the header gives; returns the whole mesh's face -> the part's (-1).
std::vector<int> local_faces(const Mesh& m, const std::vector<int>& local, MeshPart& out) {
  Mesh& pm = out.mesh;
  std::vector<int> face_local(std::size_t(m.faces()), -1);
  auto add = [&](int f, int owner, int neighbour, bool flip) {
    face_local[std::size_t(f)] = pm.faces();
    out.face_global.push_back(f);
    pm.owner.push_back(owner);
    if (neighbour >= 0) pm.neighbour.push_back(neighbour);
    pm.Sf.push_back(flip ? -1.0 * m.Sf[f] : m.Sf[f]);
    pm.Cf.push_back(m.Cf[f]);
  };
  for (int f = 0; f < m.n_internal; ++f) {
    const int o = local[std::size_t(m.owner[f])], n = local[std::size_t(m.neighbour[f])];
    if (o >= 0 && n >= 0) add(f, o, n, false);
  }
  pm.n_internal = pm.faces();
  for (const Patch& p : m.patches) {
    Patch q{p.name, pm.faces(), 0};
    for (int f = p.start; f < p.start + p.size; ++f)
      if (local[std::size_t(m.owner[f])] >= 0) add(f, local[std::size_t(m.owner[f])], -1, false);
    q.size = pm.faces() - q.start;
    pm.patches.push_back(q);
  }
  Patch rim{kRankRim, pm.faces(), 0};
  for (int f = 0; f < m.n_internal; ++f) {
    const int o = local[std::size_t(m.owner[f])], n = local[std::size_t(m.neighbour[f])];
    if ((o >= 0) != (n >= 0)) add(f, o >= 0 ? o : n, -1, o < 0);
  }
  rim.size = pm.faces() - rim.start;
  pm.patches.push_back(rim);
  return face_local;
}

// The whole mesh's columns held whole by the rank, in its numbers.
MeshColumns local_columns(const MeshColumns& cols, const std::vector<int>& part, int rank, const std::vector<int>& local,
                          const std::vector<int>& face_local) {
  MeshColumns lc;
  lc.start.push_back(0);
  for (int k = 0; k < cols.columns(); ++k) {
    const int b = cols.start[std::size_t(k)], e = cols.start[std::size_t(k) + 1];
    if (!std::all_of(cols.cells.begin() + b, cols.cells.begin() + e, [&](int c) { return part[std::size_t(c)] == rank; })) continue;
    lc.bed_face.push_back(face_local[std::size_t(cols.bed_face[std::size_t(k)])]);
    for (int i = b; i < e; ++i) lc.cells.push_back(local[std::size_t(cols.cells[std::size_t(i)])]);
    lc.start.push_back(int(lc.cells.size()));
    if (!cols.curvature.empty()) lc.curvature.push_back(cols.curvature[std::size_t(k)]);
  }
  return lc;
}

// Per neighbouring rank, the own cells that are its ghosts and the ghosts it owns (ascending in the
// whole mesh's numbers, which the local numbers of either kind keep).
HaloPlan halo_plan(const Mesh& m, const std::vector<int>& part, int rank, const std::vector<int>& local) {
  std::map<int, std::set<int>> send, recv;
  for (int f = 0; f < m.n_internal; ++f) {
    const int o = m.owner[f], n = m.neighbour[f], ro = part[std::size_t(o)], rn = part[std::size_t(n)];
    if (ro == rn) continue;
    if (ro == rank) {
      send[rn].insert(local[std::size_t(o)]);
      recv[rn].insert(local[std::size_t(n)]);
    } else if (rn == rank) {
      send[ro].insert(local[std::size_t(n)]);
      recv[ro].insert(local[std::size_t(o)]);
    }
  }
  HaloPlan h;
  for (const auto& [r, cells] : send) {
    h.ranks.push_back(r);
    h.send.emplace_back(cells.begin(), cells.end());
    h.recv.emplace_back(recv[r].begin(), recv[r].end());
  }
  return h;
}

}  // namespace

OwnedCells owned_by(const std::vector<int>& part, int parts) {
  OwnedCells o;
  o.offset.assign(std::size_t(parts) + 1, 0);
  for (int r : part) ++o.offset[std::size_t(r) + 1];
  for (int r = 0; r < parts; ++r) o.offset[std::size_t(r) + 1] += o.offset[std::size_t(r)];
  o.order.resize(part.size());
  std::vector<int> next(o.offset.begin(), o.offset.end() - 1);
  for (std::size_t c = 0; c < part.size(); ++c) o.order[std::size_t(next[std::size_t(part[c])]++)] = int(c);
  return o;
}

MeshPart mesh_part(const Mesh& m, const Partition& p, int rank, const MeshColumns& columns) {
  MeshPart out;
  const auto local = local_cells(m, p.part, rank, out);
  Mesh& pm = out.mesh;
  pm.thickness = m.thickness;
  for (int c : out.cell_global) {
    pm.centre.push_back(m.centre[c]);
    pm.volume.push_back(m.volume[c]);
  }
  const auto face_local = local_faces(m, local, out);
  pm.finish();
  out.columns = local_columns(columns, p.part, rank, local, face_local);
  out.halo = halo_plan(m, p.part, rank, local);
  out.owned_cells = owned_by(p.part, p.parts);
  return out;
}

}  // namespace runout::engine::vof
