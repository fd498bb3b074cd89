#include "jobs/scenario/scenario.hpp"

#include "engine/friction/registry.hpp"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>

#include "jobs/digest/sha256.hpp"
#include "jobs/scenario/json_shape.hpp"
#include "jobs/scenario/text_limits.hpp"
#include "jobs/scenario/model_fields.hpp"
#include "jobs/scenario/options.hpp"
#include "jobs/scenario/scenario_impl.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <mutex>
#include <set>
#include <sstream>


namespace runout::jobs {

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream o;
  o.precision(10);
  o << v;
  return o.str();
}
namespace fs = std::filesystem;

namespace {

// An input file: it must exist and be a regular file (symbolic links followed). A FIFO or device
// would block the reader (GDAL's open, which SIGTERM does not interrupt); a folder cannot be hashed.
std::string path_in(const std::string& base, const std::string& p, const std::string& field) {
  if (p.empty()) bad(field, "missing");
  fs::path q(p);
  if (q.is_relative()) q = fs::path(base) / q;
  std::error_code ec;
  const auto st = fs::status(q, ec);
  if (st.type() == fs::file_type::not_found) bad(field, "file '" + q.string() + "' does not exist");
  if (ec) bad(field, "cannot read '" + q.string() + "': " + ec.message());
  if (st.type() != fs::file_type::regular) bad(field, "'" + q.string() + "' is not a regular file");
  return q.string();
}

// A companion of an input (a DEM's .prj, a shapefile's .dbf): true when it is there; one that is there
// but not a regular file (or cannot be looked at) is refused like the input itself.
bool companion(const fs::path& q, const std::string& field) {
  std::error_code ec;
  const auto st = fs::status(q, ec);
  if (st.type() == fs::file_type::not_found) return false;
  if (ec) bad(field, "cannot read '" + q.string() + "' (read with the file): " + ec.message());
  if (st.type() != fs::file_type::regular) bad(field, "'" + q.string() + "' (read with the file) is not a regular file");
  return true;
}

}  // namespace

// Safety net after the field checks: no number anywhere in the scenario may be NaN or infinite (a
// field added later without a range check included).
void require_finite(const google::protobuf::Message& m, const std::string& prefix) {
  using google::protobuf::FieldDescriptor;
  const auto* refl = m.GetReflection();
  std::vector<const FieldDescriptor*> fields;
  refl->ListFields(m, &fields);
  for (const auto* f : fields) {
    const std::string name = prefix.empty() ? f->name() : prefix + "." + f->name();
    const int n = f->is_repeated() ? refl->FieldSize(m, f) : 1;
    for (int k = 0; k < n; ++k) {
      const std::string at = f->is_repeated() ? name + "[" + std::to_string(k) + "]" : name;
      double v = 0;
      if (f->cpp_type() == FieldDescriptor::CPPTYPE_DOUBLE) {
        v = f->is_repeated() ? refl->GetRepeatedDouble(m, f, k) : refl->GetDouble(m, f);
      } else if (f->cpp_type() == FieldDescriptor::CPPTYPE_FLOAT) {
        v = f->is_repeated() ? refl->GetRepeatedFloat(m, f, k) : refl->GetFloat(m, f);
      } else if (f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
        require_finite(f->is_repeated() ? refl->GetRepeatedMessage(m, f, k) : refl->GetMessage(m, f), at);
      }
      if (!std::isfinite(v)) bad(at, "must be a finite number, got " + num(v));
    }
  }
}

const std::vector<HazardRaster>& hazard_rasters() {
  using M = engine::HazardMaps;
  static const std::vector<HazardRaster> r = {
      {"max_depth", "maximum flow depth normal to the surface [m]", "m", &M::max_depth},
      {"max_speed", "maximum flow speed [m/s]", "m/s", &M::max_speed},
      {"max_pressure", "maximum pressure rho u^2 [kPa]", "kPa", &M::max_pressure, 1e-3},
      {"deposit", "deposit depth normal to the surface at the end [m]", "m", &M::final_depth},
      {"arrival_time", "arrival time of the flow [s]", "s", &M::arrival_time},
  };
  return r;
}

const std::vector<std::string>& raster_names() {
  static const std::vector<std::string> n = [] {
    std::vector<std::string> v;
    for (const auto& r : hazard_rasters()) v.push_back(r.name);
    return v;
  }();
  return n;
}

