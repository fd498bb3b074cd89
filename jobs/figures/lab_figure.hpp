#pragma once
// comparison.png of a plane laboratory run (validation.md part B): the x-y section at the end with
// the material coloured by speed, velocity arrows and the free surface, our front and surface angle
// beside the reference values of the scenario's lab.reference block; below it the monitors over time
// (granular flux through the gate and out of the open end, the moving share) with the reference
// outflow and fluidisation time. Drawn with cairo. 3D runs get a plan view instead (PlanFigure).
#include <cmath>
#include <string>
#include <vector>

namespace runout::figures {

struct SectionFigure {
  std::string title;
  int nx = 0, ny = 0;
  double x0 = 0, y0 = 0, dx = 0, dy = 0;
  /// Per grid cell (i + nx * j, j = 0 at the bottom): phase fraction (NaN where an obstacle blocks
  /// the cell) and velocity.
  std::vector<double> alpha, ux, uy;
  double vmax = 1;  ///< speed at the top of the colour scale [m/s]
  // Our figures.
  double front = NAN, upper_angle = NAN;
  double anchor_x = NAN, height = NAN;  ///< where our surface is at 70 % of the deposit's height [m], and that height
  std::vector<double> t, gate_flux, outflow, moving;  ///< monitors [s], [l/s], [l/s], [-]
  std::vector<double> shock;  ///< B6: the shock's distance from the end wall [m] (drawn instead of the fluxes)
  /// B1, the rotating box (drawn instead of the fluxes): the free surface's angle to the horizontal
  /// and the rotation folded to 0-90 deg (a rigid turn) [deg], the flowing layer at the centre [m],
  /// and their means once the material flows.
  std::vector<double> surface_angle, rigid_angle, flowing_layer;
  double angle_mean = NAN, angle_sd = NAN, layer_mean = NAN;
  double fluidised = NAN, gate_flux_early = NAN, strain_early = NAN;
  // The reference (lab.reference); NaN where not given.
  std::string ref_source;
  double ref_front_min = NAN, ref_front_max = NAN, ref_angle = NAN, ref_fluidised = NAN, ref_outflow = NAN, ref_strain = NAN;
};

/// Writes the figure as PNG; throws std::runtime_error if it cannot.
void write_section_figure(const std::string& path, const SectionFigure& f);

/// comparison.png of a 3D laboratory run (validation.md B7, B8): the plan view at the end (x along
/// the chute, or the arc length on a curved one; z across), the flow depth coloured from 0 to the
/// deepest column (or to the reference depth ratio times the undisturbed depth, if that is deeper),
/// depth-averaged velocity arrows, obstacles grey, dry ground (below 1 mm) white; our undisturbed
/// depth, the deepest column (a cross) and their ratio, each obstacle's shadow window (dashed) with
/// its dry area, beside the reference's depth ratio (an orange mark on the colour bar).
struct PlanFigure {
  std::string title;
  int nx = 0, nz = 0;
  double x0 = 0, z0 = 0, dx = 0, dz = 0;
  /// Per column (i + nx * k, k = 0 at z0): flow depth [m] (NaN: an obstacle not covered by flow)
  /// and the depth-averaged velocity along x and z [m/s].
  std::vector<double> depth, ux, uz;
  std::string xlabel = "x [m]";
  double undisturbed = NAN, deepest = NAN, deepest_x = NAN, deepest_z = NAN;
  struct Shadow {
    std::string shape;
    double x0, x1, z0, z1;  ///< the window [m]
    double dry_m2;          ///< its dry area (depth below 1 mm)
  };
  std::vector<Shadow> shadows;
  std::string ref_source;
  double ref_depth_ratio = NAN;  ///< deepest column over the undisturbed depth, at most (described)
};

/// Writes the plan view as PNG; throws std::runtime_error if it cannot.
void write_plan_figure(const std::string& path, const PlanFigure& f);

}  // namespace runout::figures
