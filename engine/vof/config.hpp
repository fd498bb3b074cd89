#pragma once
// The VOF engine's configuration (VofConfig) and what it is made of: the boundary conditions per
// patch (Bc, PatchBc), the numerical choices (Transpose, CoulombPressure, Convection,
// WallViscosity) with the name tables scenarios take them by, and the names of the boundary
// conditions. The equations, models, boundary conditions and solvers
// of engine/vof take their settings from here; solver.hpp (VofSolver) includes it.
#include <array>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "engine/names.hpp"
#include "engine/vof/column_friction.hpp"
#include "engine/vof/mesh.hpp"

namespace runout::engine::vof {

/// wall: stick; coulomb_slip: listing B.2; atmosphere: total pressure of air at rest outside, air in
/// and anything out; inflow: prescribed velocity and phase fraction; outflow: zero gradient;
/// symmetry: no flow through it and no shear along it (a plane of symmetry, a frictionless wall).
/// coulomb_friction: the bed's Coulomb friction as a force, tan(delta) p per area against the sliding
/// velocity (regularised below friction_creep_speed, so that material held by less than it sticks);
/// unlike coulomb_slip, whose slip fraction divides by the cell's own Coulomb viscosity, it gives the
/// bed friction delta also where delta < phi (docs/design/vof.md).
enum class Bc { wall, coulomb_slip, atmosphere, inflow, outflow, symmetry, coulomb_friction };

struct PatchBc {
  Bc kind = Bc::wall;
  double tan_delta = 0;  ///< Coulomb slip wall and Coulomb friction: bed friction
  double friction_creep_speed = 1e-4;  ///< Coulomb friction: below this sliding speed [m/s] the friction force falls linearly
  std::function<Vec(const Vec&)> inflow_velocity;  ///< inflow: velocity at a face centre
  std::function<double(const Vec&)> inflow_alpha;  ///< inflow: phase fraction at a face centre
  /// nest_inflow: whether material enters through boundary face f over the step [t0, t1], and then
  /// the face's velocity and phase fraction over the step (their mean; t0 == t1: at t0).
  std::function<bool(int f, double t0, double t1, Vec& velocity, double& alpha)> timed_inflow;
  /// The condition by its name in the registry (engine/vof/bc/registry.cpp), for kinds without a
  /// Bc value; empty: `kind`'s.
  std::string type = {};
  /// Coulomb friction: cells on the bed with at least this much material take the friction (the rest a
  /// wall's shear). 0.5 suits resolved fronts; on coarse terrain grids a front's ground cells are
  /// partly filled and need the friction too (the terrain driver takes 0.01).
  double friction_min_alpha = 0.5;
  /// Coulomb friction: the normal load is the total normal stress, p less the viscous normal stress
  /// 2 mu n.grad(U).n of the cell, instead of p alone (a spreading layer carries part of its weight
  /// by the viscous stress; docs/design/vof.md). The terrain driver takes it.
  bool friction_total_normal_stress = false;
};

/// How the viscous stress's transpose part is taken (VofConfig::viscous_transpose).
enum class Transpose { linear, harmonic, off };
/// The pressure the Coulomb viscosity (and the Coulomb bed conditions) take as the confining
/// stress: the full pressure p, or its excess over the still air's hydrostatic pressure at the same
/// height (what the grains carry beyond the ambient air; docs/design/vof.md).
enum class CoulombPressure { total, excess };
/// How the momentum's convection term takes its face values (VofConfig::momentum_convection).
enum class Convection { upwind, limited_linear };
/// Which viscosity the viscous term takes on a boundary face (VofConfig::wall_viscosity).
enum class WallViscosity { face, cell };

/// The choices above by the names scenarios give them: the lab block's option table takes its
/// choices from these tables and the lab driver parses with them (one list each).
inline constexpr NameTable<Transpose, 3> kTransposeNames{
    {{"explicit", Transpose::linear}, {"harmonic", Transpose::harmonic}, {"off", Transpose::off}}};
inline constexpr NameTable<CoulombPressure, 2> kCoulombPressureNames{
    {{"total", CoulombPressure::total}, {"excess", CoulombPressure::excess}}};
inline constexpr NameTable<Convection, 2> kConvectionNames{
    {{"upwind", Convection::upwind}, {"limited_linear", Convection::limited_linear}}};
inline constexpr NameTable<WallViscosity, 2> kWallViscosityNames{{{"face", WallViscosity::face}, {"cell", WallViscosity::cell}}};
/// The pressure-velocity coupling: PISO with 1/A (false) or the consistent 1/(A - H1) with the
/// momentum predictor (true; VofConfig::consistent and momentum_predictor).
inline constexpr NameTable<bool, 2> kPressureCouplingNames{{{"piso", false}, {"consistent", true}}};

/// The boundary conditions' names (PatchBc::type). The granular viscosity models' rows (names,
/// parameters, checks): models/registry.hpp.
std::vector<std::string> boundary_condition_names();

struct VofConfig {
  double rho1 = 936.17;        ///< granular bulk density [kg/m3]
  double rho2 = 1.0;           ///< air [kg/m3]
  double nu2 = 1.48e-5;        ///< air kinematic viscosity [m2/s]
  double phi_deg = 32;         ///< internal friction angle of the granular phase (the Coulomb viscosity)
  std::string rheology = "coulomb";  ///< the granular phase's viscosity model, by name (models/registry.hpp)
  /// The mu(I) rheology (rheology "mu_i", models/mu_i.hpp): mu = mu_s + (mu_2 - mu_s) / (I_0 / I + 1),
  /// I = d |strain rate| / sqrt(p / rho_s). Defaults: the glass beads of Jop, Forterre & Pouliquen
  /// (2006): mu_s = tan 20.9 deg, mu_2 = tan 32.76 deg, I_0 = 0.279, d = 0.5 mm, rho_s = 2450 kg/m3.
  struct MuI {
    double mu_s = 0.381863;        ///< static friction coefficient (I -> 0, unregularised)
    double mu_2 = 0.643468;        ///< limiting friction coefficient (I -> infinity)
    double i0 = 0.279;             ///< inertial number where mu is halfway between mu_s and mu_2
    double grain_diameter = 5e-4;  ///< d [m]
    double grain_density = 2450;   ///< rho_s [kg/m3]; rho1 / rho_s is the solid fraction
    /// Barker & Gray (2017)'s alpha of the regularised branch sqrt(alpha / ln(A / I)) below I_1.
    double alpha = 0;  ///< the regularisation's alpha; 0: MuILaw::scaled_alpha (1.9 for these beads)
  } mu_i;
  double nu_min = 1e-15, nu_max = 1e2;  ///< viscosity limits [m2/s]
  /// The side walls a plane (one cell thick) set-up stands for: two walls `width` apart, each
  /// carrying the Coulomb friction tan_delta p against the velocity (Jop, Forterre & Pouliquen
  /// 2005), 2 tan_delta p / width per unit volume of material; width 0: none. Below creep_speed the
  /// force falls linearly, as the Coulomb friction bed's.
  struct SideWalls {
    double width = 0;          ///< [m]
    double tan_delta = 0;      ///< the walls' friction coefficient
    double creep_speed = 1e-4;  ///< [m/s]
  } side_walls;
  std::function<Vec(double)> gravity = [](double) { return Vec{0, -9.81, 0}; };
  double max_co = 0.2;         ///< target Courant number (velocity) in cells with material
  double max_alpha_co = 0.2;   ///< target Courant number in interface cells
  double max_air_co = 1.0;     ///< target Courant number in the air (the implicit momentum equation
                               ///< stays stable; the air's speed does not matter for the material)
  double material_alpha = 1e-3;  ///< cells with more material than this count as material
  double dt_initial = 1e-4, dt_max = 1e-2;
  /// The time the run starts at [s] (initialise()): a nest inside another run starts when material
  /// first comes near it, on that run's clock.
  double t_start = 0;
  double c_alpha = 1.0;        ///< interface compression coefficient
  /// The granular phase falls through the air along gravity at this speed [m/s] (a settling flux
  /// w alpha_upper (1 - alpha_lower) across each face with a component along gravity, in the
  /// phase-fraction equation; the mixture's volume flux is unchanged). 0 (default): none. On
  /// terrain meshes it gathers the thin mixed cells of a spreading edge onto the bed
  /// (docs/design/vof.md, "Thin mixed cells fall onto the bed").
  double settling_speed = 0;
  int n_correctors = 3;        ///< PISO correctors per step
  /// Outer correctors per step (PIMPLE's nOuterCorrectors): the viscosity, the momentum matrix, the
  /// momentum predictor and the correctors are repeated with the latest velocity and pressure, the
  /// phase fraction kept. 1 (default) is PISO as interFoam runs it. The correctors alone do not
  /// converge the viscous coupling where the Coulomb viscosity is at its clip (docs/design/vof.md, "The
  /// PISO correctors do not converge the stiff viscous coupling"); with the momentum predictor the
  /// outer correctors do.
  int n_outer_correctors = 1;
  /// Non-orthogonal correctors per pressure corrector (interFoam's nNonOrthogonalCorrectors): the
  /// pressure equation's Laplacian and the buoyancy's snGrad(rho) take the non-orthogonal part of
  /// each face's gradient explicitly, from the cells' Gauss gradients (over-relaxed, Mesh::non_orth),
  /// and the pressure is solved this many more times with the correction from the latest pressure.
  /// 0 (default): orthogonal parts only, exact on the laboratory's orthogonal meshes; terrain meshes
  /// (faces between layers follow the slope over vertical columns) need at least 1.
  int n_non_orthogonal_correctors = 0;
  /// The non-orthogonal correction's limiter psi, as OpenFOAM's "limited corrected psi" snGrad: on
  /// each face the correction of the face force (pressure and buoyancy together) is at most
  /// psi / (1 - psi) times its orthogonal part. 1 (default): unlimited. Across the interface of a
  /// layer on a slope the cells' Gauss gradients mix the material's pressure gradient into the air's
  /// cells, and unlimited corrections there drive the air at 100 m/s (docs/design/vof.md); 0.5 keeps
  /// the correction where the orthogonal part carries a force (the material) and removes it where the
  /// air rests hydrostatically.
  double non_orthogonal_limiter = 1.0;
  /// The whole mesh's mean cell size [m] (the cube root of its mean volume), which sets the
  /// interface normal's guard; 0: the solver's mesh's. A part of a run split over ranks is given the
  /// whole mesh's.
  double mean_cell_size = 0;
  bool momentum_predictor = false;  ///< solve the momentum matrix before the correctors (see docs/design/vof.md)
  /// The pressure equation's coefficient: false: 1/A (PISO, interFoam); true: the consistent
  /// 1/(A - H1) of SIMPLEC (H1 the sum of the neighbour coefficients), so that in cells where the
  /// viscous coupling dominates A the pressure correction moves the velocity as the transient term
  /// alone would (a projection), instead of being amplified by the viscosity (docs/design/vof.md).
  bool consistent = false;
  /// Under the consistent coupling: cells with at least this much material take SIMPLEC's
  /// coefficient and the momentum predictor; the rest (the air) keep PISO's 1/A and their velocity.
  double consistent_alpha = 0.5;
  /// Relative tolerance of the momentum predictor's solve (BiCGStab + ILU; PETSc options with the
  /// prefix runout_u_ override it). 1e-6 gave B2's figures of 1e-10 to the third digit in a tenth
  /// of the iterations.
  double momentum_rtol = 1e-6;
  /// The viscous stress's transpose part div(mu (grad U)^T), explicit in divergence form:
  /// harmonic (default): mu_f the harmonic mean of the two cells (the stress two layers in series
  /// carry); linear: mu_f interpolated linearly, as interFoam has it; off: left out. Where the
  /// Coulomb viscosity jumps between its clip (1e2 m2/s) and flowing cells, the linear face value
  /// lets this explicit term outweigh gravity a hundredfold and drive spurious pressures, and the
  /// deposits it converges to lie 2-3 deg below phi (B2, B9); the harmonic one's lie at phi
  /// (validation.md B2, B9; docs/design/vof.md).
  Transpose viscous_transpose = Transpose::harmonic;
  /// Face values of the momentum's convection term: upwind (first order), or limited_linear:
  /// interFoam's limitedLinearV 1, upwind blended towards linear by a TVD limiter, applied as a
  /// deferred correction (validation.md B2: upwind's numerical viscosity, about u dx / 2, is as
  /// large as the Coulomb viscosity in the thin flowing layers near the surface and the front).
  Convection momentum_convection = Convection::upwind;
  /// total: p, the dissertation's formula (our level is zero at the highest point open to the
  /// atmosphere, so the air above the material adds rho_air g per metre of air the domain holds
  /// above it);
  /// excess: p less rho_air g.(x - x_ref), the air at rest's pressure at the same point, which does
  /// not depend on how much air lies above the material (docs/design/vof.md).
  CoulombPressure coulomb_pressure = CoulombPressure::total;
  /// The viscosity in the viscous term on walls and inflows:
  /// face (default): the granular phase's viscosity evaluated on the face, as OpenFOAM evaluates a
  /// strain-rate-dependent viscosity on a patch: the strain rate from the cell's velocity gradient
  /// with its normal part replaced by the face's (U_b - U_P) / d, the pressure the face's (the
  /// cell's p carried hydrostatically to the face), the phase fraction the face's (the cell's on a
  /// wall, the inflow's on an inflow). A stick wall then carries at most the Coulomb stress
  /// tan(phi) p of the bed wherever the material at it yields (the dissertation's "stick
  /// condition, i.e. bed friction equal to phi"); the Coulomb slip wall keeps the cell's;
  /// cell: the cell's own viscosity. In a layer that slides over the
  /// bed with little shear inside, the cell's strain rate is about half the wall's, and the wall's
  /// shear about twice the Coulomb stress: B2's toe stopped 6 cells short (validation.md).
  WallViscosity wall_viscosity = WallViscosity::face;
  int alpha_subcycles = 2;
  std::string pressure_pc = "gamg";  ///< "gamg", "hypre" (BoomerAMG) or "ilu" (ILU(0))
  double pressure_rtol = 1e-8;  ///< relative tolerance of the last corrector's pressure solve
  double pressure_rtol_intermediate = 0.1;  ///< of the correctors before it (1e-2 gave the same B2 figures, 35 % slower)
  int pressure_pc_refresh = 10;  ///< rebuild the pressure preconditioner every this many steps
  /// The active region: cells with alpha > active_alpha and this many layers of cells around them
  /// (0: every cell). Air beyond it is at rest under the atmosphere's pressure and costs nothing.
  int active_layers = 4;
  double active_alpha = 1e-6;
  std::map<std::string, PatchBc> bc;  ///< by patch name; every patch needs one
  /// The bed friction of a column mesh, on the column's weight (column_friction.hpp); no columns:
  /// none (the bed patch's condition carries any friction). The bed patch then takes a condition
  /// without shear (symmetry), so that the friction is counted once.
  ColumnFrictionConfig column_friction;
};

}  // namespace runout::engine::vof
