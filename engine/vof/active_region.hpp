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
#include "engine/vof/mpi/ranks.hpp"

namespace runout::engine::vof {

class ActiveRegion {
 public:
  ActiveRegion(const Mesh& m, const CellFaces& cell_faces, const VofConfig& cfg, const Boundaries& bcs, Fields& fields,
               const Hydrostatics& hydrostatics, const Mixture& mixture, const Ranks& ranks)
      : m_(m), cell_faces_(cell_faces), cfg_(cfg), bcs_(bcs), fields_(fields), hydrostatics_(hydrostatics), mixture_(mixture), ranks_(ranks) {}

  /// Rebuild the region when the material has come near its edge (force: in any case). Returns
  /// true when it changed.
  bool update(bool force);
  /// Make the cells with d >= 0 the region: its cells, the cells next to it, its faces; the air
  /// outside at rest; no flux between resting cells; the material outside the halo, which no flux
  /// can reach, summed once.
  void set(const std::vector<int>& d);
  /// Every cell next to a boundary face that seeds the region in the step being taken lies in it
  /// (on every rank: a distributed run's ranks all call it).
  bool seeds_inside() const;
  /// Forget the region (the next update() builds it in any case).
  void clear() { n_active = 0; }
  /// The nonzeros per own row of the pressure system over the region: in the rank's own columns
  /// (diagonal block) and in the other ranks' (off).
  struct Nonzeros {
    std::vector<int> own, off;
  };
  Nonzeros pressure_nonzeros() const;
  /// Every cell of the whole mesh takes part (the pressure level is free in a closed domain).
  bool whole_mesh() const { return n_active_total == cells_total_; }
  /// The ranks the run is split over (a run on one process by default).
  const Ranks& ranks() const { return ranks_; }
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
  int n_active = 0;        ///< the region's cells in this part (own and ghosts)
  int n_own_active = 0;    ///< of them the rank's own: the pressure system's rows here, the first of `cells`
  int row_offset = 0;      ///< the pressure system's first row of this rank
  CellField<int> global_row;  ///< per cell, its row in the whole pressure system; -1 outside the region
  long long n_active_total = 0;  ///< the region's cells over all ranks
  double frozen_volume = 0, frozen_min = 0, frozen_max = 0;  ///< material outside the halo (unchanging)

 private:
  bool material_inside();
  bool seeds_inside_here() const;
  std::vector<int> layers_from_material() const;
  void flood_from_openings(std::vector<int>& d) const;
  void number_rows();

  const Mesh& m_;
  const CellFaces& cell_faces_;
  const VofConfig& cfg_;
  const Boundaries& bcs_;
  Fields& fields_;
  const Hydrostatics& hydrostatics_;
  const Mixture& mixture_;
  const Ranks& ranks_;
  long long cells_total_ = -1;
  std::vector<unsigned> mark_;  // the quick check's marks
  std::vector<char> halo_flag_; // membership of halo
  unsigned stamp_ = 0;
  std::vector<int> bfs_a_, bfs_b_;
};

}  // namespace runout::engine::vof
