#pragma once
// The active region (docs/design/vof.md, "Skipping air far from the material"): cells with material
// (alpha > active_alpha), cells next to an inflow, and `active_layers` layers of cells around them.
// Only these take part in the pressure equation; the rest is air at rest under the atmosphere's
// hydrostatic pressure, and faces to it act as openings. The region is rebuilt when material comes
// within two layers of its edge, so it keeps its shape (and the pressure preconditioner) for many
// steps.
#include <vector>

#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/config.hpp"
#include "engine/vof/fields.hpp"
#include "engine/vof/fv/ops.hpp"
#include "engine/vof/hydrostatics.hpp"
#include "engine/vof/mixture.hpp"

namespace runout::engine::vof {

class ActiveRegion {
 public:
  ActiveRegion(const Mesh& m, const CellFaces& cell_faces, const VofConfig& cfg, const Boundaries& bcs, Fields& fields,
               const Hydrostatics& hydrostatics, const Mixture& mixture)
      : m_(m), cell_faces_(cell_faces), cfg_(cfg), bcs_(bcs), fields_(fields), hydrostatics_(hydrostatics), mixture_(mixture) {}

  /// Rebuild the region when the material has come near its edge (force: in any case). Returns
  /// true when it changed.
  bool update(bool force);
  /// Make the cells with d >= 0 the region: its cells, the cells next to it, its faces; the air
  /// outside at rest; no flux between resting cells; the material outside the halo, which no flux
  /// can reach, summed once.
  void set(const std::vector<int>& d);
  /// Every cell next to a boundary face that seeds the region in the step being taken lies in it.
  bool seeds_inside() const;
  /// Forget the region (the next update() builds it in any case).
  void clear() { n_active = 0; }
  /// The number of nonzeros per row of the pressure system over the region.
  std::vector<int> pressure_nonzeros() const;
  /// Every cell takes part (the pressure level is free in a closed domain).
  bool whole_mesh() const { return n_active == m_.cells(); }
  bool active(int c) const { return index[c] >= 0; }
  const CellFaces& cell_faces() const { return cell_faces_; }
  /// The test "face f is one of `faces`", for grad() over the region's faces.
  auto face_in_region() const {
    return [this](int f) { return face_in[f] != 0; };
  }

  CellField<int> index;     ///< per cell: its row in the pressure system, -1 outside the region
  std::vector<int> cells;   ///< the region
  std::vector<int> halo;    ///< the region and the cells next to it (alpha may change there)
  std::vector<int> faces;   ///< faces of the region's cells, in ascending order (internal faces first)
  std::vector<char> face_in;  ///< per face: 1 when it is one of `faces`
  int n_active = 0;
  double frozen_volume = 0, frozen_min = 0, frozen_max = 0;  ///< material outside the halo (unchanging)

 private:
  bool material_inside();
  std::vector<int> layers_from_material() const;

  const Mesh& m_;
  const CellFaces& cell_faces_;
  const VofConfig& cfg_;
  const Boundaries& bcs_;
  Fields& fields_;
  const Hydrostatics& hydrostatics_;
  const Mixture& mixture_;
  std::vector<unsigned> mark_;  // the quick check's marks
  std::vector<char> halo_flag_; // membership of halo
  unsigned stamp_ = 0;
  std::vector<int> bfs_a_, bfs_b_;
};

}  // namespace runout::engine::vof
