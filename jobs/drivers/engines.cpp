// The engine registry: one row per engine set-up a scenario can resolve to.
#include <array>

#include "jobs/drivers/engine_run.hpp"

namespace runout::jobs {

namespace {

const std::array<EngineRow, 3> kEngines{{
    {kDepthAveragedEngine, "depth-averaged Savage–Hutter", prepare_depth_averaged},
    {kVofLabEngine, "3D VOF Navier–Stokes, laboratory set-up", prepare_vof_lab},
    {kVofTerrainEngine, "3D VOF Navier–Stokes", prepare_vof_terrain},
}};

}  // namespace

const EngineRow& engine_row(std::string_view name) {
  std::string names;
  for (const auto& row : kEngines) {
    if (row.name == name) return row;
    names += (names.empty() ? "" : ", ") + std::string(row.name);
  }
  throw ScenarioError("no engine set-up '" + std::string(name) + "' (there are: " + names + ")");
}

}  // namespace runout::jobs
