#pragma once
// The lab block's options (scenario block `lab`, strings and numbers) mapped into the VOF engine's
// configuration: the material table, the solver's settings and gravity, and the boundary
// conditions of the listed sides. This file is the one place where an option's value becomes an
// engine setting; an unknown value is a ScenarioError naming the valid ones (an empty string is the
// option's default).
#include "engine/vof/backend.hpp"
#include "engine/vof/column_friction.hpp"
#include "engine/vof/error.hpp"
#include "runout/v1/scenario.pb.h"

namespace runout::jobs::vof_lab {

/// A granular material of the laboratory cases (validation.md part B).
struct Material {
  double rho, phi_deg, delta_deg;  ///< density [kg/m^3], internal and bed friction angles [deg]
};

/// lab.material with lab.phi_deg and lab.bed_friction_deg in place of the table's angles.
Material lab_material(const v1::Lab& L);

/// The solver's settings: material, Courant numbers, correctors, discretisation choices, pressure
/// solver, active region and gravity (lab.inclination_deg, turning with lab.rotation_period_s).
engine::vof::VofConfig lab_config(const v1::Lab& L, const Material& mat);

/// The boundary conditions: every side of the mesh a wall, then each of lab.boundaries its own
/// patch (split off its side between from and to) with its kind. Throws ScenarioError for a side
/// already taken or a part with no face.
void apply_boundaries(const v1::Lab& L, const Material& mat, engine::vof::Mesh& m, engine::vof::VofConfig& c);

}  // namespace runout::jobs::vof_lab
