#pragma once
// The boundary of a 3D nest inside a depth-averaged run (scenario `nest`): the grid faces between the
// nest's cells and the others, the flux gauges that count the depth-averaged scheme's own fluxes
// through them (one gauge per boundary cell of the nest: its first boundary face to the gauge's
// right, a second to its left), and the record of each step: per face the volume that entered the
// nest and the depth and velocity of the cell outside it. The nest's 3D run reads the record as its
// inflow (engine/vof/bc/nest_inflow.cpp): per face and 3D step, the mean of the entering flux over
// the step, with the outside cell's depth and velocity.
#include <cstdint>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "terrain/terrain.hpp"

namespace runout::jobs::nest {

struct BoundaryFace {
  std::size_t inside = 0, outside = 0;  ///< grid cells (j * nx + i)
  int side = 0;                         ///< of the inside cell: 0 west, 1 east, 2 south, 3 north
};

/// What the 3D run takes through a face over a step.
struct FaceInflow {
  double q = 0;         ///< the mean volume flux into the nest through the whole grid face [m3/s] (> 0)
  double depth = 0;     ///< the outside cell's vertical depth [m]
  double east = 0, north = 0;  ///< its depth-averaged velocity [m/s]
};

class NestBoundary {
 public:
  /// The boundary of `cells` (one flag per grid cell) on `g`. Throws ScenarioError naming `what` when
  /// no cell is flagged, when a flagged cell lies on the grid's edge or outside the domain, or when a
  /// cell has more than two boundary faces (the nest is one cell wide there).
  NestBoundary(const terrain::Grid& g, std::vector<std::uint8_t> cells, const std::string& what);
  const std::vector<std::uint8_t>& cells() const { return cells_; }
  const std::vector<BoundaryFace>& faces() const { return faces_; }
  int cell_count() const;
  /// The gauges to add to the depth-averaged configuration; `first` is the index the first of them
  /// takes among Sh2dConfig::gauges.
  std::vector<engine::FluxGauge> gauges(std::size_t first);
  /// After a step that ended at t: the gauges' running counts and the state.
  void record(double t, const engine::Sh2dEngine& e);
  /// The record's start (the run's start time).
  void start(double t) { times_.assign(1, t); }
  long steps() const { return long(times_.size()) - 1; }
  double end_time() const { return times_.back(); }
  /// The volume that entered through all faces, summed over the steps (per face and step only what
  /// entered) [m3].
  double inflow_volume() const;
  /// The start of the first step in which material entered (the record's end when none did).
  double first_inflow_time() const;
  /// The deepest flow of the cells outside the faces over the record [m].
  double max_depth() const { return max_depth_; }
  /// The fastest depth-averaged speed of the cells outside the faces over the record [m/s].
  double max_speed() const { return max_speed_; }
  /// What entered through face k over [t0, t1] (t0 == t1: the step holding t0); false when nothing did.
  bool inflow(std::size_t k, double t0, double t1, FaceInflow& out) const;

 private:
  const terrain::Grid& g_;
  std::vector<std::uint8_t> cells_;
  std::vector<BoundaryFace> faces_;
  std::vector<int> right_, left_;  // per face: the gauge that counts it to its right / left (-1: not that side)
  std::size_t first_ = 0;
  std::vector<double> last_right_, last_left_;
  std::vector<double> times_;  // step ends, times_[0] the start
  std::vector<double> entered_, depth_, east_, north_;  // per step (row) and face
  double max_depth_ = 0, max_speed_ = 0;
};

}  // namespace runout::jobs::nest
