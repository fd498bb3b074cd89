#pragma once
// Scenario files: JSON read through protobuf's JSON mapping into runout.v1.Scenario, then resolved
// (defaults, paths relative to the file, names to enums) and validated before anything runs. Every
// error names the field and the problem.
#include <stdexcept>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "engine/sh2d.hpp"
#include "runout/v1/scenario.pb.h"
#include "terrain/terrain.hpp"

namespace runout::engine::vof {
struct VofConfig;
}

namespace runout::jobs {

struct ScenarioError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A pressure hazard zone (outputs.pressure_zones_kpa): the cells whose maximum pressure is at least
/// from_kpa and below the next zone's.
struct ZoneThreshold {
  std::string name;
  double from_kpa = 0;
};

/// The path (thalweg) analysis (scenario `path`); every run on a DEM makes it.
struct PathSettings {
  std::string line_path, crs;  ///< the line; empty: steepest descent from the release's centroid
  std::string field = "ppr";   ///< ppr (max pressure, kPa), pft (max depth, m), pfv (max speed, m/s)
  double threshold = 1, width_m = 600, beta_deg = 10;
};

/// The engine registry's rows (jobs/drivers/engines.cpp) a scenario resolves to.
inline constexpr std::string_view kDepthAveragedEngine = "depth-averaged";
inline constexpr std::string_view kVofLabEngine = "vof-lab";
inline constexpr std::string_view kVofTerrainEngine = "vof-terrain";

/// A resistance area (scenario `resistance.areas[]`), resolved: its polygons, their CRS, its drag
/// coefficient and detrainment K (the engine's ResistanceAreas per cell once rasterised).
struct ResistanceAreaSettings {
  std::string path, crs;
  double c = 0.01, k_det = 5;
};

/// An area of erodible cover (scenario `entrainment.areas[]`), resolved: its thickness read with the
/// releases' rules (`release.kind` names the field in messages) and its density.
struct CoverAreaSettings {
  terrain::ReleaseRequest release;
  double density = 100;  ///< [kg/m^3]
};

/// A dam (scenario `dams[]`), resolved: its name and how its file is read.
struct DamSettings {
  std::string name;
  terrain::DamRequest request;
};

struct ResolvedScenario {
  v1::Scenario scenario;  ///< as given, with the defaults filled in
  std::string source;     ///< the file it came from (empty when given as a message)
  terrain::DemRequest dem;
  std::vector<terrain::ReleaseRequest> releases;
  engine::Sh2dConfig config;  ///< material, numerics, boundaries (progress hook left empty)
  std::vector<std::string> rasters;
  double outline_threshold = 0.1;
  double timeseries_interval = 0;  ///< [s]; 0: no time series
  std::vector<ZoneThreshold> pressure_zones = {{"blue", 3}, {"red", 30}};
  std::string observed_outline, observed_crs;  ///< observations: polygons of the observed runout, their CRS
  PathSettings path;
  std::vector<ResistanceAreaSettings> resistance;  ///< none: no resistance areas
  std::vector<CoverAreaSettings> cover;            ///< entrainment.areas[]; none: no erodible cover
  std::vector<DamSettings> dams;                   ///< dams[]; none: no dams
  std::vector<DamSettings> structures;             ///< structures[] (footprints); none: no structures
  std::string corridor_path;  ///< mesh.corridor_path (3D engine on the DEM), resolved; empty: none
  /// Depth-averaged with a `nest`: the nest's 3D run, resolved (engine "vof" on the DEM, its mesh's
  /// corridor the nest's polygons, its refinement and layers the nest's); null: no nest.
  std::shared_ptr<const ResolvedScenario> nest;
  /// The 3D part of a nested run: the corridor (the nest) may leave release cells out (they are the
  /// depth-averaged run's), and its boundary takes the depth-averaged run's flux.
  bool nest_part = false;
  bool maps = true;  ///< outputs.maps: the report maps (PNG, PDF)
  std::string report;  ///< outputs.report: "a4" or "a3", the run's report.pdf; "": none
  std::vector<std::string> input_files;  ///< for hashing
  /// The engine registry's row that runs it (jobs/drivers/engines.cpp): kDepthAveragedEngine;
  /// kVofLabEngine, engine "vof" with a laboratory set-up (`lab`); kVofTerrainEngine, engine "vof"
  /// on the DEM and releases (blocks `mesh` and `vof`; config holds the material, end time and stop
  /// rule as for the depth-averaged engine).
  std::string engine = std::string(kDepthAveragedEngine);
  /// The 3D engine runs it (either set-up).
  bool three_d() const { return engine != kDepthAveragedEngine; }
  /// The simulated time the run goes to at most [s].
  double end_time_s() const { return engine == kVofLabEngine ? scenario.lab().end_time_s() : config.time.t_end; }
};

/// The version of what a VOF run's results contain (run.json, the fields) for an unchanged scenario.
/// Bump it when they change meaning or value, so that a service does not answer from results of the
/// older kind (2: B6's shock is the bore, no longer the resting deposit's edge; 3: 3D runs add
/// comparison.png, and a polygon obstacle's shadow window starts behind the polygon; 4: the viscous
/// stress's transpose part takes the harmonic face viscosity by default; 5: walls and inflows take the
/// granular viscosity evaluated on the face, lab.wall_viscosity "face"; 6: runs on the DEM write
/// max_pressure.tif in kPa, the pressure zones, maps, QGIS styles and the path analysis; 7: lab
/// mu(I) takes the material's parameters, the rotating box reports its flowing layer and draws its
/// angles in comparison.png; 8: runs on the DEM take the column's weight as the bed friction's
/// load and let the material of partly filled cells settle onto the bed, by default). Adding a
/// file or a figure counts too: a cached result lacks it. The test
/// Scenarios.VofResultsMatchTheFingerprintOfTheirVersion holds this version's figures for thirteen
/// short runs and fails when a change to the numerics moves them (options those runs do not take
/// are not covered); Scenarios.VofHashCarriesTheResultsVersion pins a hash that a bump changes.
inline constexpr int kVofResultsVersion = 8;

/// The version of what a depth-averaged run's results contain (rasters, outline, run.json, time
/// series) for an unchanged scenario; the same rule as kVofResultsVersion (1: run.json's and the
/// summary's maximum speed is the maximum of max_speed.tif, the flowing cells'; 2: max_pressure.tif in
/// kPa, the pressure zones, maps, QGIS styles, the path analysis, the time series as GeoTIFF). The test
/// Scenarios.HashCarriesEachEnginesResultsVersion pins a hash that a bump changes.
inline constexpr int kDepthAveragedResultsVersion = 2;

/// A number for messages and run records: 10 significant digits, null when not finite.
std::string json_number(double v);

/// SHA-256 of a resolved scenario: its message with the input paths and the job limits left out,
/// the content of every input file, and the version of what its engine's results contain. Two
/// scenarios with the same hash compute the same result. The versions are parameters for tests.
std::string scenario_hash(const ResolvedScenario& r, int depth_averaged_version = kDepthAveragedResultsVersion,
                          int vof_version = kVofResultsVersion);

/// The raster names an output list may hold.
/// A hazard raster of both engines on the DEM: its name in `outputs.rasters`, the description and unit
/// in its band metadata, the engine's map it holds and the factor from the engine's unit to the
/// raster's (pressure: Pa to kPa, as AvaFrame and RAMMS report it). A new raster is one line in
/// hazard_rasters().
struct HazardRaster {
  std::string name;
  std::string description;
  std::string unit;
  std::vector<double> engine::HazardMaps::*map;
  double scale = 1;
};
/// Every hazard raster, in the order of the outputs' default.
const std::vector<HazardRaster>& hazard_rasters();
/// The names of hazard_rasters().
const std::vector<std::string>& raster_names();

/// Parse a scenario from JSON text. Throws ScenarioError.
v1::Scenario parse_scenario_json(const std::string& json);
/// Read, parse, resolve and validate a scenario file. Throws ScenarioError.
ResolvedScenario load_scenario(const std::string& path);
/// Resolve and validate a message; relative paths are taken from `base_dir`. Throws ScenarioError.
ResolvedScenario resolve_scenario(v1::Scenario s, const std::string& base_dir);

/// A laboratory nest's face: lab.nest.x_min moved to the nearest face of the lab's cells, and the
/// lab's cells from it to x_max (what the 3D run takes).
struct LabNestFace {
  double x = 0;
  int cells = 0;
};
LabNestFace lab_nest_face(const v1::Lab& lab);

/// The laboratory block's granular rheology into the engine's configuration: lab.rheology, the
/// granular viscosity models' parameters (by their rows, engine/vof/models/registry.hpp; those not
/// set are the lab material's, lab_model_defaults) and the side walls' friction of a plane set-up.
void apply_lab_rheology(const v1::Lab& lab, engine::vof::VofConfig& c);
/// The material block into the 3D engine's configuration on the DEM: its density, the granular
/// viscosity model of material.rheology's name and the parameters the material gives (by the
/// models' rows: internal_friction_deg, mu(I)'s fields).
void apply_material_rheology(const v1::Material& m, engine::vof::VofConfig& c);

}  // namespace runout::jobs