v1::Scenario parse_scenario_json(const std::string& json) {
  v1::Scenario s;
  google::protobuf::util::JsonParseOptions opt;
  opt.ignore_unknown_fields = false;
  const auto st = google::protobuf::util::JsonStringToMessage(json, &s, opt);
  if (!st.ok()) throw ScenarioError("scenario JSON: " + std::string(st.message()));
  check_text_limits(s);
  try {
    check_json_shape(json);  // what protobuf's parser lets through: duplicate keys, a value for a list
  } catch (const ScenarioError& e) {
    throw ScenarioError("scenario JSON: " + std::string(e.what()));
  }
  return s;
}

void apply_material_rheology(const v1::Material& m, engine::vof::VofConfig& c) {
  c.rho1 = m.density_kg_m3();
  c.rheology = m.rheology().empty() ? "coulomb" : m.rheology();  // a granular viscosity's name (check_terrain_vof)
  take_model_fields(m, ModelBlock::material, c);
}

ResolvedScenario load_scenario(const std::string& path) {
  std::error_code ec;
  const auto st = fs::status(path, ec);
  if (st.type() != fs::file_type::not_found && ec) throw ScenarioError("scenario '" + path + "': cannot read it: " + ec.message());
  if (!ec && st.type() != fs::file_type::regular) throw ScenarioError("scenario '" + path + "': not a regular file");
  std::ifstream in(path);
  if (!in) throw ScenarioError("scenario '" + path + "': cannot read the file");
  std::stringstream ss;
  ss << in.rdbuf();
  v1::Scenario s;
  try {
    s = parse_scenario_json(ss.str());
  } catch (const ScenarioError& e) {
    throw ScenarioError("scenario '" + path + "': " + e.what());
  }
  auto r = resolve_scenario(std::move(s), fs::absolute(fs::path(path)).parent_path().string());
  r.source = path;
  return r;
}

