#pragma once
// A laboratory set-up from the scenario's `lab` block: the grid and mesh (a plane block, a 3D block
// with obstacles, or the terrain-following curved chute), the engine's configuration and boundary
// conditions (config.hpp) and the initial fill.
#include <vector>

#include "engine/vof/backend.hpp"
#include "jobs/drivers/vof_lab/config.hpp"
#include "jobs/drivers/vof_lab/geometry.hpp"

namespace runout::jobs::vof_lab {

struct LabSetup {
  LabGrid g;
  engine::vof::Mesh m;
  /// Bed coordinates of each cell's centre (x along the channel, y above its bed, z across): the
  /// mesh's own coordinates for blocks, arc length and height above the bed on a curved chute.
  std::vector<engine::vof::Vec> local;
  Material mat{};
  engine::vof::VofConfig config;
  std::vector<double> alpha;  ///< the initial phase fraction per cell
  double v0 = 0;              ///< the initial volume of material [m^3]
  bool has_inflow = false;    ///< an inflow feeds the channel
};

/// Builds the set-up. Throws ScenarioError for a geometry or condition that cannot be built and
/// when no material is in the channel (neither filled nor fed).
void build_setup(const v1::Lab& L, LabSetup& out);

}  // namespace runout::jobs::vof_lab
