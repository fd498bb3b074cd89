// The option tables of every scenario and of the depth-averaged engine (options.hpp).
#include <cmath>
#include <string>
#include <vector>

#include "engine/limiters.hpp"
#include "engine/rheology.hpp"
#include "engine/sh2d.hpp"
#include "jobs/scenario/options.hpp"
#include "jobs/scenario/scenario.hpp"
#include "jobs/scenario/scenario_impl.hpp"

namespace runout::jobs {

namespace {

using T = OptionType;
using U = Unset;
using S = v1::Scenario;
using R = ResolvedScenario;

template <class E, std::size_t N>
std::vector<std::string> names(const engine::NameTable<E, N>& t) {
  std::vector<std::string> out;
  for (const auto& [n, e] : t) out.emplace_back(n);
  return out;
}
template <class E, std::size_t N>
E value(const engine::NameTable<E, N>& t, const std::string& name) {
  return engine::parse_name(t, "value", name);  // the table has checked the name
}

std::vector<std::string> friction_law_names() {
  std::vector<std::string> out;
  for (const auto* law : engine::kFrictionLaws) out.emplace_back(law->name);
  return out;
}

// Bounds (the README's "Valid ranges").
constexpr double kMaxCell = 1e4;            // grid.resolution_m [m]
constexpr double kMaxThickness = 500;       // a release [m]: rock avalanches start some hundred metres thick
constexpr double kMaxDensity = 1e4;         // [kg/m3]: above any rock or ore
constexpr double kMaxXi = 1e5;              // Voellmy xi [m/s2]
constexpr double kMaxFlowRule = 10;         // pf_beta, pf_gamma, mu_i0 [-]: published values lie below 1
constexpr double kMaxLength = 100;          // pf_length_m, grain_diameter_m [m]: boulders, h_stop of rock avalanches
constexpr double kMaxEndTime = 1e5;         // numerics.end_time_s, outputs.timeseries_interval_s [s]
constexpr double kMaxDepthThreshold = 100;  // outline and flow thresholds [m]
constexpr double kMaxZonePressure = 1e5;    // outputs.pressure_zones_kpa[].from_kpa [kPa]: 100 MPa
constexpr int kMaxZones = 16;
constexpr double kMaxRanks = 65536;         // ranks: a large cluster's partition (a server sets its own bound)

// outputs.pressure_zones_kpa: named, ascending and distinct; none: the Swiss practice (blue from 3
// kPa, red from 30 kPa).
void pressure_zones(const S& s, R& r) {
  const auto& z = s.outputs().pressure_zones_kpa();
  r.pressure_zones.clear();
  if (z.empty()) {
    r.pressure_zones = {{"blue", 3}, {"red", 30}};
    return;
  }
  if (z.size() > kMaxZones) bad("outputs.pressure_zones_kpa", "at most " + std::to_string(kMaxZones) + " zones, got " + std::to_string(z.size()));
  for (int k = 0; k < z.size(); ++k) {
    const std::string at = "outputs.pressure_zones_kpa[" + std::to_string(k) + "]";
    if (z[k].name().empty()) bad(at + ".name", "missing (each zone needs a name, e.g. \"red\")");
    if (!(z[k].from_kpa() > 0)) bad(at + ".from_kpa", "missing (the zone's lowest pressure in kPa, > 0)");
    for (int q = 0; q < k; ++q)
      if (z[q].name() == z[k].name()) bad(at + ".name", "'" + z[k].name() + "' names zone " + std::to_string(q) + " too");
    if (k > 0 && !(z[k].from_kpa() > z[k - 1].from_kpa()))
      bad(at + ".from_kpa", "the zones must ascend: " + json_number(z[k].from_kpa()) + " kPa is not above zone " + std::to_string(k - 1) +
                                "'s " + json_number(z[k - 1].from_kpa()) + " kPa");
    r.pressure_zones.push_back({z[k].name(), z[k].from_kpa()});
  }
}

}  // namespace

const OptionTable& scenario_options() {
  static const OptionTable t = {
      {"name", T::text, U::as_given, "", {}, {}, "", "free text, copied to the run record", "run record"},
      {"engine", T::choice, U::fill, "depth-averaged", {}, {"depth-averaged", "vof"}, "",
       "the engine: depth-averaged (Savage-Hutter, on a DEM) or vof (3D: on the DEM, or the laboratory set-up of `lab`)", "ResolvedScenario::engine",
       "", [](const S& s, R& r) { r.engine = s.engine() == "vof" ? kVofTerrainEngine : kDepthAveragedEngine; }},
      {"limits.max_wall_s", T::number, U::as_given, "", {}, {}, "s",
       "the service's wall-time limit of one attempt (checked by the server); not part of the hash", "the service's job", "the server's"},
      {"limits.max_memory_bytes", T::integer, U::as_given, "", {}, {}, "bytes",
       "the service's memory limit of the job's process; not part of the hash", "the service's job", "the server's"},
      {"ranks", T::integer, U::as_given, "", Range{0, kMaxRanks}, {}, "",
       "the MPI ranks of the job's 3D run (the local worker pool: mpirun; Slurm: one job of this many tasks); not part of the hash",
       "the service's job", "one process"},
  };
  return t;
}

namespace {

// The outputs and the analyses of a run on the DEM (both engines): rasters, thresholds, time series,
// pressure zones, path, observations, points of interest.
OptionTable output_options() {
  return {
      {"outputs.rasters", T::choice_list, U::fill, "all", {}, raster_names(), "", "the rasters to write",
       "ResolvedScenario::rasters", "", [](const S& s, R& r) { r.rasters.assign(s.outputs().rasters().begin(), s.outputs().rasters().end()); }},
      {"outputs.outline_threshold_m", T::number, U::fill, "0.1", Range{0, kMaxDepthThreshold, true}, {}, "m",
       "the depth that outlines the runout", "ResolvedScenario::outline_threshold", "",
       [](const S& s, R& r) { r.outline_threshold = s.outputs().outline_threshold_m(); }},
      {"outputs.flow_threshold_m", T::number, U::fill, "0.01", Range{0, kMaxDepthThreshold, true}, {}, "m",
       "the depth that counts as flowing (arrival time, speed and pressure maps)", "Sh2dConfig::flow_threshold", "",
       [](const S& s, R& r) { r.config.flow_threshold = s.outputs().flow_threshold_m(); }},
      {"outputs.timeseries_interval_s", T::number, U::as_given, "", Range{0, kMaxEndTime}, {}, "s",
       "HDF5 + XDMF frames of depth and speed this often", "ResolvedScenario::timeseries_interval", "none",
       [](const S& s, R& r) { r.timeseries_interval = s.outputs().timeseries_interval_s(); }},
      {"outputs.pressure_zones_kpa[].name", T::text, U::as_given, "", {}, {}, "",
       "a pressure zone's name; a colour name (yellow, blue, red, ...) colours it. No zones given: blue from 3 kPa, red from 30 kPa",
       "ResolvedScenario::pressure_zones"},
      {"outputs.pressure_zones_kpa[].from_kpa", T::number, U::as_given, "", Range{0, kMaxZonePressure, true}, {}, "kPa",
       "the zone's lowest maximum pressure (the zone ends at the next one's); ascending", "ResolvedScenario::pressure_zones", "",
       pressure_zones},
      {"observations.outline_path", T::path, U::as_given, "", {}, {}, "",
       "polygons of the observed runout (any vector file, any CRS): the run is scored against them (run.json, map_observation)",
       "ResolvedScenario::observed_outline"},
      {"observations.crs", T::text, U::as_given, "", {}, {}, "", "the observed polygons' CRS when the file has none",
       "ResolvedScenario::observed_crs", "", [](const S& s, R& r) { r.observed_crs = s.observations().crs(); }},
      {"path.line_path", T::path, U::as_given, "", {}, {}, "",
       "the avalanche path from the top down (any vector file, any CRS; its first line); default: steepest descent from the release's centroid",
       "ResolvedScenario::path"},
      {"path.crs", T::text, U::as_given, "", {}, {}, "", "the path line's CRS when the file has none", "ResolvedScenario::path", "",
       [](const S& s, R& r) { r.path.crs = s.path().crs(); }},
      {"path.runout_field", T::choice, U::keep, "ppr", {}, {"ppr", "pft", "pfv"}, "",
       "what marks the runout along the path: max pressure (ppr, kPa), max depth (pft, m) or max speed (pfv, m/s)", "ResolvedScenario::path",
       "", [](const S& s, R& r) { r.path.field = s.path().runout_field().empty() ? "ppr" : s.path().runout_field(); }},
      {"path.runout_threshold", T::number, U::keep, "1", Range{0, 1e5, true}, {}, "field's unit",
       "the runout is the last cross-section where the field reaches this (AIMEC's 1 kPa)", "ResolvedScenario::path", "",
       [](const S& s, R& r) { r.path.threshold = s.path().has_runout_threshold() ? s.path().runout_threshold() : 1.0; }},
      {"path.domain_width_m", T::number, U::keep, "600", Range{0, 1e5, true}, {}, "m", "the cross-sections' width (AIMEC's 600 m)",
       "ResolvedScenario::path", "", [](const S& s, R& r) { r.path.width_m = s.path().has_domain_width_m() ? s.path().domain_width_m() : 600.0; }},
      {"path.beta_deg", T::number, U::keep, "10", Range{0, 90, true, true}, {}, "deg",
       "the beta point: where the path's slope first falls below this", "ResolvedScenario::path", "",
       [](const S& s, R& r) { r.path.beta_deg = s.path().has_beta_deg() ? s.path().beta_deg() : 10.0; }},
      {"outputs.maps", T::flag, U::keep, "true", {}, {}, "",
       "the report maps (map_*.png and .pdf); false: rasters, vectors and run.json only (ensemble members)", "ResolvedScenario::maps", "",
       [](const S& s, R& r) { r.maps = !s.outputs().has_maps() || s.outputs().maps(); }},
      {"outputs.report", T::choice, U::keep, "", {}, {"a4", "a3"}, "",
       "the run's report.pdf on this paper (landscape; as `runout report` writes it); unset: none", "ResolvedScenario::report", "",
       [](const S& s, R& r) { r.report = s.outputs().report(); }},
      {"outputs.points_of_interest[].name", T::text, U::required, "", {}, {}, "",
       "a named point (a farmhouse): drawn on the maps, its maxima and zone in run.json", "run record, maps"},
      {"outputs.points_of_interest[].x", T::number, U::as_given, "", Range{}, {}, "", "easting, or longitude in a geographic CRS",
       "run record, maps"},
      {"outputs.points_of_interest[].y", T::number, U::as_given, "", Range{}, {}, "", "northing, or latitude", "run record, maps"},
      {"outputs.points_of_interest[].crs", T::text, U::as_given, "", {}, {}, "", "the point's CRS (\"EPSG:4326\"); default the grid's",
       "run record, maps"},
  };
}

// What is built on the ground and where 3D runs: dams and walls, structures, a 3D nest.
OptionTable works_options() {
  return {
      {"dams[].name", T::text, U::as_given, "", {}, {}, "", "the dam's name in run.json and on the maps; default \"dam N\"",
       "ResolvedScenario::dams"},
      {"dams[].path", T::path, U::required, "", {}, {}, "",
       "crest lines or footprints (polygons) in any CRS: a step of the height on the cells they touch",
       "ResolvedScenario::dams"},
      {"dams[].crs", T::text, U::as_given, "", {}, {}, "", "the file's CRS when it has none", "ResolvedScenario::dams"},
      {"dams[].height_m", T::number, U::as_given, "", Range{0, 100, true}, {}, "m", "the dam's height above the ground (or height_attribute)",
       "DamRequest::height"},
      {"dams[].height_attribute", T::text, U::as_given, "", {}, {}, "", "the attribute that holds each feature's height",
       "DamRequest::height_attribute"},
      {"nest.path", T::path, U::as_given, "", {}, {}, "",
       "a 3D nest: polygons (any CRS); the grid cells whose centres lie inside are run by the 3D engine with the "
       "depth-averaged flux through their boundary, and their hazard rasters are the 3D run's",
       "ResolvedScenario::nest"},
      {"nest.crs", T::text, U::as_given, "", {}, {}, "", "the nest polygons' CRS when the file has none", "ResolvedScenario::nest"},
      {"nest.refinement", T::integer, U::keep, "4", Range{1, 8}, {}, "",
       "the nest's mesh columns per grid cell along each axis (columns of the grid's cell over this)", "ResolvedScenario::nest"},
      {"nest.first_layer_m", T::number, U::as_given, "", Range{0, 100, true}, {}, "m",
       "the nest mesh's ground layer; default a fifth of the deepest flow through the nest", "ResolvedScenario::nest"},
      {"nest.band_height_m", T::number, U::as_given, "", Range{0, 1000, true}, {}, "m",
       "the nest mesh's height above the ground; default eight times the deepest flow through the nest", "ResolvedScenario::nest"},
      {"structures[].name", T::text, U::as_given, "", {}, {}, "", "the structure's name in run.json, the loads' files and on the maps; default \"structure N\"",
       "ResolvedScenario::structures"},
      {"structures[].path", T::path, U::as_given, "", {}, {}, "",
       "footprints (polygons) in any CRS: a wall of the height on the cells they touch (depth-averaged), an obstacle with its own walls (3D); "
       "required but with surface_path",
       "ResolvedScenario::structures"},
      {"structures[].crs", T::text, U::as_given, "", {}, {}, "", "the file's CRS when it has none", "ResolvedScenario::structures"},
      {"structures[].height_m", T::number, U::as_given, "", Range{0, 100, true}, {}, "m",
       "the structure's height above the ground (or height_attribute, or top_attribute)", "DamRequest::height"},
      {"structures[].height_attribute", T::text, U::as_given, "", {}, {}, "", "the attribute that holds each feature's height [m]",
       "DamRequest::height_attribute"},
      {"structures[].top_attribute", T::text, U::as_given, "", {}, {}, "",
       "the attribute that holds each feature's top elevation [m]; its height is the top less each cell's ground", "DamRequest::top_attribute"},
      {"structures[].surface_path", T::path, U::as_given, "", {}, {}, "",
       "a surface model (DSM, raster in any CRS): the top at each cell's centre; with path inside the footprints, without it the cells "
       "where it stands min_height_m above the ground",
       "DamRequest::surface_path"},
      {"structures[].min_height_m", T::number, U::as_given, "", Range{0, 100, true}, {}, "m",
       "with surface_path: the least height of the surface over the ground that counts as the structure; default 2",
       "DamRequest::min_height"},
  };
}

// What lies on the ground: resistance areas (forest) and the erodible cover (entrainment).
OptionTable ground_options() {
  return {
      {"resistance.areas[].path", T::path, U::required, "", {}, {}, "",
       "polygons of a resistance area (forest) in any CRS: the cells whose centres lie inside", "ResolvedScenario::resistance"},
      {"resistance.areas[].crs", T::text, U::as_given, "", {}, {}, "", "the polygons' CRS when the file has none",
       "ResolvedScenario::resistance"},
      {"resistance.areas[].drag_coefficient", T::number, U::as_given, "", Range{0, 10}, {}, "",
       "this area's drag coefficient c (drag c rho |u| u per bed area); default resistance.drag_coefficient",
       "ResistanceAreas::c"},
      {"resistance.areas[].detrainment_k_pa", T::number, U::as_given, "", Range{0, 1e4}, {}, "Pa",
       "this area's detrainment K; default resistance.detrainment_k_pa", "ResistanceAreas::k_det"},
      {"resistance.drag_coefficient", T::number, U::keep, "0.01", Range{0, 10}, {}, "",
       "the drag coefficient c of the areas that give none (AvaFrame com1DFA's cResH)", "ResistanceAreas::c"},
      {"resistance.detrainment", T::flag, U::keep, "true", {}, {}, "",
       "detrainment below the band and the drag only inside it; false: the drag wherever the areas lie",
       "ResistanceAreas::detrainment", "",
       [](const S& s, R& r) { r.config.resistance.detrainment = !s.resistance().has_detrainment() || s.resistance().detrainment(); }},
      {"resistance.detrainment_k_pa", T::number, U::keep, "5", Range{0, 1e4}, {}, "Pa",
       "the detrainment K of the areas that give none: the flow leaves K / (rho |u|) of thickness per second behind (Feistl et al. 2014; com1DFA's detK)",
       "ResistanceAreas::k_det"},
      {"resistance.speed_min_m_s", T::number, U::keep, "6", Range{0, 1000}, {}, "m/s",
       "the band's lowest speed: slower, the area detrains instead of dragging (com1DFA's forestVMin)", "ResistanceAreas::speed_min", "",
       [](const S& s, R& r) { r.config.resistance.speed_min = s.resistance().has_speed_min_m_s() ? s.resistance().speed_min_m_s() : engine::ResistanceAreas{}.speed_min; }},
      {"resistance.speed_max_m_s", T::number, U::keep, "40", Range{0, 1000}, {}, "m/s",
       "the band's highest speed: faster, no drag (com1DFA's forestVMax)", "ResistanceAreas::speed_max", "",
       [](const S& s, R& r) { r.config.resistance.speed_max = s.resistance().has_speed_max_m_s() ? s.resistance().speed_max_m_s() : engine::ResistanceAreas{}.speed_max; }},
      {"resistance.depth_min_m", T::number, U::keep, "0.6", Range{0, 1000}, {}, "m",
       "the band's lowest normal depth: thinner, the area detrains (com1DFA's forestThMin)", "ResistanceAreas::depth_min", "",
       [](const S& s, R& r) { r.config.resistance.depth_min = s.resistance().has_depth_min_m() ? s.resistance().depth_min_m() : engine::ResistanceAreas{}.depth_min; }},
      {"resistance.depth_max_m", T::number, U::keep, "10", Range{0, 1000}, {}, "m",
       "the band's highest normal depth: deeper, no drag (com1DFA's forestThMax)", "ResistanceAreas::depth_max", "",
       [](const S& s, R& r) { r.config.resistance.depth_max = s.resistance().has_depth_max_m() ? s.resistance().depth_max_m() : engine::ResistanceAreas{}.depth_max; }},
      {"entrainment.areas[].path", T::path, U::as_given, "", {}, {}, "",
       "polygons of erodible cover in any CRS (the part of each cell inside); needed unless thickness_raster is given",
       "ResolvedScenario::cover"},
      {"entrainment.areas[].crs", T::text, U::as_given, "", {}, {}, "", "the polygons' or raster's CRS when the file has none",
       "ResolvedScenario::cover"},
      {"entrainment.areas[].thickness_m", T::number, U::as_given, "", Range{0, kMaxThickness, true}, {}, "m",
       "the cover's thickness in every polygon (or thickness_attribute, or thickness_raster)", "ErodibleCover::depth"},
      {"entrainment.areas[].thickness_attribute", T::text, U::as_given, "", {}, {}, "",
       "the attribute that holds each polygon's cover thickness (AvaFrame's ENT files: thickness)", "ErodibleCover::depth"},
      {"entrainment.areas[].thickness_raster", T::path, U::as_given, "", {}, {}, "",
       "the cover's thickness from a raster (any GDAL format and CRS, resampled bilinearly), inside the polygons of path when given",
       "ErodibleCover::depth"},
      {"entrainment.areas[].thickness_measured", T::choice, U::as_given, "normal", {}, {"normal", "vertical"}, "",
       "the cover's thickness is measured normal to the slope or vertically", "ErodibleCover::depth"},
      {"entrainment.areas[].density_kg_m3", T::number, U::as_given, "", Range{1, 1000}, {}, "kg/m^3",
       "this area's cover density; default entrainment.density_kg_m3", "ErodibleCover::density"},
      {"entrainment.law", T::choice, U::keep, "erosion", {}, {"erosion", "ploughing"}, "",
       "erosion: tau_b |u| / e_b of mass per bed area and second (com1DFA's default); ploughing: the whole cover where the flow first flows",
       "ErodibleCover::ploughing", "", [](const S& s, R& r) { r.config.cover.ploughing = s.entrainment().law() == "ploughing"; }},
      {"entrainment.erosion_energy_j_kg", T::number, U::keep, "5000", Range{0, 1e7, true}, {}, "J/kg",
       "the specific erosion energy e_b of basal erosion (com1DFA's entEroEnergy)", "ErodibleCover::erosion_energy", "",
       [](const S& s, R& r) {
         r.config.cover.erosion_energy =
             s.entrainment().has_erosion_energy_j_kg() ? s.entrainment().erosion_energy_j_kg() : engine::ErodibleCover{}.erosion_energy;
       }},
      {"entrainment.density_kg_m3", T::number, U::keep, "100", Range{1, 1000}, {}, "kg/m^3",
       "the cover's density for the areas that give none (com1DFA's rhoEnt)", "ErodibleCover::density"},
  };
}

// The `variations` block (an ensemble, jobs/ensemble): checked here field by field; what the values
// make (members, the aggregate's settings) is jobs/ensemble/variations.cpp's.
OptionTable variation_options() {
  const Range positive{0, kMaxDepthThreshold * 1e3, true};
  return {
      {"variations.design", T::choice, U::keep, "cross-product", {}, {"cross-product", "latin-hypercube"}, "",
       "the members: every combination of the parameters' values, or a latin hypercube of `samples` members", "ensemble members"},
      {"variations.samples", T::integer, U::as_given, "", Range{0, 100000}, {}, "", "latin-hypercube: the number of members",
       "ensemble members"},
      {"variations.seed", T::integer, U::as_given, "1", {}, {}, "", "the random draws' seed (distributions, latin hypercube)",
       "ensemble members"},
      {"variations.parameters[].parameter", T::text, U::required, "", {}, {}, "",
       "the varied number by its path (material.bed_friction_deg, releases[].thickness_factor, grid.resolution_m, releases[0].active, ...)",
       "ensemble members"},
      {"variations.parameters[].values[]", T::number, U::as_given, "", Range{}, {}, "parameter's", "a list of values", "ensemble members"},
      {"variations.parameters[].from", T::number, U::as_given, "", Range{}, {}, "parameter's", "a range's (or distribution's) lower end",
       "ensemble members"},
      {"variations.parameters[].to", T::number, U::as_given, "", Range{}, {}, "parameter's", "a range's (or distribution's) upper end",
       "ensemble members"},
      {"variations.parameters[].step", T::number, U::as_given, "", Range{0, 1e9, true}, {}, "parameter's",
       "the range's step (cross product)", "ensemble members"},
      {"variations.parameters[].percent", T::number, U::as_given, "", Range{0, 100, true, true}, {}, "%",
       "the scenario's value -percent .. +percent", "ensemble members"},
      {"variations.parameters[].count", T::integer, U::as_given, "", Range{0, 100000}, {}, "",
       "values over +-percent (default 3), or draws from the distribution (cross product)", "ensemble members"},
      {"variations.parameters[].distribution", T::choice, U::as_given, "", {}, {"uniform", "normal"}, "",
       "uniform (from..to or +-percent) or normal (mean, sd; cut to from..to when given)", "ensemble members"},
      {"variations.parameters[].mean", T::number, U::as_given, "", Range{}, {}, "parameter's", "the normal distribution's mean",
       "ensemble members"},
      {"variations.parameters[].sd", T::number, U::as_given, "", Range{0, 1e9, true}, {}, "parameter's",
       "the normal distribution's standard deviation", "ensemble members"},
      {"variations.depth_thresholds_m[]", T::number, U::as_given, "", positive, {}, "m",
       "probability of max depth > each; default outputs.outline_threshold_m", "ensemble aggregate"},
      {"variations.speed_thresholds_m_s[]", T::number, U::as_given, "", positive, {}, "m/s", "probability of max speed >= each; default 1",
       "ensemble aggregate"},
      {"variations.pressure_thresholds_kpa[]", T::number, U::as_given, "", Range{0, kMaxZonePressure, true}, {}, "kPa",
       "probability of max pressure >= each; default the pressure zones' lower bounds", "ensemble aggregate"},
      {"variations.percentiles[]", T::number, U::as_given, "", Range{0, 100}, {}, "%",
       "percentiles of max depth, speed and pressure per cell; default 5, 50, 95", "ensemble aggregate"},
      {"variations.member_outputs", T::choice, U::keep, "rasters", {}, {"rasters", "all"}, "",
       "the members' outputs: hazard rasters and run.json only (no maps, no time series), or all the scenario asks for",
       "ensemble members"},
      {"zoning.scenarios[].return_period_y", T::number, U::required, "", Range{1, 100000}, {}, "years",
       "the scenario's return period, whole years (each once; at least two scenarios)", "zoning members"},
      {"zoning.scenarios[].values[].parameter", T::text, U::required, "", {}, {}, "",
       "a number of the scenario by its path, as variations name it (releases[].thickness_factor, material.voellmy_mu, ...)",
       "zoning members"},
      {"zoning.scenarios[].values[].value", T::number, U::required, "", Range{}, {}, "parameter's", "its value in this scenario",
       "zoning members"},
      {"zoning.red_pressure_kpa", T::number, U::as_given, "30", Range{0, 10000, true}, {}, "kPa",
       "red where a scenario up to design_y reaches this pressure", "zoning aggregate"},
      {"zoning.frequent_y", T::number, U::as_given, "30", Range{1, 100000}, {}, "years",
       "red wherever a scenario up to this return period reaches", "zoning aggregate"},
      {"zoning.design_y", T::number, U::as_given, "300", Range{1, 100000}, {}, "years",
       "the scenarios up to this return period make red and blue; rarer ones yellow", "zoning aggregate"},
  };
}

// The terrain, the grid and the releases.
OptionTable terrain_options() {
  return {
      {"dem.path", T::path, U::required, "", {}, {}, "", "the terrain: any raster GDAL reads (GeoTIFF, ESRI ASCII grid, SRTM .hgt, ...)",
       "DemRequest::dem_path"},
      {"dem.crs", T::text, U::as_given, "", {}, {}, "", "the DEM's CRS when the file has none (\"EPSG:2056\"; \"local\": local metres)",
       "DemRequest::dem_crs", "", [](const S& s, R& r) { r.dem.dem_crs = s.dem().crs(); }},
      {"area_of_interest.path", T::path, U::as_given, "", {}, {}, "", "a polygon file that bounds the computation; default the whole DEM",
       "DemRequest::aoi_path"},
      {"grid.resolution_m", T::number, U::as_given, "", Range{0, kMaxCell, true}, {}, "m", "cell size of the computation",
       "DemRequest::resolution", "the DEM's", [](const S& s, R& r) { r.dem.resolution = s.grid().resolution_m(); }},
      {"grid.crs", T::choice, U::as_given, "", {}, {"utm", "dem", "EPSG:<code>"}, "",
       "the computation's CRS; default (unset) utm: the UTM zone of the area's centre", "DemRequest::target_crs", "",
       [](const S& s, R& r) { r.dem.target_crs = s.grid().crs(); }},
      {"grid.resampling", T::choice, U::fill, "cubic", {}, {"near", "bilinear", "cubic", "cubicspline", "lanczos", "average"}, "",
       "GDAL's resampling of the DEM onto the grid", "DemRequest::resampling", "",
       [](const S& s, R& r) { r.dem.resampling = s.grid().resampling(); }},
      {"releases[].path", T::path, U::as_given, "", {}, {}, "",
       "release polygons in any CRS GDAL/PROJ know; at least one release; needed unless thickness_raster is given", "ReleaseRequest::path"},
      {"releases[].thickness_m", T::number, U::as_given, "", Range{0, kMaxThickness, true}, {}, "m",
       "release thickness of every polygon (or thickness_attribute, or thickness_raster)", "ReleaseRequest::thickness"},
      {"releases[].thickness_raster", T::path, U::as_given, "", {}, {}, "",
       "the release thickness from a raster (any GDAL format and CRS, resampled bilinearly at the release's samples, finer than the grid; 0 or no data "
       "does not release), inside the polygons of path when given",
       "ReleaseRequest::thickness_raster"},
      {"releases[].thickness_factor", T::number, U::keep, "1", Range{0, 100, true}, {}, "",
       "every thickness of the release (given, attribute or raster) times this; ensembles vary it (variations)",
       "ReleaseRequest::thickness_factor"},
      {"releases[].thickness_attribute", T::text, U::as_given, "", {}, {}, "", "the attribute that holds each polygon's thickness",
       "ReleaseRequest::thickness_attribute"},
      {"releases[].thickness_measured", T::choice, U::as_given, "normal", {}, {"normal", "vertical"}, "",
       "the thickness is measured normal to the slope or vertically", "ReleaseRequest::vertical"},
      {"releases[].min_slope_deg", T::number, U::as_given, "", Range{0, 90, false, true}, {}, "deg",
       "slope window: only ground at least this steep releases (on the DEM's resampled surface at its pixel size / 8, whatever the grid)", "ReleaseRequest::min_slope"},
      {"releases[].max_slope_deg", T::number, U::as_given, "", Range{0, 90, true}, {}, "deg",
       "slope window: only ground at most this steep releases (on the DEM's resampled surface at its pixel size / 8, whatever the grid)", "ReleaseRequest::max_slope"},
      {"releases[].min_slope_attribute", T::text, U::as_given, "", {}, {}, "", "the slope window's lower bound per polygon",
       "ReleaseRequest::min_slope_attribute"},
      {"releases[].max_slope_attribute", T::text, U::as_given, "", {}, {}, "", "the slope window's upper bound per polygon",
       "ReleaseRequest::max_slope_attribute"},
      {"releases[].crs", T::text, U::as_given, "", {}, {}, "", "the polygons' CRS when the file has none", "ReleaseRequest::crs"},
      {"releases[].secondary", T::flag, U::as_given, "false", {}, {}, "",
       "a secondary release: each polygon lies at rest until the flow reaches it, then starts (depth-averaged engine)",
       "ReleaseRequest::secondary"},
  };
}

// The material: density and the friction law's parameters.
OptionTable material_options() {
  return {
      {"material.rheology", T::choice, U::fill, "coulomb", {}, friction_law_names(), "",
       "the basal friction law (engine/friction; the section below)", "Material::rheology", "",
       [](const S& s, R& r) { r.config.material.rheology = &engine::friction_law(s.material().rheology()); }},
      {"material.density_kg_m3", T::number, U::fill, "300", Range{0, kMaxDensity, true}, {}, "kg/m3",
       "bulk density, for the pressure outputs (and mu_i's solid fraction)", "Material::density", "",
       [](const S& s, R& r) { r.config.material.density = s.material().density_kg_m3(); }},
      {"material.bed_friction_deg", T::number, U::as_given, "", Range{0, 90, false, true}, {}, "deg",
       "delta, the bed friction angle (coulomb)", "Material::delta (radians)", "", [](const S& s, R& r) {
         if (s.material().has_bed_friction_deg()) r.config.material.delta = radians(s.material().bed_friction_deg());
       }},
      {"material.voellmy_mu", T::number, U::as_given, "", Range{0, 5, false, true}, {}, "", "mu, the dry-friction coefficient (voellmy)",
       "Material::mu", "", [](const S& s, R& r) {
         if (s.material().has_voellmy_mu()) r.config.material.mu = s.material().voellmy_mu();
       }},
      {"material.voellmy_xi", T::number, U::as_given, "", Range{0, kMaxXi, true}, {}, "m/s^2",
       "xi, the turbulent-friction coefficient (voellmy)", "Material::xi", "", [](const S& s, R& r) {
         if (s.material().has_voellmy_xi()) r.config.material.xi = s.material().voellmy_xi();
       }},
      {"material.bed_friction_1_deg", T::number, U::as_given, "", Range{0, 90, false, true}, {}, "deg",
       "delta_1, the lowest friction angle of steady flow (pouliquen_forterre; glass beads 20.9)", "Material::delta1 (radians)", "",
       [](const S& s, R& r) {
         if (s.material().has_bed_friction_1_deg()) r.config.material.delta1 = radians(s.material().bed_friction_1_deg());
       }},
      {"material.bed_friction_2_deg", T::number, U::as_given, "", Range{0, 90, false, true}, {}, "deg",
       "delta_2 > delta_1, the friction angle of thin layers (pouliquen_forterre; glass beads 32.76)", "Material::delta2 (radians)", "",
       [](const S& s, R& r) {
         if (s.material().has_bed_friction_2_deg()) r.config.material.delta2 = radians(s.material().bed_friction_2_deg());
       }},
      {"material.bed_friction_3_deg", T::number, U::as_given, "", Range{0, 90, false, true}, {}, "deg",
       "delta_3 >= delta_1, the friction angle of mu_start: a layer at rest starts above it (pouliquen_forterre; unset: delta_1)",
       "Material::delta3 (radians)", "", [](const S& s, R& r) {
         if (s.material().has_bed_friction_3_deg()) r.config.material.delta3 = radians(s.material().bed_friction_3_deg());
       }},
      {"material.pf_beta", T::number, U::as_given, "", Range{0, kMaxFlowRule, true}, {}, "",
       "beta of the flow rule Fr = beta h / h_stop - gamma (pouliquen_forterre; glass beads 0.136)", "Material::pf_beta", "",
       [](const S& s, R& r) {
         if (s.material().has_pf_beta()) r.config.material.pf_beta = s.material().pf_beta();
       }},
      {"material.pf_length_m", T::number, U::as_given, "", Range{0, kMaxLength, true}, {}, "m",
       "L of h_stop = L (tan d2 - tan theta) / (tan theta - tan d1) (pouliquen_forterre; glass beads 0.000825, 1.65 d)", "Material::pf_length",
       "", [](const S& s, R& r) {
         if (s.material().has_pf_length_m()) r.config.material.pf_length = s.material().pf_length_m();
       }},
      {"material.pf_gamma", T::number, U::as_given, "0", Range{0, kMaxFlowRule}, {}, "",
       "gamma < beta, the flow rule's offset (pouliquen_forterre; glass beads 0)", "Material::pf_gamma", "", [](const S& s, R& r) {
         if (s.material().has_pf_gamma()) r.config.material.pf_gamma = s.material().pf_gamma();
       }},
      {"material.mu_s", T::number, U::as_given, "", Range{0, 5, false, true}, {}, "",
       "mu_s, the friction coefficient as I -> 0 (mu_i; glass beads 0.38)", "Material::mu_s", "", [](const S& s, R& r) {
         if (s.material().has_mu_s()) r.config.material.mu_s = s.material().mu_s();
       }},
      {"material.mu_2", T::number, U::as_given, "", Range{0, 5, false, true}, {}, "",
       "mu_2 >= mu_s, the friction coefficient as I -> infinity (mu_i; glass beads 0.64)", "Material::mu_2", "",
       [](const S& s, R& r) {
         if (s.material().has_mu_2()) r.config.material.mu_2 = s.material().mu_2();
       }},
      {"material.mu_i0", T::number, U::as_given, "", Range{0, kMaxFlowRule, true}, {}, "",
       "I_0, the inertial number where mu is halfway from mu_s to mu_2 (mu_i; glass beads 0.279)", "Material::mu_i0", "",
       [](const S& s, R& r) {
         if (s.material().has_mu_i0()) r.config.material.mu_i0 = s.material().mu_i0();
       }},
      {"material.grain_diameter_m", T::number, U::as_given, "", Range{0, kMaxLength, true}, {}, "m",
       "d, the grain diameter (mu_i; glass beads 0.0005)", "Material::grain_diameter", "", [](const S& s, R& r) {
         if (s.material().has_grain_diameter_m()) r.config.material.grain_diameter = s.material().grain_diameter_m();
       }},
      {"material.grain_density_kg_m3", T::number, U::as_given, "", Range{0, kMaxDensity, true}, {}, "kg/m3",
       "rho_s, the grains' density: phi = density_kg_m3 / rho_s <= 1 is the solid fraction (mu_i; glass beads 2450)",
       "Material::grain_density", "", [](const S& s, R& r) {
         if (s.material().has_grain_density_kg_m3()) r.config.material.grain_density = s.material().grain_density_kg_m3();
       }},
      {"material.internal_friction_deg", T::number, U::as_given, "", Range{0, 90, false, true}, {}, "deg",
       "phi, the internal friction angle (earth_pressure active-passive)", "Material::phi (radians)", "", [](const S& s, R& r) {
         if (s.material().has_internal_friction_deg()) r.config.material.phi = radians(s.material().internal_friction_deg());
       }},
      {"material.earth_pressure", T::choice, U::fill, "unity", {}, names(engine::kEarthPressureNames), "",
       "earth-pressure coefficient: 1 (hydrostatic) or active/passive from phi and delta", "Material::earth_pressure", "",
       [](const S& s, R& r) { r.config.material.earth_pressure = value(engine::kEarthPressureNames, s.material().earth_pressure()); }},
  };
}

// The scheme, the time step, the end time and the stop rule, the boundaries.
OptionTable numerics_options() {
  return {
      {"numerics.scheme", T::choice, U::fill, "noc-tvd", {}, {"noc-tvd"}, "",
       "NOC predictor with TVD-limited slopes, central face fluxes (the only one)", "-"},
      {"numerics.limiter", T::choice, U::fill, "minmod", {}, names(engine::kLimiterNames), "", "the TVD slope limiter",
       "Sh2dConfig::limiter", "", [](const S& s, R& r) { r.config.limiter = value(engine::kLimiterNames, s.numerics().limiter()); }},
      {"numerics.cfl", T::number, U::fill, "0.45", Range{0.01, 0.5}, {}, "", "Courant number of the time step",
       "Sh2dConfig::time.cfl", "", [](const S& s, R& r) { r.config.time.cfl = s.numerics().cfl(); }},
      {"numerics.end_time_s", T::number, U::fill, "600", Range{0, kMaxEndTime, true}, {}, "s", "the simulated time at most",
       "Sh2dConfig::time.t_end", "", [](const S& s, R& r) { r.config.time.t_end = s.numerics().end_time_s(); }},
      {"numerics.stop_fraction", T::number, U::fill, "0.01", Range{0, 1, false, true}, {}, "",
       "stop when the kinetic energy falls below this fraction of its peak", "Sh2dConfig::time.stop_fraction", "",
       [](const S& s, R& r) { r.config.time.stop_fraction = s.numerics().stop_fraction(); }},
      {"numerics.boundary", T::choice, U::fill, "outflow", {}, names(engine::kBoundary2DNames), "",
       "at the grid's edges: material leaves (outflow) or is held (wall)", "Sh2dConfig::west, east, south, north", "",
       [](const S& s, R& r) {
         r.config.west = r.config.east = r.config.south = r.config.north = value(engine::kBoundary2DNames, s.numerics().boundary());
       }},
      {"numerics.curvature_off", T::flag, U::as_given, "false", {}, {}, "", "true: no centrifugal term in the friction",
       "Sh2dConfig::curvature (negated)", "", [](const S& s, R& r) { r.config.curvature = !s.numerics().curvature_off(); }},
  };
}

}  // namespace

const OptionTable& depth_averaged_options() {
  static const OptionTable t = [] {
    OptionTable v;
    for (auto* part : {terrain_options, material_options, numerics_options, output_options, ground_options, works_options, variation_options})
      for (auto& o : part()) v.push_back(std::move(o));
    return v;
  }();
  return t;
}

}  // namespace runout::jobs
