#pragma once
// A laboratory nest (lab.nest, one-way coupling as the nest on the DEM: docs/user/scenarios.md, "A 3D nest"): the
// depth-averaged engine runs the whole chute along x (engine/sh1d: from the left inflow, without the
// obstacles, open at the lower end) and records the depth and depth-averaged velocity at the nest's
// face after each of its steps; the 3D run covers [face, x_max] with the lab's cells and takes that
// flow through its left side (engine/vof/bc/nest_inflow.cpp): over a 3D step the record at the
// step's middle, as a plug (the lab's inflows are plugs or linear profiles; the depth-averaged run
// keeps only their mean), each face of the side filled by the share of its layer below the depth.
//
// The depth-averaged run's material: the lab material's density, internal friction phi and a bed
// friction of delta where the bottom is a Coulomb condition (coulomb-slip, coulomb-friction), else
// phi (a stick wall under the Coulomb viscosity carries at most tan(phi) p, engine/vof/bc/wall.cpp),
// and earth pressure 1: the 3D engine's normal stresses are its isotropic pressure (its viscous part
// adds none along the bed in a flow sheared parallel to it).
#include <string>
#include <vector>

#include "engine/vof/backend.hpp"
#include "jobs/drivers/vof_lab/config.hpp"
#include "runout/v1/run_record.pb.h"
#include "runout/v1/scenario.pb.h"

namespace runout::jobs::vof_lab {

/// The depth-averaged run's record at the nest's face.
struct FaceRecord {
  double x = 0;                  ///< the face (lab.nest.x_min on the nearest face of the lab's cells) [m]
  double width = 0;              ///< of the channel across (z) [m]
  double bed_friction_deg = 0;   ///< the depth-averaged run's delta
  int cells = 0;                 ///< the depth-averaged run's cells along the chute
  long steps = 0;
  double wall_s = 0;
  std::vector<double> t, h, u;   ///< after each step: time [s], depth [m] and velocity [m/s] at the face

  /// Depth and velocity at time `t` (linear between the recorded steps).
  void at(double time, double& depth, double& speed) const;
  /// The volume that crossed the face up to `time` [m3]: h u times the width, by the trapezoid rule.
  double volume_until(double time) const;
  double max_speed() const;
};

/// The part of the lab block the 3D run takes: [face, x_max] with the lab's cells (nx reduced), its
/// left side still the inflow side (its condition replaced by attach_face), no nest.
v1::Lab nest_part(const v1::Lab& L);

/// Runs the depth-averaged engine along the whole chute of `L` (a lab block with a nest) to its end
/// time and records the flow at the face of nest_part(L).
FaceRecord record_face(const v1::Lab& L, const Material& mat);

/// The left side's condition from the record (the patch apply_boundaries made for it) and the largest
/// step that keeps the inflow's Courant number within the configuration's.
void attach_face(const FaceRecord& rec, const v1::Lab& part, const engine::vof::Mesh& m, engine::vof::VofConfig& c);

/// What crossed the boundary of the 3D run, summed over every boundary face: in (material entering;
/// only the nest's face lets material in) and out [m3].
struct FaceBalance {
  double in = 0, out = 0;
  void step(const engine::vof::VofBackend& s, double dt);
};

/// The run record's `nest` block: the two inflows and the 3D run's balance, the record's figures.
void write_nest(const FaceRecord& rec, const FaceBalance& bal, double v_final, double t, int mesh_cells, double dx,
                v1::NestResult& out);

/// nest_inflow.csv: the record (time, depth, velocity, discharge per width).
void write_face_csv(const std::string& path, const FaceRecord& rec);

}  // namespace runout::jobs::vof_lab
