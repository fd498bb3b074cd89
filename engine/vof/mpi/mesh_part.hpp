#pragma once
// One rank's part of a distributed mesh (docs/design/parallel.md): the rank's own cells, then its
// ghosts (the other ranks' cells that share a face with its own), as a mesh of its own that the
// numerics run on as on any mesh. Its faces are the whole mesh's faces between two of its cells
// (internal, in the whole mesh's order), then the whole mesh's boundary faces of its cells (the same
// patches, in their order, each patch kept even where the part has none of its faces), then the
// patch kRankRim: the faces between a ghost and a cell the part does not hold, out of the ghost. A
// cell's faces thus keep the whole mesh's order, and a sum over a cell's faces is the whole mesh's
// sum bit for bit. Only the own cells' values are computed right; the ghosts take their owners'
// values by the halo's exchange.
#include <string>
#include <vector>

#include "engine/vof/column_friction.hpp"
#include "engine/vof/mesh.hpp"
#include "engine/vof/mpi/halo.hpp"
#include "engine/vof/mpi/partition.hpp"

namespace runout::engine::vof {

/// The patch of a part's faces between its ghosts and the cells beyond them.
inline const std::string kRankRim = "rank rim";

struct MeshPart {
  Mesh mesh;                     ///< own cells [0, owned), then the ghosts
  int owned = 0;
  std::vector<int> cell_global;  ///< per local cell, its number in the whole mesh
  std::vector<int> face_global;  ///< per local face, its number in the whole mesh
  MeshColumns columns;           ///< the whole mesh's columns whose cells are all the part's own, in local numbers
  HaloPlan halo;
  OwnedCells owned_cells;        ///< every rank's own cells (for gathering the whole mesh's fields)
  int ghosts() const { return mesh.cells() - owned; }
};

/// Each rank's elements (cells, or faces by their owner cells) from a rank per element.
OwnedCells owned_by(const std::vector<int>& rank_of, int ranks);

/// Rank `rank`'s part of `m` split by `p`; `columns` the whole mesh's columns (may be empty).
MeshPart mesh_part(const Mesh& m, const Partition& p, int rank, const MeshColumns& columns);

}  // namespace runout::engine::vof
