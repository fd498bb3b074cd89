#pragma once
// The quality of a mesh, as OpenFOAM's checkMesh reports it: non-orthogonality (the angle between
// a face's area vector and the line joining the centres of its two cells; on the boundary, the line
// from the cell centre to the face centre), skewness (how far that line misses the face centre,
// relative to its length) and the cells' aspect ratio (their largest face against their smallest).
// The VOF discretisation corrects for non-orthogonality (terrain meshes); large values cost accuracy.
#include "engine/vof/mesh.hpp"

namespace runout::engine::vof {

struct MeshQuality {
  double non_orthogonality_max_deg = 0, non_orthogonality_mean_deg = 0;  ///< internal faces
  double skewness_max = 0, skewness_mean = 0;                            ///< internal faces
  double aspect_ratio_max = 0, aspect_ratio_mean = 0;                    ///< cells
};

MeshQuality mesh_quality(const Mesh& m);

}  // namespace runout::engine::vof
