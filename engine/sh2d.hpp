#pragma once
// Two-dimensional Savage-Hutter equations on a raster of terrain elevations z = b(x, y).
//
// Conventions (docs/design/depth-averaged.md has the derivation):
// * x, y are horizontal map coordinates [m]; the grid is the DEM's raster.
// * h is the flow depth measured NORMAL to the local surface (the convention of Savage & Hutter);
//   inputs and outputs use h. Inside, the solver carries H = h / cos(theta), the volume per unit
//   HORIZONTAL area (theta the local slope angle), so that the mass equation is exactly
//   conservative on any terrain: dH/dt + div(H U) = 0.
// * The velocity u is tangent to the surface; the solver carries its horizontal projection U (the
//   vertical component is slaved: w = grad(b) . U), and the momentum H U per horizontal area.
//
// With c = cos(theta) = (1 + |grad b|^2)^(-1/2), the curvature term Q = U^T Hess(b) U (centripetal
// acceleration normal to the surface, positive in concave terrain) and the basal normal stress
// N / rho = h c (g + Q)_+ (the centrifugal contribution included, eq. 3.48 generalised), the
// horizontal momentum balance per horizontal area is
//
//   d(H U)/dt + div(H U (x) U + Pi) = -H c^2 (g + Q)_+ grad(b)                      (gravity + normal reaction)
//                                      - [mu H c (g + Q)_+ + g |u|^2 / (xi c)] u_h / |u| (basal friction)
//
// with |u|^2 = |U|^2 + (grad b . U)^2, u_h / |u| the horizontal part of the unit velocity, and the
// depth-averaged pressure (earth pressure K in the downslope direction d and K_y across it)
//
//   Pi = (g H^2 / 2) [ c^4 K_x d d^T + c^2 K_y s s^T ],  s perpendicular to d,
//
// which on an inclined plane reduces exactly to the Savage-Hutter equations in slope coordinates
// (x_s = x / cos(zeta), u_s = U / cos(zeta), h = H cos(zeta)). Coulomb friction uses mu = tan(delta);
// Voellmy friction adds the turbulent term (1/xi = 0 for Coulomb).
//
// Scheme ("noc", the NOC-TVD predictor-corrector of Tai et al. 2002 / Wang et al. 2004 in its
// non-staggered flux form): limited piecewise-linear reconstruction (minmod by default), predictor
// to t + dt/2 with the flux Jacobians applied to the limited slopes plus the source (Wang et al.
// 2004, eq. 4.78 of the dissertation in 2D), corrector with the central local-speed flux of
// Kurganov & Tadmor (2000) at the cell faces from the predicted face values, and the source at the
// half step. Coulomb friction is a bounded impulse that never reverses a velocity; faces between two
// cells that friction holds at rest carry no numerical diffusion, so material at rest stays exactly
// at rest (well-balanced for Coulomb friction). A face-flux limiter (draining-time form) keeps the
// depth non-negative without losing mass.
//
// Work follows the flow: the grid is cut into tiles; only tiles holding material, and their
// neighbours, are computed in a step (CFL <= 0.5 moves material less than one cell per step).
// OpenMP runs over the active tiles; every reduction is done per tile and summed in tile order,
// so results are bitwise identical for any thread count.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/limiters.hpp"
#include "engine/rheology.hpp"
#include "engine/run_control.hpp"
#include "engine/stepping.hpp"