namespace {

// A raster input and the companion files that change how it reads (ESRI ASCII .prj, GDAL's PAM
// file .aux.xml): all part of the input.
void add_raster(const std::string& path, const std::string& field, ResolvedScenario& r) {
  r.input_files.push_back(path);
  for (const char* ext : {".prj", ".hdr", ".tfw"}) {
    fs::path side = fs::path(path).replace_extension(ext);
    if (side != fs::path(path) && companion(side, field)) r.input_files.push_back(side.string());
  }
  if (companion(path + ".aux.xml", field)) r.input_files.push_back(path + ".aux.xml");
}

// A vector input and, for a shapefile, its companions.
void add_vector(const std::string& path, const std::string& field, ResolvedScenario& r) {
  r.input_files.push_back(path);
  for (const char* ext : {".shx", ".dbf", ".prj", ".cpg"}) {
    fs::path side = fs::path(path).replace_extension(ext);
    if (fs::path(path).extension() == ".shp" && companion(side, field)) r.input_files.push_back(side.string());
  }
}

// The input files: the DEM with the companions that change how it reads, the area of interest.
void resolve_inputs(const v1::Scenario& s, const std::string& base, ResolvedScenario& r) {
  r.dem.dem_path = path_in(base, s.dem().path(), "dem.path");
  add_raster(r.dem.dem_path, "dem.path", r);
  if (!s.area_of_interest().path().empty()) {
    r.dem.aoi_path = path_in(base, s.area_of_interest().path(), "area_of_interest.path");
    r.input_files.push_back(r.dem.aoi_path);
  }
  if (!s.path().line_path().empty()) {
    r.path.line_path = path_in(base, s.path().line_path(), "path.line_path");
    add_vector(r.path.line_path, "path.line_path", r);
  }
  if (!s.observations().outline_path().empty()) {
    r.observed_outline = path_in(base, s.observations().outline_path(), "observations.outline_path");
    add_vector(r.observed_outline, "observations.outline_path", r);
  }
  const auto& rs = s.resistance();
  for (int a = 0; a < rs.areas_size(); ++a) {
    const auto& ar = rs.areas(a);
    const std::string field = "resistance.areas[" + std::to_string(a) + "]";
    ResistanceAreaSettings q;
    q.path = path_in(base, ar.path(), field + ".path");
    add_vector(q.path, field + ".path", r);
    q.crs = ar.crs();
    if (ar.has_drag_coefficient()) q.c = ar.drag_coefficient();  // else the block's, else the default
    else if (rs.has_drag_coefficient()) q.c = rs.drag_coefficient();
    if (ar.has_detrainment_k_pa()) q.k_det = ar.detrainment_k_pa();
    else if (rs.has_detrainment_k_pa()) q.k_det = rs.detrainment_k_pa();
    r.resistance.push_back(q);
  }
  if (!s.mesh().corridor_path().empty()) {
    r.corridor_path = path_in(base, s.mesh().corridor_path(), "mesh.corridor_path");
    add_vector(r.corridor_path, "mesh.corridor_path", r);
  }
}

// The thickness of a release or an area of cover (the messages Release and CoverArea share these
// fields): polygons with a thickness or a thickness attribute, or a thickness raster, any CRS. `f`
// names the entry in messages, `what` what its polygons are.
template <class M>
terrain::ReleaseRequest resolve_thickness(const M& m, const std::string& f, const char* what, const std::string& base,
                                          ResolvedScenario& r) {
  terrain::ReleaseRequest q;
  if (m.path().empty() && m.thickness_raster().empty()) bad(f + ".path", std::string("missing (") + what + " polygons, or a thickness_raster)");
  if (!m.path().empty()) {
    q.path = path_in(base, m.path(), f + ".path");
    add_vector(q.path, f + ".path", r);
  }
  q.has_thickness = m.has_thickness_m();
  q.thickness = m.thickness_m();
  q.thickness_attribute = m.thickness_attribute();
  if (!m.thickness_raster().empty()) {
    q.thickness_raster = path_in(base, m.thickness_raster(), f + ".thickness_raster");
    add_raster(q.thickness_raster, f + ".thickness_raster", r);
    if (q.has_thickness || !q.thickness_attribute.empty())
      bad(f + ".thickness_raster", "gives the thickness: leave thickness_m and thickness_attribute unset");
  } else if (!q.has_thickness && q.thickness_attribute.empty()) {
    bad(f, "needs thickness_m, thickness_attribute or thickness_raster");
  }
  q.vertical = m.thickness_measured() == "vertical";
  q.crs = m.crs();
  return q;
}

// The erodible cover's areas: each read as a release is, with its density.
void resolve_cover(const v1::Scenario& s, const std::string& base, ResolvedScenario& r) {
  const auto& e = s.entrainment();
  for (int a = 0; a < e.areas_size(); ++a) {
    const auto& ar = e.areas(a);
    const std::string f = "entrainment.areas[" + std::to_string(a) + "]";
    CoverAreaSettings c;
    c.release = resolve_thickness(ar, f, "cover", base, r);
    c.release.kind = f;
    c.density = ar.has_density_kg_m3() ? ar.density_kg_m3() : e.has_density_kg_m3() ? e.density_kg_m3() : 100.0;
    r.cover.push_back(c);
  }
}

// A dam's or a structure's file with its name (or `fallback`) and height fields, as a request.
bool has_surface(const v1::Dam&) { return false; }
bool has_surface(const v1::Structure& d) { return !d.surface_path().empty(); }

template <class M>
DamSettings vector_with_height(const M& d, const std::string& f, const std::string& fallback, const std::string& base, ResolvedScenario& r) {
  DamSettings q;
  q.name = d.name().empty() ? fallback : d.name();
  q.request.field = f;
  if (!d.path().empty() || !has_surface(d)) {  // a structure from a surface model may go without footprints
    q.request.path = path_in(base, d.path(), f + ".path");
    add_vector(q.request.path, f + ".path", r);
  }
  q.request.crs = d.crs();
  q.request.has_height = d.has_height_m();
  q.request.height = d.height_m();
  q.request.height_attribute = d.height_attribute();
  return q;
}

// The dams: each a vector file with a height (given or per feature).
void resolve_dams(const v1::Scenario& s, const std::string& base, ResolvedScenario& r) {
  for (int a = 0; a < s.dams_size(); ++a) {
    const std::string f = "dams[" + std::to_string(a) + "]";
    DamSettings q = vector_with_height(s.dams(a), f, "dam " + std::to_string(a + 1), base, r);
    if (!q.request.has_height && q.request.height_attribute.empty()) bad(f, "needs height_m or height_attribute");
    if (q.request.has_height && !q.request.height_attribute.empty()) bad(f + ".height_attribute", "give height_m or height_attribute, not both");
    r.dams.push_back(q);
  }
}

// The structures: each a file of footprints with a height, given, per feature or as a top elevation.
void resolve_structures(const v1::Scenario& s, const std::string& base, ResolvedScenario& r) {
  for (int a = 0; a < s.structures_size(); ++a) {
    const std::string f = "structures[" + std::to_string(a) + "]";
    DamSettings q = vector_with_height(s.structures(a), f, "structure " + std::to_string(a + 1), base, r);
    for (const auto& other : r.structures)
      if (other.name == q.name) bad(f + ".name", "\"" + q.name + "\" names another structure already; each needs its own name");
    const auto& st = s.structures(a);
    q.request.top_attribute = st.top_attribute();
    if (!st.surface_path().empty()) {
      q.request.surface_path = path_in(base, st.surface_path(), f + ".surface_path");
      add_raster(q.request.surface_path, f + ".surface_path", r);
    }
    if (st.has_min_height_m() && st.surface_path().empty()) bad(f + ".min_height_m", "only with surface_path");
    q.request.min_height = st.has_min_height_m() ? st.min_height_m() : 2.0;
    const int given = int(q.request.has_height) + int(!q.request.height_attribute.empty()) + int(!q.request.top_attribute.empty()) +
                      int(!q.request.surface_path.empty());
    if (given == 0) bad(f, "needs height_m, height_attribute, top_attribute or surface_path");
    if (given > 1) bad(f, "give one of height_m, height_attribute, top_attribute and surface_path, not several");
    r.structures.push_back(q);
  }
}

void resolve_releases(const v1::Scenario& s, const std::string& base, ResolvedScenario& r) {
  if (s.releases().empty()) bad("releases", "at least one release is needed");
  for (int k = 0; k < s.releases_size(); ++k) {
    const auto& rl = s.releases(k);
    const std::string f = "releases[" + std::to_string(k) + "]";
    terrain::ReleaseRequest q = resolve_thickness(rl, f, "release", base, r);
    if (!q.thickness_raster.empty() && q.path.empty() && (!rl.min_slope_attribute().empty() || !rl.max_slope_attribute().empty()))
      bad(f, "slope-window attributes need polygons (path); give min_slope_deg and max_slope_deg");
    q.has_min_slope = rl.has_min_slope_deg();
    q.min_slope = rl.min_slope_deg();
    q.has_max_slope = rl.has_max_slope_deg();
    q.max_slope = rl.max_slope_deg();
    if (q.has_min_slope && q.has_max_slope && !(q.min_slope < q.max_slope)) bad(f, "min_slope_deg must be below max_slope_deg");
    q.min_slope_attribute = rl.min_slope_attribute();
    q.max_slope_attribute = rl.max_slope_attribute();
    q.secondary = rl.secondary();
    q.thickness_factor = rl.has_thickness_factor() ? rl.thickness_factor() : 1.0;
    r.releases.push_back(q);
  }
  if (std::all_of(r.releases.begin(), r.releases.end(), [](const terrain::ReleaseRequest& q) { return q.secondary; }))
    bad("releases", "every release is secondary: at least one must start the flow");
}

// The friction law's parameters (engine/friction: each law lists the material fields it reads; those
// without a meaning for unset are required), then the material's physical limits.
void check_material(const v1::Material& m, const engine::Material& mat) {
  const auto* refl = m.GetReflection();
  for (const auto& p : mat.rheology->parameters) {
    if (p.field.empty()) break;
    if (!p.unset.empty()) continue;
    const auto* f = m.GetDescriptor()->FindFieldByName(std::string(p.field));
    if (!f || !refl->HasField(m, f))
      bad("material." + std::string(p.field), "needed by the " + std::string(mat.rheology->name) + " rheology");
  }
  if (mat.earth_pressure == engine::EarthPressure::active_passive && !m.has_internal_friction_deg())
    bad("material.internal_friction_deg", "needed by earth_pressure active-passive");
  try {
    mat.validate();
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(e.what());
  }
}

// The 3D engine on the DEM: a friction law it has a granular viscosity of the same name for
// (engine/vof/models), with every parameter of that model's rows given in the material (the rows'
// ranges and the model's checks: check_model), and the bed's friction angle.
void check_terrain_vof(const v1::Scenario& s) {
  const auto& m = s.material();
  std::vector<std::string> laws;  // the friction laws the 3D engine has a granular viscosity of the same name for
  for (const auto* law : engine::kFrictionLaws)
    if (engine::vof::find_granular_viscosity(law->name)) laws.push_back("\"" + std::string(law->name) + "\"");
  const auto* model = engine::vof::find_granular_viscosity(m.rheology());
  if (!model || std::find(laws.begin(), laws.end(), "\"" + m.rheology() + "\"") == laws.end()) {
    std::string list;
    for (std::size_t k = 0; k < laws.size(); ++k) list += (k == 0 ? "" : k + 1 == laws.size() ? " or " : ", ") + laws[k];
    bad("material.rheology", "the 3D engine takes " + list + " (got \"" + m.rheology() + "\")");
  }
  const auto* refl = m.GetReflection();
  for (const auto& p : model->parameters) {
    if (p.field.empty()) break;
    const auto* f = m.GetDescriptor()->FindFieldByName(std::string(p.material_name()));
    if (!f || !refl->HasField(m, f)) bad(model_field(p, ModelBlock::material), "needed by the 3D engine's " + std::string(model->caption));
  }
  engine::vof::VofConfig c;
  apply_material_rheology(m, c);
  check_model(c, ModelBlock::material);
  if (!m.has_bed_friction_deg()) bad("material.bed_friction_deg", "needed by the 3D engine's bed condition");
  if (!s.outputs().report().empty())
    bad("outputs.report", "the 3D engine's run writes no report itself; make it with `runout report` on the run's folder");
  const auto& me = s.mesh();
  if (me.has_first_layer_m() && me.has_band_height_m() && !(me.band_height_m() > me.first_layer_m()))
    bad("mesh.band_height_m", "must exceed mesh.first_layer_m");
  if (me.corridor() == "polygon" && me.corridor_path().empty()) bad("mesh.corridor_path", "missing (mesh.corridor \"polygon\")");
  if (me.corridor() != "polygon" && !me.corridor_path().empty())
    bad("mesh.corridor_path", "only with mesh.corridor \"polygon\" (got \"" + me.corridor() + "\")");
  if (me.corridor() != "polygon" && !me.corridor_crs().empty())
    bad("mesh.corridor_crs", "only with mesh.corridor \"polygon\" (got \"" + me.corridor() + "\")");
  if (me.corridor() != "footprint" && me.has_corridor_margin_m())
    bad("mesh.corridor_margin_m", "only with mesh.corridor \"footprint\" (got \"" + me.corridor() + "\")");
  for (int k = 0; k < s.releases_size(); ++k)
    if (s.releases(k).secondary())
      bad("releases[" + std::to_string(k) + "].secondary", "the 3D engine takes no secondary releases (the depth-averaged engine does)");
  if (s.resistance().ByteSizeLong() > 0)
    bad("resistance", "the 3D engine takes no resistance areas (the depth-averaged engine does)");
  if (s.entrainment().ByteSizeLong() > 0)
    bad("entrainment", "the 3D engine takes no erodible cover (the depth-averaged engine does)");
  if (s.dams_size() > 0) bad("dams", "the 3D engine takes no dams yet (the depth-averaged engine does; structures[] go to both)");
}

// The erodible cover: at least one area, and a friction law with a constant mu (the kernels of the
// ground's terms take Coulomb's and Voellmy's basal shear stress).
void check_cover(const v1::Scenario& s, const ResolvedScenario& r) {
  if (s.entrainment().ByteSizeLong() == 0) return;  // none given (or only defaults, which the options cleared)
  if (s.entrainment().areas_size() == 0) bad("entrainment.areas", "at least one area (polygons or a thickness raster)");
  const engine::Material& mat = r.config.material;
  if (mat.friction().flow)
    bad("entrainment", "needs a friction law with a constant mu (material.rheology coulomb or voellmy), not " +
                           std::string(mat.rheology->name));
}

// Resistance areas: at least one area, a band whose minima lie below its maxima, and a friction law
// with a constant mu (the areas' drag joins Voellmy's in the kernels).
void check_resistance(const v1::Scenario& s, const ResolvedScenario& r) {
  if (s.resistance().ByteSizeLong() == 0) return;  // none given (or only defaults, which the options cleared)
  const auto& band = r.config.resistance;  // the options' values, defaults filled in
  const engine::Material& mat = r.config.material;
  if (s.resistance().areas_size() == 0) bad("resistance.areas", "at least one area (polygons)");
  if (band.speed_min > band.speed_max) bad("resistance.speed_min_m_s", "must not exceed resistance.speed_max_m_s");
  if (band.depth_min > band.depth_max) bad("resistance.depth_min_m", "must not exceed resistance.depth_max_m");
  if (mat.friction().flow)
    bad("resistance", "needs a friction law with a constant mu (material.rheology coulomb or voellmy), not " +
                          std::string(mat.rheology->name));
}

}  // namespace

