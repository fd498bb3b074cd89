#pragma once
// A VOF run's state at a moment (VofSolver::state() and restore()): its fields and what the solver
// carries from step to step.
#include <vector>

#include "engine/vof/mesh.hpp"

namespace runout::engine::vof {

/// Everything a run needs to continue from a moment (a checkpoint): the fields and the solver's
/// state carried from step to step. A run restored from it takes exactly the steps the original
/// takes after state() (bit for bit on the same build and machine).
struct VofState {
  double t = 0, dt = 0;
  std::vector<double> alpha, p_rgh, p, nu1, mu, phi;
  std::vector<Vec> U;
  std::vector<int> active_cells;  ///< the active region (it depends on the run's history)
  /// The pressure preconditioner: steps since it was last built (VofConfig::pressure_pc_refresh),
  /// how often the current pressure solver has built it (0, 1, or 2 for more), and the operators it
  /// was built from at the first and at the latest build, in compressed rows over the active
  /// region's cells (GAMG keeps the first build's prolongators). restore() builds the same
  /// preconditioner from them.
  int steps_since_pc = 0, pc_builds = 0;
  std::vector<int> pc_rows, pc_cols;
  std::vector<double> pc_first_values, pc_values;
};

}  // namespace runout::engine::vof
