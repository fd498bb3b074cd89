#pragma once
// comparison.png of a plane laboratory run (validation.md part B): the x-y section at the end with
// the material coloured by speed, velocity arrows and the free surface, our front and surface angle
// beside the reference values of the scenario's lab.reference block; below it the monitors over time
// (granular flux through the gate and out of the open end, the moving share) with the reference
// outflow and fluidisation time. Drawn with cairo.
#include <cmath>
#include <string>
#include <vector>

namespace runout::jobs {

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
  double fluidised = NAN, gate_flux_early = NAN, strain_early = NAN;
  // The reference (lab.reference); NaN where not given.
  std::string ref_source;
  double ref_front_min = NAN, ref_front_max = NAN, ref_angle = NAN, ref_fluidised = NAN, ref_outflow = NAN, ref_strain = NAN;
};

/// Writes the figure as PNG; throws std::runtime_error if it cannot.
void write_section_figure(const std::string& path, const SectionFigure& f);

}  // namespace runout::jobs