namespace {

// The 3D run of a depth-averaged scenario's nest: the same scenario for engine "vof" on the DEM, its
// mesh's corridor the nest's polygons, its refinement and layers the nest's. What the 3D engine
// refuses (dams, resistance, cover, secondary releases) is refused for the nest, naming it.
ResolvedScenario resolve_nest(const v1::Scenario& s, const std::string& base) {
  const auto& n = s.nest();
  if (n.path().empty()) bad("nest.path", "missing: the nest's polygons");
  const int refinement = n.refinement() == 0 ? 4 : n.refinement();  // unset: the default
  if (refinement < 1 || refinement > 8) bad("nest.refinement", "must lie in [1, 8], got " + std::to_string(refinement));
  v1::Scenario d = s;
  d.clear_nest();
  d.set_engine("vof");
  auto* me = d.mutable_mesh();
  me->set_corridor("polygon");
  me->set_corridor_path(n.path());
  me->set_corridor_crs(n.crs());
  me->set_refinement(refinement);
  if (n.has_first_layer_m()) me->set_first_layer_m(n.first_layer_m());
  if (n.has_band_height_m()) me->set_band_height_m(n.band_height_m());
  try {
    ResolvedScenario r = resolve_scenario(d, base);
    r.nest_part = true;
    return r;
  } catch (const ScenarioError& e) {
    throw ScenarioError(std::string("nest: the 3D run of the nest: ") + e.what());
  }
}

}  // namespace

