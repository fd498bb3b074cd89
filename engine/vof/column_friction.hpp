#pragma once
// The bed friction of a column mesh (terrain-following meshes: a vertical column of cells above
// each bed face; docs/design/vof.md, "The bed carries the column's weight"). The Coulomb friction
// takes its normal load from the whole column: the bed-normal part of the weight of the material
// above the bed face, plus the centripetal load of a curved bed, and never less than the bed face's
// pressure (impacts and other dynamic loads). It acts against the velocity of the column's
// material (its volume-weighted mean), on every cell of the column in proportion to the material
// the cell holds: material in a mixed cell above a nearly empty ground cell feels the bed as the
// rest of the column does. Implicit as the Coulomb friction condition: each cell takes the drag
// tan(delta) N (its share of the column's material) / max(|u_t|, creep speed) on its diagonal, u_t
// the column's material velocity along the bed, with the part on the bed-normal velocity given back
// explicitly, so that the force on the column is tan(delta) N against u_t, and a column held by less
// comes to rest cell by cell, without the creep of the Coulomb viscosity's clip.
#include <vector>

#include "engine/vof/fv/fv_matrix.hpp"
#include "engine/vof/stats.hpp"
#include "engine/vof/fv/ops.hpp"

namespace runout::engine::vof {

class ActiveRegion;
class Hydrostatics;
struct Fields;

/// The columns of a terrain-following mesh: per column its bed face (a boundary face), its cells
/// from the bed up, and the bed's curvature K in the engine's frame, such that material moving along
/// the bed at u needs the bed-normal acceleration u.K.u to follow it (positive where the bed is
/// concave: the load grows).
struct MeshColumns {
  std::vector<int> bed_face;     ///< per column
  std::vector<int> start;        ///< per column, the first of its cells in `cells`; one more at the end
  std::vector<int> cells;        ///< bottom up
  std::vector<Tensor> curvature; ///< per column; empty: a plane bed
  int columns() const { return int(bed_face.size()); }
};

struct ColumnFrictionConfig {
  MeshColumns columns;  ///< none: the bed conditions alone carry the friction
  double tan_delta = 0;
  double creep_speed = 1e-4;  ///< [m/s]; below it the force falls linearly
};

/// The friction's drag per cell (its diagonal coefficient [kg/s]; 0 where none) and its column's bed
/// normal: the pressure coupling takes the drag along the bed only (MomentumEqn).
struct ColumnDrag {
  CellField<double> drag;
  CellField<Vec> normal;
  CellField<Vec> given_back;  ///< the source's explicit part on the bed-normal velocity, drag (U.n) n
};

/// Adds the columns' bed friction to the momentum matrix's diagonal and source (cells of the active
/// region only), fills `drag` (sized to the mesh; cells of the active region set) and returns the
/// loads; rho1 the material's density.
BedLoad add_column_friction(const Mesh& m, const ColumnFrictionConfig& cf, double rho1, const Fields& F, const Hydrostatics& hs,
                            const ActiveRegion& region, FvMatrix<Vec>& UEqn, ColumnDrag& drag);

/// The columns above `bed_faces` (boundary faces) of a mesh whose cells stack away from them, as
/// the laboratory's blocks over their bottom: from each face's cell through the face opposite the
/// one it entered by (the face whose outward normal is closest to the bed's inward normal, within
/// 25 deg) to the next cell, until the walk reaches the boundary. Throws VofError when a cell has no
/// such face. No curvature (plane beds).
MeshColumns columns_above(const Mesh& m, const std::vector<int>& bed_faces);

/// Checks a MeshColumns against the mesh (offsets, cell and face indices, one column per bed face);
/// throws VofError naming what is wrong.
void check_columns(const Mesh& m, const MeshColumns& c);

}  // namespace runout::engine::vof
