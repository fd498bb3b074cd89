// The option table of the VOF laboratory block `lab` (options.hpp) and its materials. The mapping
// into the engine's VofConfig lives in the lab driver (jobs/drivers/vof_lab/config.cpp), which
// `maps_to` names; the choices of the engine's options come from its name tables
// (engine/vof/config.hpp), the boundary kinds and the granular viscosities from their rows
// (engine/vof/bc/conditions.hpp, engine/vof/models/registry.hpp).
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "engine/vof/bc/conditions.hpp"
#include "engine/vof/config.hpp"
#include "jobs/scenario/model_fields.hpp"
#include "jobs/scenario/options.hpp"
#include "jobs/scenario/scenario_impl.hpp"

namespace runout::jobs {

namespace {

using T = OptionType;
using U = Unset;

constexpr double kExt = 1e4;   // |coordinate| of the lab block [m]
constexpr double kTime = 1e4;  // lab times [s]
const Range kCoord{-kExt, kExt};
const Range kLength{0, kExt};

}  // namespace

std::vector<std::string> condition_names(bool bed) {
  std::vector<std::string> out;
  for (const auto* r : engine::vof::boundary_conditions())
    if ((!bed || r->bed) && !r->coupled) out.push_back(engine::vof::scenario_spelling(r->name));
  return out;
}

namespace {

std::vector<std::string> material_names() {
  std::vector<std::string> out;
  for (const auto& m : lab_materials()) out.push_back(m.name);
  return out;
}

Option coord(std::string path, std::string doc) {
  return {std::move(path), T::number, U::as_given, "", kCoord, {}, "m", std::move(doc), "mesh and geometry"};
}
Option length(std::string path, std::string doc, std::string zero = "") {
  return {std::move(path), T::number, U::as_given, "", kLength, {}, "m", std::move(doc), "geometry", std::move(zero)};
}

}  // namespace

const std::vector<LabMaterial>& lab_materials() {
  // validation.md part B; fine-sand: the rotating box, whose side walls raise the effective phi.
  static const std::vector<LabMaterial> m = {
      {"pvc", 936.17, 32, 20, "PVC granulate of the laboratory chutes", 32, 4e-3, 1550},
      {"sand", 1626.67, 37, 18, "quartz sand", 37, 0.98e-3, 2650},
      {"fine-sand", 1855, 54.5, 54.5, "the rotating box's fine sand (its side walls raise the effective phi)", 37, 0.175e-3, 2650},
  };
  return m;
}

std::vector<std::pair<std::string, double>> lab_model_defaults(const LabMaterial& m) {
  return {{"phi_deg", m.phi_deg},
          {"mu_s", std::tan(radians(m.repose_deg))},
          {"mu_2", std::tan(radians(m.repose_deg + LabMaterial::kMuIRise))},
          {"grain_diameter_m", m.grain_diameter},
          {"grain_density_kg_m3", m.grain_density}};
}

namespace {

// The channel's geometry, the mesh and the boundaries.
OptionTable lab_geometry_options() {
  return {
      {"lab.inclination_deg", T::number, U::as_given, "", Range{-90, 90, true, true}, {}, "deg", "zeta, the channel's inclination",
       "VofConfig::gravity"},
      coord("lab.x_min", "domain: x down the channel"),
      coord("lab.x_max", "domain: x down the channel"),
      coord("lab.y_min", "domain: y normal to the channel's bottom"),
      coord("lab.y_max", "domain: y normal to the channel's bottom"),
      coord("lab.z_min", "3D domain: z across the channel"),
      coord("lab.z_max", "3D domain: z across the channel"),
      {"lab.nx", T::integer, U::required, "", Range{2, 4e6}, {}, "", "cells along x", "mesh"},
      {"lab.ny", T::integer, U::required, "", Range{2, 4e6}, {}, "", "cells along y", "mesh"},
      {"lab.nz", T::integer, U::as_given, "", Range{1, 4e6}, {}, "", "cells along z (3D)", "mesh", "a plane set-up"},
      coord("lab.fill[].x_min", "a rectangle of granular material"),
      coord("lab.fill[].x_max", "a rectangle of granular material"),
      coord("lab.fill[].y_min", "a rectangle of granular material"),
      coord("lab.fill[].y_max", "a rectangle of granular material"),
      coord("lab.fill[].polygon_xy[]", "or a polygon: x1, y1, x2, y2, ... (at least 3 corners)"),
      length("lab.fill[].cap_radius", "3D: a spherical cap on the bed, its sphere's radius"),
      length("lab.fill[].cap_height", "3D: the cap's height at its centre (0 < cap_height <= cap_radius)"),
      coord("lab.fill[].cap_x", "3D: the cap's centre"),
      coord("lab.fill[].cap_z", "3D: the cap's centre"),
      {"lab.boundaries[].side", T::choice, U::required, "", {}, {"bottom", "top", "left", "right", "back", "front", "obstacle"}, "",
       "the side (back, front: 3D); a side not listed is a wall", "VofConfig::bc"},
      {"lab.boundaries[].kind", T::choice, U::required, "", {}, condition_names(false), "",
       "the boundary condition (engine/vof/bc; the section below)", "VofConfig::bc[side].kind"},
      coord("lab.boundaries[].from", "the part of the side this applies to (along it); default all"),
      coord("lab.boundaries[].to", "the part of the side this applies to (along it); default all"),
      {"lab.boundaries[].inflow_u0", T::number, U::as_given, "", Range{-100, 100}, {}, "m/s", "inflow: velocity along x at the bottom",
       "VofConfig::bc inflow_velocity"},
      {"lab.boundaries[].inflow_dudy", T::number, U::as_given, "", Range{-1e4, 1e4}, {}, "1/s",
       "inflow: the velocity's growth with y up to the fill height", "VofConfig::bc inflow_velocity"},
      length("lab.boundaries[].inflow_height", "inflow: granular material below this y, air above"),
  };
}

// The material, the run's times and controls, the obstacles and the published reference.
OptionTable lab_run_options() {
  return {
      {"lab.material", T::choice, U::fill, "pvc", {}, material_names(), "", "the granular material (the table below)",
       "VofConfig::rho1, phi_deg; coulomb-slip delta"},
      {"lab.bed_friction_deg", T::number, U::as_given, "", Range{0, 80, false, true}, {}, "deg",
       "bed friction angle of coulomb-slip sides instead of the material's", "coulomb-slip delta"},
      {"lab.end_time_s", T::number, U::fill, "1", Range{0, kTime, true}, {}, "s", "the simulated time", "run control"},
      {"lab.write_interval_s", T::number, U::fill, "0.05", Range{0, kTime}, {}, "s", "fields to HDF5 this often", "run control"},
      {"lab.max_courant", T::number, U::fill, "0.2", Range{0.01, 1}, {}, "", "the time step's Courant number",
       "VofConfig::max_co, max_alpha_co"},
      {"lab.correctors", T::integer, U::fill, "3", Range{1, 50}, {}, "", "PISO correctors per step", "VofConfig::n_correctors"},
      {"lab.outer_correctors", T::integer, U::keep, "1", Range{1, 20}, {}, "",
       "outer correctors per step (PIMPLE's nOuterCorrectors); 1: PISO as interFoam", "VofConfig::n_outer_correctors"},
      {"lab.rotation_period_s", T::number, U::as_given, "", Range{0, 1e6}, {}, "s", "the channel rotates (the rotating box, B1)",
       "VofConfig::gravity", "fixed"},
      coord("lab.stations_x[]", "report depth and velocity profiles at these x (run.json)"),
      {"lab.active_layers", T::integer, U::fill, "4", Range{-1, 1000}, {}, "",
       "layers of air cells computed around the material; -1: every cell", "VofConfig::active_layers"},
      {"lab.checkpoint_interval_s", T::number, U::as_given, "", Range{0, kTime}, {}, "s",
       "with `runout run --checkpoint`: a checkpoint this often (simulated time)", "run control", "only when interrupted"},
      {"lab.nest.x_min", T::number, U::as_given, "", kCoord, {}, "m",
       "a nest: the 3D run covers [nest.x_min, x_max], the chute above runs on the depth-averaged engine (1D) from the left "
       "inflow and feeds it there (upstream of every obstacle; moved to the nearest face of the cells)",
       "the 3D mesh and its left side"},
      {"lab.obstacles[].shape", T::choice, U::required, "", {}, {"polygon", "cylinder", "tetrahedron-edge", "tetrahedron-face"}, "",
       "cells inside are left out (cylinder, tetrahedra: 3D)", "mesh"},
      coord("lab.obstacles[].polygon_xy[]", "polygon: x1, y1, x2, y2, ... (at least 3 corners)"),
      coord("lab.obstacles[].x", "3D shapes: the footprint's centre"),
      coord("lab.obstacles[].z", "3D shapes: the footprint's centre"),
      length("lab.obstacles[].radius", "cylinder"),
      length("lab.obstacles[].height", "cylinder"),
      length("lab.obstacles[].edge", "tetrahedra"),
      {"lab.reference.source", T::text, U::as_given, "", {}, {}, "", "what the run is compared with, named in comparison.png",
       "figures"},
      {"lab.reference.front_x_min", T::number, U::as_given, "", Range{}, {}, "m", "final front: a range (with front_x_max)",
       "figures"},
      {"lab.reference.front_x_max", T::number, U::as_given, "", Range{}, {}, "m", "final front: a range (with front_x_min)",
       "figures"},
      {"lab.reference.surface_angle_deg", T::number, U::as_given, "", Range{0, 90, false, true}, {}, "deg",
       "upper deposit surface against the channel bottom", "figures"},
      {"lab.reference.fluidised_time_s", T::number, U::as_given, "", Range{0}, {}, "s", "whole mass moving", "figures"},
      {"lab.reference.outflow_l_s", T::number, U::as_given, "", Range{0}, {}, "l/s", "granular flux through the gate", "figures"},
      {"lab.reference.gate_strain_rate_1_s", T::number, U::as_given, "", Range{0}, {}, "1/s", "strain rate at the gate", "figures"},
      {"lab.reference.depth_ratio_max", T::number, U::as_given, "", Range{0}, {}, "",
       "3D: the deepest column at most this many times the undisturbed depth", "figures"},
  };
}

// The engine's models and numerical choices.
OptionTable lab_model_options() {
  return {
      {"lab.viscous_transpose", T::choice, U::fill, "harmonic", {}, names_of(engine::vof::kTransposeNames), "",
       "the viscous stress's transpose part: harmonic face viscosity, linear (interFoam) or none", "VofConfig::viscous_transpose"},
      {"lab.chute.bend_deg", T::number, U::as_given, "", Range{0, 90, true, true}, {}, "deg",
       "a curved chute (3D): turns up by this much", "mesh"},
      coord("lab.chute.bend_start_m", "the bend's start (arc length)"),
      coord("lab.chute.bend_end_m", "the bend's end (arc length)"),
      length("lab.chute.channel_radius_m", "R of the cross-channel parabola", "flat across"),
      {"lab.pressure_coupling", T::choice, U::fill, "piso", {}, names_of(engine::vof::kPressureCouplingNames), "",
       "the pressure equation with 1/A (interFoam) or SIMPLEC's 1/(A - H1) with the momentum predictor",
       "VofConfig::consistent, momentum_predictor"},
      {"lab.momentum_convection", T::choice, U::keep, "upwind", {}, names_of(engine::vof::kConvectionNames), "",
       "face values of the momentum's convection: first order or TVD (limitedLinearV 1)", "VofConfig::momentum_convection"},
      {"lab.coulomb_pressure", T::choice, U::keep, "total", {}, names_of(engine::vof::kCoulombPressureNames), "",
       "the Coulomb viscosity's confining pressure: p, or p less the still air's hydrostatic pressure",
       "VofConfig::coulomb_pressure"},
      {"lab.pressure_preconditioner", T::choice, U::keep, "gamg", {}, {"gamg", "hypre", "ilu"}, "",
       "the pressure solve's preconditioner: PETSc's GAMG, hypre's BoomerAMG or ILU(0)", "VofConfig::pressure_pc"},
      {"lab.wall_viscosity", T::choice, U::keep, "face", {}, names_of(engine::vof::kWallViscosityNames), "",
       "viscosity on walls and inflows: evaluated on the face (as OpenFOAM) or the cell's", "VofConfig::wall_viscosity"},
      {"lab.bed_normal_stress", T::choice, U::keep, "pressure", {}, {"pressure", "column"}, "",
       "the normal load of the bottom's coulomb-friction parts: the face's pressure, or the weight of the material in the cells "
       "above each bed face (the column found by walking the mesh away from the face), as on the DEM; plane beds only, other "
       "sides keep the face's pressure (docs/design/vof.md)",
       "VofConfig::column_friction"},
      {"lab.side_wall_width_m", T::number, U::as_given, "", Range{0, 10, true}, {}, "m",
       "plane set-ups: the width between the side walls they stand for (with side_wall_friction_deg)", "VofConfig::side_walls.width"},
      {"lab.side_wall_friction_deg", T::number, U::as_given, "", Range{0, 80, false, true}, {}, "deg",
       "plane set-ups: the side walls' friction angle; 2 tan(delta_w) p / width per unit volume against the velocity",
       "VofConfig::side_walls.tan_delta"},
  };
}

}  // namespace

const OptionTable& lab_options() {
  static const OptionTable t = [] {
    OptionTable v;
    for (auto* part : {lab_geometry_options, lab_run_options, lab_model_options})
      for (auto& o : part()) v.push_back(std::move(o));
    std::vector<std::string> from_material;  // the models' parameters whose default is the lab material's
    for (const auto& [field, value] : lab_model_defaults(lab_materials().front())) from_material.push_back(field);
    for (auto& o : lab_model_parameter_options(from_material)) v.push_back(std::move(o));
    return v;
  }();
  return t;
}

}  // namespace runout::jobs
