#pragma once
// The mesh split over the ranks of a distributed run (docs/design/parallel.md). A column mesh (terrain:
// a column of cells above each bed face) is split by whole columns: the bed friction, the hazard
// maps' integrals through the depth and the pressure's strongest couplings (thin layers stacked in a
// column) then stay on one rank. The units (columns, and cells outside every column) are split
//   * into strips along the flow where the mesh spreads across it (a 3D chute, an avalanche's
//     corridor): the units in order of their position in the horizontal direction in which the
//     mesh spreads least, cut into runs of equal cells. The engine computes only the active region
//     around the material, which moves along the flow: a split across the flow (Scotch's, which
//     minimises the cut) leaves the material on one rank for much of the run, strips give every
//     rank a share of it at every moment (docs/design/parallel.md);
//   * otherwise (a plane mesh) as the graph of units that share a face, by Scotch (Debian's
//     libscotch), each vertex weighted by its cells, in a deterministic context.
// Each rank splits alone: the same mesh and rank count give every rank, and every run, the same
// partition without a message.
#include <vector>

#include "engine/vof/column_friction.hpp"
#include "engine/vof/mesh.hpp"

namespace runout::engine::vof {

struct Partition {
  std::vector<int> part;    ///< per cell, its rank in [0, parts)
  int parts = 1;
  bool strips = false;      ///< strips along the flow (else Scotch's split of the graph)
  Vec across;               ///< the strips' direction across the flow
  long long cut_faces = 0;  ///< internal faces between two ranks' cells
  double imbalance = 1;     ///< the largest rank's cells over the mean
};

/// The cells of `m` over `parts` ranks; `columns` may be empty (no columns); `gravity` sets what is
/// horizontal (zero: no strips). Throws VofError when there are fewer graph vertices (columns and
/// loose cells) than parts.
Partition partition_cells(const Mesh& m, const MeshColumns& columns, int parts, const Vec& gravity = {});

/// The cut faces and the imbalance of a given split (a partition read back or built by hand).
Partition partition_figures(const Mesh& m, std::vector<int> part, int parts);

}  // namespace runout::engine::vof
