#pragma once
// The run driver: terrain -> engine -> outputs (rasters, outline, map, run record) for one resolved
// scenario, writing into a directory.
// The command line's `runout run` and (later) the service's workers call the same code.
#include <cmath>
#include <string>
#include <vector>

#include <optional>

#include "engine/run_control.hpp"
#include "engine/sh2d.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::jobs {

namespace nest {
class NestBoundary;
}

/// The 3D part of a nested run (jobs/drivers/nest/run.hpp): what it reads, and what it hands back
/// to the depth-averaged run at its end.
struct NestLink {
  const nest::NestBoundary* boundary = nullptr;  ///< the depth-averaged run's record of the nest's boundary
  double start_time = 0;                         ///< when the 3D run starts [s, the depth-averaged run's clock]
  engine::HazardMaps maps;                       ///< the 3D run's maps on the grid (only the nest's cells hold values)
  double inflow_m3 = 0;        ///< the volume the 3D run took in through the nest's boundary
  double volume_error = 0;     ///< the 3D run's own balance
  long mesh_cells = 0;
  double column_width_m = 0, first_layer_m = 0, band_height_m = 0;
  double continued_from = NAN;  ///< the 3D run's checkpoint time when it continued from one
};

struct RunOptions {
  engine::ProgressHook progress;  ///< optional; returning false cancels the run
  long progress_every = 50;
  /// ISeeSnow benchmark export (validation.md A8) when not empty: the simulation id (e.g.
  /// "03CoulombOnly"). Writes <release>_<id>_null_runout_pft.asc / _pfv.asc on the DEM's grid and
  /// iseesnow_<id>.csv.
  std::string iseesnow_id;
  /// Write checkpoints to this file (replaced each time, atomically) every checkpoint interval of
  /// simulated time and when the run is cancelled; empty: none. Both engines: VOF runs
  /// (jobs/checkpoint.hpp, the frames so far in FILE.fields.h5) and depth-averaged runs
  /// (jobs/sh_checkpoint.hpp, the time series so far in FILE.timeseries.h5).
  std::string checkpoint_path;
  /// Continue from this checkpoint instead of the initial state. VOF runs: same scenario but the end
  /// time and the write and checkpoint intervals may differ. Depth-averaged runs: the same scenario
  /// (jobs::scenario_hash); the continued run's outputs are the uninterrupted run's, bit for bit.
  std::string restart_path;
  /// The interval of simulated time between checkpoints [s] for depth-averaged runs, and for VOF
  /// runs whose scenario sets no lab.checkpoint_interval_s (0: checkpoints only when the run is
  /// interrupted).
  double checkpoint_interval_s = 0;
  /// Depth-averaged runs: the terrain cache's folder (the prepared grid of a DEM, area and grid,
  /// shared by the runs that use them, e.g. an ensemble's members); empty: the grid is prepared.
  std::string terrain_cache_dir;
  /// The 3D run of a nest (ResolvedScenario::nest_part): the link to the depth-averaged run around it.
  NestLink* nest = nullptr;
};

/// A dam of the scenario (dams[]) and what passed it (run.json's dams[]).
struct DamSummary {
  std::string name;
  bool lines = false;  ///< crest lines (else footprints)
  long cells = 0;
  double height_max_m = 0, crest_length_m = 0;
  double crossed_right_m3 = 0, crossed_left_m3 = 0, overflow_m3 = 0;  ///< crest lines
  double max_depth_m = 0;  ///< on the dam's cells (above its crest)
};

/// A structure (scenario structures[]) and the flow's load on it (proto StructureResult).
struct StructureSummary {
  std::string name;
  long cells = 0;
  double height_max_m = 0;
  double max_depth_next_m = 0, max_pressure_next_kpa = 0;
  bool loads = false;  ///< 3D: the force figures below are set
  double peak_force_kn = 0, peak_force_time_s = 0, peak_force_east_kn = 0, peak_force_north_kn = 0, peak_force_up_kn = 0;
  double impulse_kn_s = 0, max_pressure_kpa = 0, max_pressure_time_s = 0, max_pressure_height_m = 0, wall_area_m2 = 0;
  std::vector<double> front_height_m, front_alpha, front_speed_m_s;
  double x = 0, y = 0;  ///< its cells' centroid in the grid's CRS
  bool loads_resolved = false;  ///< 3D: the impact is resolved (StructureLoads::summarise's rule)
  std::string loads_note;       ///< 3D: why the loads are (not) design values
  double column_width_m = 0;    ///< 3D: the mesh's column width
};

/// The 3D nest of a depth-averaged run (proto NestResult).
struct NestSummary {
  int cells = 0, boundary_faces = 0;
  long mesh_cells = 0, recorded_steps = 0;
  double column_width_m = 0, first_layer_m = 0, band_height_m = 0;
  double inflow_depth_averaged_m3 = 0, inflow_3d_m3 = 0, volume_error_3d = 0, seconds_3d = 0, start_time_s = 0;
  std::vector<StructureSummary> structures;  ///< the 3D run's: the structures' loads
  bool cancelled = false;       ///< the 3D run was stopped by the progress hook: the nested run writes no results
  double continued_from = NAN;  ///< the 3D run continued from a checkpoint at this time [s]; NaN: from its start
};

struct RunSummary {
  int nx = 0, ny = 0;
  double dx = 0;
  std::string crs;
  double release_area_m2 = 0, release_volume_m3 = 0;
  double affected_area_m2 = 0, runout_m = 0, max_speed = 0, max_depth = 0;
  /// The runout point's distance along the path (the figure the profile and the maps show); NaN
  /// without a path or without a runout point; with the path analysis's criterion.
  double path_runout_m = NAN;
  std::string path_criterion;
  double volume_initial = 0, volume_final = 0, volume_outflow = 0, volume_error = 0;
  double volume_detrained = 0;  ///< depth-averaged: left behind in resistance areas
  double volume_entrained = 0;  ///< depth-averaged: taken up from the erodible cover (flow volume)
  double t = 0;
  long steps = 0;
  std::string stop;
  double seconds_prepare = 0, seconds_run = 0, seconds_write = 0;
  double cpu_seconds = 0;  ///< processor time of the solve (all threads)
  std::vector<std::string> files;  ///< written, relative to the output directory
  std::optional<NestSummary> nest;  ///< depth-averaged with a nest
  std::vector<std::string> notes;
  std::vector<DamSummary> dams;  ///< depth-averaged: per dam
  std::vector<StructureSummary> structures;  ///< per structure (scenario structures[])
};

/// The run's runout in words, one figure wherever it is printed: "runout 3075 m along the path (max
/// pressure >= 1 kPa inside the outline)" where the path analysis found a runout point, else the
/// farthest outlined cell's distance from the release's centroid.
std::string runout_phrase(const RunSummary& sum);

/// Run a scenario and write every output into `out_dir` (which must exist). Throws ScenarioError or
/// terrain::TerrainError for bad input; returns the summary also written to run.json.
RunSummary run_scenario(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt = {});

}  // namespace runout::jobs
