#pragma once
// The flow's load on a wall patch of the 3D engine (a structure's walls and roof, a laboratory
// obstacle): the pressure's force, summed over the patch's faces, and the pressure on each face.
// The pressure on a face is VofBackend::face_pressure: the owner cell's pressure carried
// hydrostatically to the face, less the still air's there, so that a structure standing in still air
// feels nothing (its buoyancy in air, rho_air g V, is left out with it). The wall's shear is not
// part of the load: on the walls a structure gets (docs/design/vof.md, "Structures") it is at most
// tan(delta) times the normal stress, and the momentum balance of a flow stopped by a wall is carried
// by the pressure.
#include <string>
#include <vector>

#include "engine/vof/backend.hpp"

namespace runout::engine::vof {

struct PatchLoad {
  /// The force on the structure [N] in the engine's frame: the sum over the faces of p_f S_f, S_f
  /// pointing out of the flow's domain, i.e. into the structure.
  Vec force;
  double area = 0;          ///< the patch's area [m2]
  double max_pressure = 0;  ///< the highest face pressure [Pa] (0 when none is above the still air's)
  int max_face = -1;        ///< the face holding it (mesh numbering), -1 for none
  std::vector<double> face_pressure;  ///< per face of the patch, in the patch's order [Pa]
};

/// The load on patch `patch` now. Throws VofError for a patch the mesh does not have.
PatchLoad patch_load(const VofBackend& s, const std::string& patch);

}  // namespace runout::engine::vof