ResolvedScenario resolve_scenario(v1::Scenario s, const std::string& base) {
  check_text_limits(s);  // first: nothing else reads an unbounded name or a path cut by a NUL byte
  apply_option_rules(scenario_options(), s);
  const bool vof = s.engine() == "vof";
  if (s.ranks() > 1) {
    if (s.has_variations() || s.has_zoning())
      bad("ranks", "an ensemble's members run on one process each; ranks splits one 3D run over MPI ranks");
    if (!vof && !s.has_nest())
      bad("ranks", "only for a 3D run (engine \"vof\", or a depth-averaged scenario's nest): the depth-averaged engine runs on one process");
  }
  if (vof && s.has_lab()) return resolve_lab(std::move(s));
  if (!vof && s.has_mesh()) bad("mesh", "only for engine \"vof\" (the 3D engine on the DEM); a nest's mesh is in `nest`");
  if (vof && s.has_nest()) bad("nest", "only for engine \"depth-averaged\": the nest is a 3D run inside a depth-averaged one");
  // The option tables fill the defaults and check every field's range or choices; the checks
  // between fields and the input files follow.
  apply_option_rules(depth_averaged_options(), s);
  if (s.has_resistance() && s.resistance().ByteSizeLong() == 0) s.clear_resistance();  // only its defaults: none
  if (s.has_entrainment() && s.entrainment().ByteSizeLong() == 0) s.clear_entrainment();
  if (s.has_nest() && s.nest().ByteSizeLong() == 0) s.clear_nest();  // only its defaults: none
  if (!vof && s.has_vof() && !s.has_nest())  // a depth-averaged scenario's `vof` block is its nest's 3D run
    bad("vof", "only for engine \"vof\" (the 3D engine on the DEM), or for the 3D run of a depth-averaged scenario's nest");
  if (vof) {
    const double write_given = s.vof().write_interval_s();
    apply_option_rules(terrain_vof_options(), s);
    s.mutable_vof()->set_write_interval_s(default_frame_interval(write_given, s.vof().write_interval_s(), s.numerics().end_time_s()));
  }
  ResolvedScenario r;
  resolve_inputs(s, base, r);
  resolve_releases(s, base, r);
  resolve_cover(s, base, r);
  resolve_dams(s, base, r);
  resolve_structures(s, base, r);
  map_options(scenario_options(), s, r);
  map_options(depth_averaged_options(), s, r);
  if (vof) check_terrain_vof(s);  // first: the 3D engine takes one friction law
  check_material(s.material(), r.config.material);
  if (!vof) check_resistance(s, r);
  if (!vof) check_cover(s, r);
  const double t_end = s.numerics().end_time_s();
  check_output_interval("outputs.timeseries_interval_s", s.outputs().timeseries_interval_s(), "numerics.end_time_s", t_end, true);
  if (vof) {
    check_output_interval("vof.write_interval_s", s.vof().write_interval_s(), "numerics.end_time_s", t_end, false);
    check_output_interval("vof.checkpoint_interval_s", s.vof().checkpoint_interval_s(), "numerics.end_time_s", t_end, true);
  }
  require_finite(s, "");
  if (s.has_nest()) {
    r.nest = std::make_shared<const ResolvedScenario>(resolve_nest(s, base));
    for (const auto& f : r.nest->input_files)  // the nest's polygons
      if (std::find(r.input_files.begin(), r.input_files.end(), f) == r.input_files.end()) r.input_files.push_back(f);
  }
  r.scenario = std::move(s);
  return r;
}