namespace runout::engine {

/// Terrain raster: cell (i, j) has its centre at (x0 + i dx, y0 + j dy), elevation z[j * nx + i].
struct Terrain2D {
  int nx = 0, ny = 0;
  double dx = 1.0, dy = 1.0;
  double x0 = 0.0, y0 = 0.0;
  std::vector<double> z;
  /// Optional: 1 for cells that are not part of the domain (no terrain data, outside the area of
  /// interest). Material that reaches them leaves the domain (free outflow, counted as outflow);
  /// they never hold material. Their z must still be finite (it shapes the neighbours' gradients).
  std::vector<std::uint8_t> outside;
  std::size_t cells() const { return std::size_t(nx) * std::size_t(ny); }
};

enum class Boundary2D { wall, outflow };
inline constexpr NameTable<Boundary2D, 2> kBoundary2DNames{
    {{"wall", Boundary2D::wall}, {"outflow", Boundary2D::outflow}}};

/// Hazard quantities accumulated in the time loop (normal depth, surface speed).
struct HazardMaps {
  std::vector<double> max_depth;     ///< [m], normal to the surface
  std::vector<double> max_speed;     ///< [m/s]
  std::vector<double> max_pressure;  ///< rho |u|^2 [Pa]
  std::vector<double> arrival_time;  ///< [s], NaN where the threshold was never exceeded
  std::vector<double> final_depth;   ///< [m], normal to the surface
};

/// Read-only view of the solver state, handed to a snapshot hook (valid during the call only).
struct Sh2dStateView {
  const std::vector<double>& H;
  const std::vector<double>& HU;
  const std::vector<double>& HV;
};
/// Called with the simulated time and the state: at t = 0, at the end of the first step at or after
/// each multiple of `snapshot_interval`, and at the end of the run. Snapshots do not change the steps.
using SnapshotHook = std::function<void(double t, const Sh2dStateView& state)>;

/// Everything of a run that persists from one step to the next, taken between two steps: a run
/// continued from it (run_sh2d with `from`) computes the same bits as the uninterrupted run.
struct Sh2dCheckpoint {
  int nx = 0, ny = 0, tile = 0;  ///< the grid and tile size it was taken on
  double t = 0;
  long steps = 0;
  /// The state at t (H, momenta) and the velocities the scheme reconstructs from (kept, not
  /// recomputed: U = HU * (1 / H) in the update differs from HU / H in the last bit).
  std::vector<double> H, HU, HV, U, V;
  HazardMaps hazard;  ///< max depth, speed, pressure, arrival time so far (final_depth empty)
  /// Per tile: the sums of the last step that computed the tile (mass, kinetic energy, flowing
  /// speed, CFL rate; a tile that becomes active again starts from its stored rate), the running
  /// outflow, travel and positivity counts, whether it holds material and whether it is active.
  std::vector<double> tile_mass, tile_ke, tile_speed, tile_rate, tile_out, tile_travel;
  std::vector<long> tile_limited;
  std::vector<std::uint8_t> tile_wet, tile_active;
  double volume_initial = 0;       ///< [m^3]
  double kinetic_energy_peak = 0;  ///< the stopping rule's peak [m^5/s^2]
  double cell_updates = 0, active_fraction_sum = 0, max_active_fraction = 0;
  double next_snapshot = 0, last_snapshot = -1;  ///< the time-series schedule
  /// Per secondary release area: when it was released [s], NaN while it waits; and the volume
  /// released so far [m^3].
  std::vector<double> secondary_time;
  double volume_secondary = 0;
  /// With resistance areas: the depth detrained per cell so far (as H) and per tile the volume.
  std::vector<double> detrained, tile_detrained;
  /// With an erodible cover: the cover left per cell (as flow H) and per tile the volume entrained.
  std::vector<double> cover, tile_entrained;
  /// Per flux gauge: the net volume that left its cells to its right and to its left so far [m^3].
  std::vector<double> gauge_right, gauge_left;
};
/// Called with a checkpoint at the end of the first step at or after each multiple of
/// `checkpoint_interval` (steps are never shortened for it) and when the progress hook cancels the
/// run (before the final snapshot of the cancelled run). Valid during the call only.
using CheckpointHook = std::function<void(const Sh2dCheckpoint& cp)>;

/// A secondary release area (AvaFrame's secondary release): snow or debris at rest that is not part
/// of the flow until the flow reaches it. At the end of the first step after which a cell of the
/// area flows (normal depth above Sh2dConfig::flow_threshold), its whole thickness is added, at
/// rest, and moves with the flow from then on.
struct SecondaryRelease {
  std::string name;
  std::vector<std::size_t> cells;  ///< cell indices (i + nx j)
  std::vector<double> depth;       ///< normal depth per cell of `cells` [m], > 0
};

/// Resistance areas (forest, other obstacles on the ground), as AvaFrame's com1DFA models them
/// (its resistance model `default`, AvaFrame 1.13 and later; parameter values there marked as not yet
/// calibrated): a drag per bed area of c rho |u| u, which adds c to Voellmy's g / xi in the implicit
/// drag (engine/rheology.hpp turbulent_factor), and, with detrainment, the drag only where the normal
/// depth and the speed both lie in [depth_min, depth_max] and [speed_min, speed_max], and below either
/// minimum the detrainment of Feistl et al. (2014), dh/dt = -K / (rho |u|) of normal thickness, the
/// detrained material left on the ground with its momentum taken out of the flow. Per cell: c (0
/// outside every area) and K [Pa] (0: none). Only with a constant mu (Coulomb or Voellmy).
struct ResistanceAreas {
  std::vector<double> c;      ///< per cell, [-]; empty: no resistance areas
  std::vector<double> k_det;  ///< per cell [Pa]; empty or 0: no detrainment there
  bool detrainment = true;    ///< false: the drag wherever c > 0, no detrainment
  double speed_min = 6, speed_max = 40;    ///< [m/s] (com1DFA's forestVMin, forestVMax)
  double depth_min = 0.6, depth_max = 10;  ///< normal depth [m] (forestThMin, forestThMax)
  bool empty() const { return c.empty(); }
};

/// An erodible snow cover (entrainment), as AvaFrame's com1DFA models it (its theory page, equations
/// "erosion" and "ploughing"; defaults entEroEnergy = 5000 J/kg, rhoEnt = 100 kg/m^3): where the flow passes over the
/// cover it erodes mass at dm/dt = tau_b |u| / e_b per bed area (basal erosion: tau_b the basal shear
/// stress of the friction law, Coulomb and Voellmy's drag, |u| the speed, e_b the specific erosion
/// energy), or, with `ploughing`, the flow takes up the whole cover of a cell where it first flows
/// there (front entrainment: com1DFA's choice with e_b = 0, here on the grid in one step). The
/// eroded mass joins the flow at rest (the momentum is kept, the speed drops) at the flow's density:
/// a volume of cover q / rho_flow per bed area of q = rho_cover d of mass. Per cell: the cover's normal
/// depth d [m] (0: none) and density [kg/m^3]. Only with a constant mu (Coulomb or Voellmy).
struct ErodibleCover {
  std::vector<double> depth;    ///< normal depth per cell [m]; empty: no cover
  std::vector<double> density;  ///< per cell [kg/m^3] (com1DFA's rhoEnt: 100)
  double erosion_energy = 5000;  ///< e_b [J/kg] (com1DFA's entEroEnergy)
  bool ploughing = false;        ///< true: front entrainment instead of basal erosion
  bool empty() const { return depth.empty(); }
};

/// A flux gauge: a line across the flow (a dam's crest), the cells it passes through, and for each of
/// them which of its faces (west, east, south, north) lead to the line's right (+1) or left (-1),
/// 0 for faces to another cell of the gauge or off the grid. The scheme's own face fluxes (the mass
/// fluxes the update applies, draining factors included) out of the gauge's cells through those faces
/// are summed each step: the volume that left the crest to its right and to its left, exactly as the
/// volume balance moves it.
struct FluxGauge {
  std::string name;
  std::vector<std::size_t> cells;               ///< cell indices (i + nx j), each in one gauge at most
  std::vector<std::array<std::int8_t, 4>> sides;  ///< per cell: W, E, S, N
};

struct Sh2dConfig {
  Material material;
  Limiter limiter = Limiter::minmod;
  TimeControl time;
  Boundary2D west = Boundary2D::outflow, east = Boundary2D::outflow;
  Boundary2D south = Boundary2D::outflow, north = Boundary2D::outflow;
  double gravity = 9.81;
  double dry_depth = 1e-8;          ///< volume per area below which velocity is zero [m]
  double activation_depth = 1e-9;   ///< a tile with any cell deeper than this is active [m]
  /// Normal depth above which a cell counts as flowing [m]: its arrival time, the maximum speed
  /// and pressure maps, and every reported speed (Sh2dDiagnostics::max_speed, Progress::max_speed).
  /// Films thinner than this, which pure Coulomb friction lets slide on at speed, are left out; the
  /// maximum depth, the volumes and the kinetic-energy stopping rule see every cell.
  double flow_threshold = 0.01;
  int tile = 32;                    ///< tile edge in cells
  bool curvature = true;            ///< the centrifugal part of the normal load raises friction
  /// Upper bound of the centripetal term Q = U^T Hess(b) U in units of g. Bends of the DEM sharper
  /// than the flow can follow at the grid scale (a 5 m gully taken at 50 m/s gives Q ~ 25 g) are not
  /// resolved, and integrated explicitly they pump energy into the flow without bound; smooth terrain
  /// stays below it (a 100 m radius at 30 m/s gives 0.9 g).
  double curvature_cap = 1.0;
  bool skip_inactive = true;        ///< false: compute every cell of every tile every step (for comparison)
  /// false: compute the whole of every active tile, also its cells beyond the reach of material
  /// (for comparison: the results are the same bits)
  bool skip_empty = true;
  bool track_travel = false;        ///< accumulate Sh2dDiagnostics::mean_travel (costs a sqrt per cell)
  double snapshot_interval = 0;     ///< [s]; 0: no snapshots
  SnapshotHook snapshot;            ///< optional
  double checkpoint_interval = 0;   ///< [s] of simulated time; 0: checkpoints only when cancelled
  CheckpointHook checkpoint;        ///< optional
  std::vector<SecondaryRelease> secondary;  ///< released when the flow reaches them
  ResistanceAreas resistance;               ///< none by default
  ErodibleCover cover;                      ///< none by default
  /// Dams and walls: per cell the height [m, vertical] a dam stands above the terrain (0: none);
  /// empty: none. The terrain is not raised: the faces between cells of different dam heights are
  /// steps (hydrostatic reconstruction with the run-up of the flow's velocity head; see
  /// docs/design/depth-averaged.md "Dams and walls"), the slopes and curvature stay the ground's.
  std::vector<double> dam_height;
  std::vector<FluxGauge> gauges;            ///< none by default
};

/// Solver state: H = h / cos(theta) and the horizontal momentum H U, H V per horizontal area.
struct Sh2dState {
  std::vector<double> H, HU, HV;
};


struct Sh2dDiagnostics {
  long steps = 0;
  double t = 0;
  StopReason stop = StopReason::end_time;
  double volume_initial = 0, volume_final = 0;  ///< [m^3]
  double volume_secondary = 0;                  ///< added by the secondary releases [m^3]
  std::vector<double> secondary_time;           ///< per secondary release: when released [s], NaN: never
  double volume_outflow = 0;                    ///< left through outflow boundaries [m^3]
  double volume_detrained = 0;                  ///< left behind in resistance areas (ResistanceAreas) [m^3]
  /// Taken up from the erodible cover (ErodibleCover), as flow volume at the flow's density [m^3].
  double volume_entrained = 0;
  double kinetic_energy_peak = 0;               ///< per unit density [m^5/s^2]
  /// Mass-averaged horizontal distance travelled: (1/V0) * integral over time and area of H |U| [m]
  /// (only with Sh2dConfig::track_travel).
  double mean_travel = 0;
  /// Over the whole run, of cells deeper than Sh2dConfig::flow_threshold: the maximum of
  /// HazardMaps::max_speed [m/s]. (Films thinner than the threshold are left out, as in the maps.)
  double max_speed = 0;
  long positivity_limited = 0;                  ///< cell-steps whose outflow had to be limited
  double cell_updates = 0;                      ///< cells computed, summed over steps
  double mean_active_fraction = 0, max_active_fraction = 0;
  double wall_seconds = 0;  ///< whole run, set-up included
  double loop_seconds = 0;  ///< time loop only
  /// Relative volume error: |final + outflow + detrained - initial - secondary - entrained| /
  /// (initial + secondary + entrained).
  double volume_error() const {
    const double in = volume_initial + volume_secondary + volume_entrained;
    return in > 0 ? std::abs(volume_final + volume_outflow + volume_detrained - in) / in : 0.0;
  }
};

struct Sh2dResult {
  Sh2dState state;
  HazardMaps hazard;
  Sh2dDiagnostics diag;
  /// Normal thickness left behind per cell by detrainment in resistance areas [m] (empty without).
  std::vector<double> detrained;
  /// The erodible cover left per cell, as its own normal depth [m] (empty without a cover).
  std::vector<double> cover;
  /// Per flux gauge (Sh2dConfig::gauges): the net volume that left its cells to its right and to its
  /// left [m^3] (negative: more came in from that side).
  std::vector<double> gauge_right, gauge_left;
};

/// Surface geometry derived from the terrain once per run (exposed for tests and output conversion).
struct SurfaceGeometry {
  std::vector<double> bx, by;         ///< grad b
  std::vector<double> hxx, hxy, hyy;  ///< Hess b
  std::vector<double> c;              ///< cos(theta)
  static SurfaceGeometry from(const Terrain2D& t);
};

/// State at rest from a normal depth field h (per cell).
Sh2dState state_from_normal_depth(const Terrain2D& terrain, const std::vector<double>& h);
/// Normal depth h = H cos(theta) per cell.
std::vector<double> normal_depth(const Terrain2D& terrain, const Sh2dState& s);

namespace sh2d_detail {
class Solver;
}

/// The 2D solver as the run loop (engine/stepping.hpp) drives it. It keeps references to the
/// terrain and the configuration: both must outlive it. The constructors throw
/// std::invalid_argument naming the problem on inconsistent input; a step throws std::runtime_error
/// when the state becomes non-finite (NaN or infinite depth or momentum).
class Sh2dEngine final : public SteppingEngine {
 public:
  Sh2dEngine(const Terrain2D& terrain, const Sh2dConfig& config, Sh2dState initial);
  /// Continues a run from a checkpoint taken by the same terrain and configuration (the end time and
  /// the intervals may differ).
  Sh2dEngine(const Terrain2D& terrain, const Sh2dConfig& config, const Sh2dCheckpoint& from);
  ~Sh2dEngine() override;
  double time() const override;
  long steps() const override;
  StepReport step(double t_end) override;
  double kinetic_energy() const override;
  /// The state now (valid until the next step).
  Sh2dStateView state() const;
  /// Per flux gauge (Sh2dConfig::gauges): the net volume that left its cells to its right and to its
  /// left so far [m^3] (valid until the next step).
  const std::vector<double>& gauge_right() const;
  const std::vector<double>& gauge_left() const;
  /// The whole state between two steps, with the loop's running figures: a run continued from it
  /// computes the same bits as the uninterrupted run.
  Sh2dCheckpoint checkpoint(const LoopState& loop) const;
  /// The loop's running figures a checkpoint carries.
  static LoopState loop_state(const Sh2dCheckpoint& cp);
  /// The run's diagnostics and results, moved out of the engine: once, after the loop.
  Sh2dResult finish(StopReason stop, const LoopState& loop);

 private:
  std::unique_ptr<sh2d_detail::Solver> s_;
};

/// The loop's schedule of a configuration: its end time, stop rule and step limit, its snapshots (as
/// frames, the final state included) and checkpoints, its progress cadence.
LoopSchedule loop_schedule(const Sh2dConfig& config);

/// Run the 2D solver through the run loop with the configuration's hooks. Throws std::invalid_argument naming the problem on inconsistent input, and
/// std::runtime_error when the state becomes non-finite (NaN or infinite depth or momentum).
Sh2dResult run_sh2d(const Terrain2D& terrain, const Sh2dConfig& config, Sh2dState initial);
/// Continue a run from a checkpoint taken by the same terrain and configuration (the end time, the
/// checkpoint hook and interval may differ). Throws std::invalid_argument when it does not fit.
Sh2dResult run_sh2d(const Terrain2D& terrain, const Sh2dConfig& config, const Sh2dCheckpoint& from);

}  // namespace runout::engine
