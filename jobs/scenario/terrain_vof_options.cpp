// The option table of the 3D engine on the DEM (engine "vof" without `lab`): the blocks `mesh`
// (the terrain-following mesh) and `vof` (the run). The DEM, area of interest, grid, releases,
// material, end time, stop rule and outputs are the depth-averaged engine's options
// (depth_averaged_options.cpp). The mapping into the engine's configuration lives in the terrain
// driver (jobs/drivers/vof_terrain/config.cpp), which `maps_to` names.
#include <string>
#include <vector>

#include "jobs/scenario/options.hpp"

namespace runout::jobs {

namespace {

using T = OptionType;
using U = Unset;

constexpr double kTime = 1e5;    // [s]
constexpr double kHeight = 1e3;  // mesh heights [m]

}  // namespace

const OptionTable& terrain_vof_options() {
  static const OptionTable t = {
      {"mesh.first_layer_m", T::number, U::as_given, "", Range{0, kHeight, true}, {}, "m",
       "vertical thickness of the ground layer; default a fifth of the thickest release column", "ColumnMeshSpec::first_layer_m"},
      {"mesh.growth", T::number, U::fill, "1.2", Range{1, 3}, {}, "", "each layer this many times the one below it",
       "ColumnMeshSpec::growth"},
      {"mesh.band_height_m", T::number, U::as_given, "", Range{0, kHeight, true}, {}, "m",
       "from the ground to the mesh's top; default eight times the thickest release column", "ColumnMeshSpec::band_height_m"},
      {"mesh.refinement", T::integer, U::keep, "1", Range{0, 8}, {}, "",
       "columns per grid cell along each axis, so that cells are not far longer than the flow is deep (the maps stay on "
       "the grid: each cell integrates its columns); 0: the rule, the smallest of 1, 2, 4 whose columns are within ten times "
       "the thickest release column, as far as 250,000 cells allow (docs/design/vof.md)",
       "ColumnMeshSpec::refinement"},
      {"mesh.corridor", T::choice, U::fill, "footprint", {}, {"footprint", "polygon", "none"}, "",
       "which columns are meshed: the depth-averaged engine's footprint on the same inputs (max depth above "
       "outputs.flow_threshold_m) dilated by mesh.corridor_margin_m, the polygons of mesh.corridor_path, or every column of the "
       "domain; material leaving the corridor is counted (run.json)",
       "vof_terrain::build_corridor"},
      {"mesh.corridor_margin_m", T::number, U::as_given, "", Range{0, 1e5}, {}, "m",
       "mesh.corridor \"footprint\": the footprint dilated by this much; default 150 m or two cells, whichever is wider",
       "vof_terrain::build_corridor"},
      {"mesh.corridor_path", T::path, U::as_given, "", {}, {}, "",
       "mesh.corridor \"polygon\": polygons of the corridor (any vector file, any CRS); the release must lie inside them",
       "ResolvedScenario::corridor_path"},
      {"mesh.corridor_crs", T::text, U::as_given, "", {}, {}, "", "the corridor polygons' CRS when the file has none",
       "vof_terrain::build_corridor"},
      {"vof.write_interval_s", T::number, U::fill, "10", Range{0, kTime}, {}, "s", "3D frames (fields.h5, fields.xmf) this often",
       "run control", "none"},
      {"vof.max_courant", T::number, U::fill, "0.2", Range{0.01, 1}, {}, "", "the time step's Courant number in the material",
       "VofConfig::max_co, max_alpha_co"},
      {"vof.bed", T::choice, U::fill, "coulomb-friction", {}, condition_names(true), "",
       "the ground's boundary condition (the section \"Boundary conditions\" below); those with the bed friction take "
       "material.bed_friction_deg",
       "VofConfig::bc[ground]"},
      {"vof.outer_correctors", T::integer, U::fill, "3", Range{1, 20}, {}, "", "outer correctors per step (PIMPLE's nOuterCorrectors)",
       "VofConfig::n_outer_correctors"},
      {"vof.non_orthogonal_correctors", T::integer, U::fill, "1", Range{0, 5}, {}, "",
       "non-orthogonal correctors per pressure corrector (interFoam's nNonOrthogonalCorrectors)",
       "VofConfig::n_non_orthogonal_correctors"},
      {"vof.non_orthogonal_limiter", T::number, U::fill, "1", Range{0, 1}, {}, "",
       "limits each face's non-orthogonal correction to psi / (1 - psi) times its orthogonal part (1: unlimited)",
       "VofConfig::non_orthogonal_limiter"},
      {"vof.bed_normal_stress", T::choice, U::fill, "column", {}, {"column", "pressure", "total"}, "",
       "the bed friction's normal load: the column's weight (its bed-normal part and the curved bed's centripetal load) acting on "
       "the column's material, the ground cell's pressure, or its total normal stress (less the viscous normal stress) "
       "(docs/design/vof.md)",
       "VofConfig::column_friction, PatchBc::friction_total_normal_stress"},
      {"vof.max_viscosity_m2_s", T::number, U::as_given, "", Range{1, 1e8}, {}, "m2/s",
       "the Coulomb viscosity's clip nu_max, default 1e2: material at rest creeps at about g sin(theta) h^2 / (3 nu_max) "
       "(a 2 m layer on 15 deg: 2.7 cm/s at 1e2, 0.3 mm/s at 1e4)",
       "VofConfig::nu_max"},
      {"vof.settling_speed_m_s", T::number, U::fill, "10", Range{0, 100}, {}, "m/s",
       "the granular phase falls through the air along gravity at this speed, so that the thin mixed cells of a spreading flow "
       "gather on the bed instead of running off as a sheet; 0: none (docs/design/vof.md)",
       "VofConfig::settling_speed"},
      {"vof.pressure_preconditioner", T::choice, U::fill, "ilu", {}, {"ilu", "gamg", "hypre"}, "",
       "the pressure solve's preconditioner: ILU(0) (suits the thin layers), PETSc's GAMG or hypre's BoomerAMG",
       "VofConfig::pressure_pc"},
      {"vof.active_layers", T::integer, U::fill, "4", Range{-1, 1000}, {}, "",
       "layers of air cells computed around the material; -1: every cell", "VofConfig::active_layers"},
      {"vof.checkpoint_interval_s", T::number, U::as_given, "", Range{0, kTime}, {}, "s",
       "with `runout run --checkpoint`: a checkpoint this often (simulated time)", "run control", "only when interrupted"},
      {"vof.profiles[].name", T::text, U::required, "", {}, {}, "", "a named point: the flow through the depth there (run.json)",
       "run record"},
      {"vof.profiles[].x", T::number, U::as_given, "", Range{}, {}, "", "easting, or longitude in a geographic CRS", "run record"},
      {"vof.profiles[].y", T::number, U::as_given, "", Range{}, {}, "", "northing, or latitude", "run record"},
      {"vof.profiles[].crs", T::text, U::as_given, "", {}, {}, "", "the point's CRS (\"EPSG:4326\"); default the grid's",
       "run record"},
  };
  return t;
}

}  // namespace runout::jobs