namespace {

// The digest of an input file, remembered by its path, size and modification time: an ensemble's
// members share their inputs, and a large DEM is read once, not once per member.
std::string input_digest(const std::string& path) {
  static std::mutex mu;
  static std::map<std::string, std::pair<std::string, std::string>> memo;  // path -> (size:mtime, digest)
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  const auto mtime = fs::last_write_time(path, ec);
  if (ec) return sha256_file(path);
  const std::string stamp = std::to_string(size) + ":" + std::to_string(mtime.time_since_epoch().count());
  {
    std::lock_guard lk(mu);
    if (const auto it = memo.find(path); it != memo.end() && it->second.first == stamp) return it->second.second;
  }
  std::string d = sha256_file(path);
  std::lock_guard lk(mu);
  memo[path] = {stamp, d};
  return d;
}

}  // namespace

std::string scenario_hash(const ResolvedScenario& r, int depth_averaged_version, int vof_version) {
  v1::Scenario s = r.scenario;
  s.mutable_dem()->clear_path();
  s.mutable_area_of_interest()->clear_path();
  for (auto& rel : *s.mutable_releases()) {
    rel.clear_path();
    rel.clear_thickness_raster();
  }
  if (s.has_observations()) s.mutable_observations()->clear_outline_path();
  if (s.has_path()) s.mutable_path()->clear_line_path();
  if (s.has_mesh()) s.mutable_mesh()->clear_corridor_path();
  if (s.has_nest()) s.mutable_nest()->clear_path();
  if (s.has_resistance())
    for (auto& a : *s.mutable_resistance()->mutable_areas()) a.clear_path();
  for (auto& d : *s.mutable_dams()) d.clear_path();
  for (auto& d : *s.mutable_structures()) d.clear_path();
  if (s.has_entrainment())
    for (auto& a : *s.mutable_entrainment()->mutable_areas()) {
      a.clear_path();
      a.clear_thickness_raster();
    }
  // A block left empty (its kept defaults cleared) is the block not given.
  if (s.has_path() && s.path().ByteSizeLong() == 0) s.clear_path();
  if (s.has_observations() && s.observations().ByteSizeLong() == 0) s.clear_observations();
  if (s.has_variations() && s.variations().ByteSizeLong() == 0) s.clear_variations();
  s.clear_limits();  // a job's limits do not change what it computes
  s.clear_ranks();   // nor, beyond round-off, the ranks it runs on
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream so(&bytes);
    google::protobuf::io::CodedOutputStream co(&so);
    co.SetSerializationDeterministic(true);
    s.SerializeToCodedStream(&co);
  }
  Sha256 h;
  h.update("runout.v1.Scenario\n");
  h.update(bytes);
  // What the engine's results contain, by version (kVofResultsVersion, kDepthAveragedResultsVersion).
  if (r.three_d()) h.update("\nvof results " + std::to_string(vof_version));
  else h.update("\ndepth-averaged results " + std::to_string(depth_averaged_version));
  for (const auto& f : r.input_files) {
    h.update("\n");
    h.update(fs::path(f).extension().string());
    h.update(" ");
    h.update(input_digest(f));
  }
  return h.hex();
}

}  // namespace runout::jobs
