#pragma once
// The geometry of the laboratory set-ups: the lab block as a grid, obstacles (validation.md B5, B7)
// and the curved chute's bed (B8).
#include <google/protobuf/repeated_field.h>

#include "engine/vof/backend.hpp"
#include "jobs/formats/vof_frames.hpp"
#include "runout/v1/scenario.pb.h"

namespace runout::jobs::vof_lab {

/// The lab block's grid (jobs/formats/vof_frames.hpp) with the channel's width and centre line.
struct LabGrid : FrameGrid {
  double width = 0;  ///< across the channel: the modelled width in 3D, the plane mesh's thickness in 2D
  int kc = 0;        ///< the slice along the centre line (stations, gate monitor)
};

/// Is (x, y) inside the polygon x0, y0, x1, y1, ... (even-odd rule)?
bool in_polygon(const google::protobuf::RepeatedField<double>& xy, double x, double y);

/// Is the point c inside the obstacle (bed at y0)?
bool in_obstacle(const v1::LabObstacle& o, const engine::vof::Vec& c, double y0);

/// The curved chute of lab.chute (validation.md B8) in channel coordinates (X along the upper chute,
/// Y normal to it): the reference curve C(s) by arc length s, straight to the bend, a circular arc
/// over it (the inclination changes linearly with s), straight after it; the bed lies b(s, z) above
/// it along its normal N(s). point(s, n, z) = C(s) + (b(s, z) + n) N(s) + z e_z.
class ChuteBed {
 public:
  explicit ChuteBed(const v1::Lab& L);
  engine::vof::Vec point(double s, double n, double z) const;
  /// The reference curve's tangent at s: its angle to X (the tangent is (cos, sin) in X-Y).
  double angle(double s) const { return s <= s1_ ? 0.0 : s <= s2_ ? k_ * (s - s1_) : beta_; }

 private:
  double s1_, s2_, beta_, R_, k_;
};

}  // namespace runout::jobs::vof_lab
