#pragma once
// The 3D engine's configuration for a run on the DEM: the scenario's material, the `vof` block's
// settings and the conditions of the terrain mesh's patches. This file is the one place where a
// terrain option's value becomes an engine setting.
#include "engine/vof/backend.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::vof_terrain {

/// Gravity vertical (-y in the engine's frame); the consistent pressure coupling with the outer and
/// non-orthogonal correctors of the `vof` block; the Coulomb viscosity from the material's density
/// and internal friction angle, confined by the pressure in excess of the still air's; the ground
/// by vof.bed with the material's bed friction angle; the top and the sides open to the
/// atmosphere (air at rest outside, anything out). The Coulomb viscosity keeps the engine's clip
/// (a clip grown with the flow's depth let the viscous stress carry part of the weight, and the bed
/// friction fell with the pressure; docs/design/vof.md). With vof.bed "coulomb-friction" and
/// vof.bed_normal_stress "column" (the default) the friction acts on the columns `columns`
/// (bed_columns()) and the ground takes no shear of its own; ScenarioError when they are missing.
/// The material in partly filled cells falls onto the bed at vof.settling_speed_m_s. Each structure's
/// walls and roof (structure_patch) are Coulomb slip walls at the bed friction angle.
engine::vof::VofConfig terrain_config(const ResolvedScenario& r, engine::vof::MeshColumns columns = {});

}  // namespace runout::jobs::vof_terrain
