#pragma once
// What a VOF step reports (StepStats) and what the bed carried at its momentum build (BedLoad).

namespace runout::engine::vof {

/// Per-step solver statistics.
struct StepStats {
  double t = 0, dt = 0, co = 0, alpha_co = 0, air_co = 0;  ///< Courant numbers: material, interface, air
  /// What set dt: the Courant number in the "material", at the "interface" or in the "air", the
  /// step's "growth" limit (20 % a step), the "largest step" or the "end time".
  const char* dt_limit = "";
  int pressure_iterations = 0;  ///< summed over the correctors (and outer correctors)
  int momentum_iterations = 0;  ///< of the predictor, both components (summed over outer correctors)
  double seconds_pressure = 0, seconds_total = 0;  ///< the pressure correctors (assembly, solve, flux update); the step
  double seconds_pressure_solve = 0;  ///< of seconds_pressure, the time in PETSc's KSPSolve (preconditioner set-up included)
  double alpha_min = 0, alpha_max = 0;
  double granular_volume = 0;   ///< sum alpha V [m3]
  double max_speed = 0;         ///< in cells with alpha > 0.5
  double divergence = 0;        ///< max |sum of face fluxes| / V over cells [1/s]
  int active_cells = 0;         ///< cells in the active region (the pressure system's size)
};

/// What the bed carried at the last momentum build, summed over the columns with material [N]:
/// the weight's bed-normal part, the centripetal load, the bed faces' pressure times their area,
/// and the load the friction took (per column the largest of the first two summed and the third).
struct BedLoad {
  double weight_normal = 0, centripetal = 0, face_pressure = 0, friction_load = 0;
  int columns = 0;  ///< columns with material
};

}  // namespace runout::engine::vof
