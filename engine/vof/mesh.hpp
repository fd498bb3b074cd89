#pragma once
// Face-addressed finite-volume mesh for the VOF engine: cells (centre, volume), faces (owner,
// neighbour, area vector, centre), internal faces first, then the boundary faces grouped into named
// patches. Plane (one cell thick) meshes carry no front/back faces: those would be "empty" patches
// that contribute nothing. The numerics use only this addressing, so channel meshes, terrain-following
// meshes and imported meshes all work the same way.
#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "engine/vof/fv/field.hpp"

namespace runout::engine::vof {

struct Vec {
  double x = 0, y = 0, z = 0;
};
inline Vec operator+(Vec a, Vec b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec operator-(Vec a, Vec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec operator*(double s, Vec a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline double norm(Vec a) { return std::sqrt(dot(a, a)); }

struct Patch {
  std::string name;
  int start = 0;  ///< first face
  int size = 0;
};

struct Mesh {
  CellField<Vec> centre;     ///< per cell
  CellField<double> volume;  ///< per cell
  FaceField<int> owner, neighbour;  ///< per face; neighbour only for internal faces
  FaceField<Vec> Sf, Cf;     ///< per face: area vector (out of the owner), centre
  int n_internal = 0;          ///< faces [0, n_internal) are internal
  std::vector<Patch> patches;  ///< boundary faces in order, each patch contiguous
  double thickness = 0;        ///< plane meshes: the one cell's depth [m]; 0 for 3D meshes
  /// Derived per face: |Sf|, 1/|d . n| (d: owner centre to neighbour centre, or to the face centre on
  /// the boundary), and the owner's interpolation weight.
  FaceField<double> magSf, delta_coeff, weight;
  /// Derived per face: the non-orthogonal part of Sf, Sf - |Sf| delta_coeff d (zero where d is
  /// along Sf): what the over-relaxed correction of a face gradient takes explicitly.
  FaceField<Vec> non_orth;

  int cells() const { return int(volume.size()); }
  /// The cube root of the mean cell volume [m].
  double mean_cell_size() const;
  int faces() const { return int(owner.size()); }
  const Patch& patch(const std::string& name) const;
  int patch_index(const std::string& name) const;  ///< -1 when absent
  /// Compute the derived face data; checks that every cell is closed (sum of Sf = 0).
  void finish();
};

/// A rectangular block in the x-y plane (x along the channel, y normal to its bottom), one cell of
/// `thickness` deep, with optional geometric grading in y (ratio of the last to the first cell
/// height). Patches: "bottom", "top", "left" (x = x0), "right" (x = x1). Cells whose centre lies
/// inside `blocked` (a closed polygon, counter-clockwise) are left out, and the faces they shared
/// with kept cells form the patch "obstacle" (cut-out, stair-stepped obstacles).
struct BlockSpec {
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  int nx = 10, ny = 10;
  double thickness = 0.01;
  double y_grading = 1.0;
  std::vector<std::array<double, 2>> blocked;
  std::function<bool(const Vec&)> blocked_if;  ///< further cells to leave out, by centre
};
Mesh block_mesh(const BlockSpec& s);

/// A box of hexahedral cells (x along the channel, y normal to its bottom, z across it), uniform in
/// x and z, optionally graded in y. Cells whose centre satisfies `blocked` are left out and the
/// faces they shared with kept cells form the patch "obstacle" (stair-stepped obstacles: a
/// tetrahedron or a cylinder standing on the bottom is blocked out cell by cell). Patches:
/// "bottom" (y0), "top" (y1), "left" (x0), "right" (x1), "back" (z0), "front" (z1), "obstacle".
struct Block3Spec {
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1, z0 = 0, z1 = 1;
  int nx = 10, ny = 10, nz = 10;
  double y_grading = 1.0;
  std::function<bool(const Vec&)> blocked;
};
Mesh block_mesh_3d(const Block3Spec& s);

/// A structured mesh of hexahedra from its node positions: ni x nj x nk cells, node (i, j, k) at
/// `node(i, j, k)` for i <= ni, j <= nj, k <= nk (the lab's convention: i along the channel, j away
/// from its bed, k across it). Cells are numbered as block_mesh_3d numbers them, i fastest then j
/// then k, so cell (i, j, k) is (k nj + j) ni + i. Faces may be non-planar (area vector from the
/// diagonals, exact for the quad's outline); volumes by the divergence theorem; cell centre the
/// mean of its nodes. Patches as block_mesh_3d: "bottom" (j = 0), "top", "left" (i = 0), "right",
/// "back" (k = 0), "front". For terrain-following meshes (the curved chute of validation.md B8, the
/// column meshes over a DEM). Cells for which `blocked` holds are left out (the others keep their
/// order) and the faces they share with kept cells form the patch `patch_names[6]`. `patch_names`
/// renames the patches (the low and high ends of i, j, k, then the blocked cells' faces); equal
/// names make one patch.
struct HexGridSpec {
  int ni = 1, nj = 1, nk = 1;
  std::function<Vec(int i, int j, int k)> node;
  std::function<bool(int i, int j, int k)> blocked;
  std::array<std::string, 7> patch_names = {"left", "right", "bottom", "top", "back", "front", "obstacle"};
};
Mesh structured_hex_mesh(const HexGridSpec& s);

/// Rename the part of a patch whose face centres satisfy `pick` (or, for a pick taking an int, whose
/// face numbers do) into a new patch (e.g. the top boundary above x > 0 becomes "atmosphere"). Faces are reordered so that patches stay contiguous.
template <class Pick>
void split_patch(Mesh& m, const std::string& from, const std::string& to, Pick pick);

}  // namespace runout::engine::vof

#include "engine/vof/mesh_impl.hpp"
