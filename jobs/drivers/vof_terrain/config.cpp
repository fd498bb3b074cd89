#include "jobs/drivers/vof_terrain/config.hpp"

#include <algorithm>
#include <cmath>

#include "jobs/drivers/vof_terrain/mesh.hpp"

namespace runout::jobs::vof_terrain {

namespace vof = engine::vof;

vof::VofConfig terrain_config(const ResolvedScenario& r, vof::MeshColumns columns) {
  const auto& s = r.scenario;
  const auto& v = s.vof();
  vof::VofConfig c;
  apply_material_rheology(s.material(), c);  // density, rheology (checked when the scenario was resolved)
  c.max_co = c.max_alpha_co = v.max_courant();
  c.dt_max = 1.0;  // the Courant numbers limit the step on a real grid's cells (metres, not centimetres)
  c.n_outer_correctors = v.outer_correctors();
  c.n_non_orthogonal_correctors = v.non_orthogonal_correctors();
  c.non_orthogonal_limiter = v.non_orthogonal_limiter();
  // Long yielded layers need the consistent coupling: PISO's 1/A holds them back on any mesh
  // (docs/design/vof.md, "Meshes over terrain").
  c.consistent = c.momentum_predictor = true;
  // The band's height is a meshing choice: the air it holds above the flow must not add strength.
  c.coulomb_pressure = vof::CoulombPressure::excess;
  c.active_layers = std::max(0, v.active_layers());
  c.pressure_pc = v.pressure_preconditioner();
  if (v.has_max_viscosity_m2_s()) c.nu_max = v.max_viscosity_m2_s();
  c.gravity = [](double) { return vof::Vec{0, -9.81, 0}; };
  // Material in a partly filled cell falls onto the bed (docs/design/vof.md, "Thin mixed cells fall onto the bed").
  c.settling_speed = v.settling_speed_m_s();
  vof::PatchBc ground;
  ground.type = v.bed();
  std::replace(ground.type.begin(), ground.type.end(), '-', '_');  // the registry's spelling
  ground.friction_min_alpha = 0.01;
  ground.friction_total_normal_stress = v.bed_normal_stress() == "total";
  ground.tan_delta = std::tan(s.material().bed_friction_deg() * 3.14159265358979323846 / 180);
  if (ground.type == "coulomb_friction" && v.bed_normal_stress() == "column") {
    if (columns.columns() == 0) throw ScenarioError("vof.bed_normal_stress \"column\": the mesh has no columns");
    // The friction acts on the column's material (engine/vof/column_friction.hpp); the ground
    // itself takes no shear, so that the friction is counted once.
    c.column_friction.columns = std::move(columns);
    c.column_friction.tan_delta = ground.tan_delta;
    ground.type = "symmetry";
  }
  c.bc["ground"] = ground;
  for (const auto& st : r.structures) {
    vof::PatchBc wall;
    wall.type = "coulomb_slip";
    wall.tan_delta = std::tan(s.material().bed_friction_deg() * 3.14159265358979323846 / 180);
    c.bc[structure_patch(st.name)] = wall;
  }
  c.bc["atmosphere"].kind = vof::Bc::atmosphere;
  c.bc["sides"].kind = vof::Bc::atmosphere;
  return c;
}

}  // namespace runout::jobs::vof_terrain
