#include "jobs/scenario/scenario.hpp"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>

#include "jobs/digest/sha256.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>

#include "engine/names.hpp"

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

[[noreturn]] void bad(const std::string& field, const std::string& problem) { throw ScenarioError(field + ": " + problem); }

// A named option whose default stays unset, so that scenarios from before the option existed keep
// their hash: empty or one of `valid` (the first is the default). True when it names the default,
// which the caller then clears.
bool unset_default(const std::string& value, const std::string& field, std::initializer_list<const char*> valid) {
  if (value.empty()) return false;
  std::string list;
  bool first = true;
  for (const char* v : valid) {
    if (value == v) return first;
    list += (first ? "" : ", ") + std::string(v);
    first = false;
  }
  bad(field, "unknown '" + value + "' (valid: " + list + ")");
}

std::string num(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

// The valid ranges of the numeric fields (docs/user/scenarios.md "Valid ranges"): a value outside, NaN or an
// infinity is refused with the field, the range and the value. `lo_open` / `hi_open`: the bound itself
// is excluded.
void in_range(const std::string& field, double v, double lo, double hi, const char* unit = "", bool lo_open = false,
              bool hi_open = false, const char* note = "") {
  const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  if (!ok)
    bad(field, std::string("must lie in ") + (lo_open ? "(" : "[") + num(lo) + ", " + num(hi) + (hi_open ? ")" : "]") +
                   (*unit ? " " : "") + unit + note + ", got " + num(v));
}
// Bounds (docs/user/scenarios.md "Valid ranges").
constexpr double kMaxCell = 1e4;          // grid.resolution_m [m]
constexpr double kMaxThickness = 500;     // a release [m]: rock avalanches start some hundred metres thick
constexpr double kMaxDensity = 1e4;       // [kg/m3]: above any rock or ore
constexpr double kMaxXi = 1e5;            // Voellmy xi [m/s2]
constexpr double kMaxEndTime = 1e5;       // numerics.end_time_s, outputs.timeseries_interval_s [s]
constexpr double kMaxDepthThreshold = 100;  // outline and flow thresholds [m]
constexpr double kMaxLabExtent = 1e4;     // |coordinate| of the lab block [m]
constexpr double kMaxLabTime = 1e4;       // lab times [s]

// An input file: it must exist and be a regular file (symbolic links followed). A FIFO or device
// would block the reader (GDAL's open, which SIGTERM does not interrupt); a folder cannot be hashed.
std::string path_in(const std::string& base, const std::string& p, const std::string& field) {
  if (p.empty()) bad(field, "missing");
  if (p.find('\0') != std::string::npos) bad(field, "the path holds a NUL character");
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

// Lenient JSON that protobuf's parser accepts: a key given twice (the later wins) and a single value
// where a list is needed (taken as a one-element list). A small scanner over the text that protobuf
// already parsed, following the message's fields; it gives up quietly on anything it does not
// understand (protobuf has judged the syntax).
class JsonShape {
 public:
  explicit JsonShape(const std::string& t) : t_(t) {}
  void check() {
    try {
      ws();
      object(v1::Scenario::descriptor(), "");
    } catch (const ScenarioError&) {
      throw;
    } catch (...) {  // GiveUp, or a \u escape that is not hex
    }
  }

 private:
  struct GiveUp {};
  const std::string& t_;
  std::size_t i_ = 0;

  char peek() {
    if (i_ >= t_.size()) throw GiveUp{};
    return t_[i_];
  }
  void ws() {
    while (i_ < t_.size() && (t_[i_] == ' ' || t_[i_] == '\t' || t_[i_] == '\n' || t_[i_] == '\r')) ++i_;
  }
  void expect(char c) {
    if (peek() != c) throw GiveUp{};
    ++i_;
  }
  std::string string() {
    expect('"');
    std::string s;
    while (peek() != '"') {
      char c = t_[i_++];
      if (c == '\\') {
        c = peek();
        ++i_;
        if (c == 'u') {
          if (i_ + 4 > t_.size()) throw GiveUp{};
          const unsigned cp = unsigned(std::stoul(t_.substr(i_, 4), nullptr, 16));
          i_ += 4;
          if (cp < 0x80) {
            s += char(cp);
          } else {  // (not a field name: kept as a marker, enough to compare keys)
            s += "\\u" + t_.substr(i_ - 4, 4);
          }
          continue;
        }
        switch (c) {
          case 'n': c = '\n'; break;
          case 't': c = '\t'; break;
          case 'r': c = '\r'; break;
          case 'b': c = '\b'; break;
          case 'f': c = '\f'; break;
          default: break;  // " \\ /
        }
      }
      s += c;
    }
    ++i_;
    return s;
  }
  // A value we do not look into (a number, true, false, null, a string, or anything nested).
  void skip() {
    const char c = peek();
    if (c == '"') {
      string();
    } else if (c == '{' || c == '[') {
      const char close = c == '{' ? '}' : ']';
      ++i_;
      ws();
      if (peek() == close) {
        ++i_;
        return;
      }
      for (;;) {
        if (close == '}') {
          string();
          ws();
          expect(':');
          ws();
        }
        skip();
        ws();
        if (peek() == ',') {
          ++i_;
          ws();
          continue;
        }
        expect(close);
        return;
      }
    } else {
      while (i_ < t_.size() && std::string(",]} \t\r\n").find(t_[i_]) == std::string::npos) ++i_;
    }
  }
  static const char* kind(char c) {
    return c == '{' ? "an object" : c == '"' ? "a string" : (c == 't' || c == 'f') ? "a boolean" : "a number";
  }
  void object(const google::protobuf::Descriptor* d, const std::string& path) {
    expect('{');
    ws();
    std::set<std::string> seen;
    if (peek() == '}') {
      ++i_;
      return;
    }
    for (;;) {
      const std::string key = string();
      const auto* f = d ? d->FindFieldByName(key) : nullptr;
      if (d && !f) f = d->FindFieldByCamelcaseName(key);
      const std::string field = path.empty() ? (f ? f->name() : key) : path + "." + (f ? f->name() : key);
      if (!seen.insert(f ? f->name() : key).second) bad(field, "given twice (a key may appear once in an object)");
      ws();
      expect(':');
      ws();
      value(f, field);
      ws();
      if (peek() == ',') {
        ++i_;
        ws();
        continue;
      }
      expect('}');
      return;
    }
  }
  void value(const google::protobuf::FieldDescriptor* f, const std::string& field) {
    const char c = peek();
    if (c == 'n' && t_.compare(i_, 4, "null") == 0) {
      i_ += 4;
      return;
    }
    if (f && f->is_repeated()) {
      if (c != '[') bad(field, std::string("must be a list [...], got ") + kind(c));
      ++i_;
      ws();
      if (peek() == ']') {
        ++i_;
        return;
      }
      for (int k = 0;; ++k) {
        element(f, field + "[" + std::to_string(k) + "]");
        ws();
        if (peek() == ',') {
          ++i_;
          ws();
          continue;
        }
        expect(']');
        return;
      }
    }
    element(f, field);
  }
  void element(const google::protobuf::FieldDescriptor* f, const std::string& field) {
    if (f && f->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_MESSAGE && peek() == '{')
      object(f->message_type(), field);
    else
      skip();
  }
};

template <class E, std::size_t N>
E enum_of(const engine::NameTable<E, N>& t, const std::string& field, const std::string& value, const std::string& dflt) {
  try {
    return engine::parse_name(t, "value", value.empty() ? dflt : value);
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(field + ": " + e.what());
  }
}

double angle(const std::string& field, double deg) {
  if (!(deg >= 0 && deg < 90)) bad(field, "must lie in [0, 90) degrees, got " + num(deg));
  return deg * M_PI / 180.0;
}

}  // namespace

const std::vector<std::string>& raster_names() {
  static const std::vector<std::string> n = {"max_depth", "max_speed", "max_pressure", "deposit", "arrival_time"};
  return n;
}

v1::Scenario parse_scenario_json(const std::string& json) {
  v1::Scenario s;
  google::protobuf::util::JsonParseOptions opt;
  opt.ignore_unknown_fields = false;
  const auto st = google::protobuf::util::JsonStringToMessage(json, &s, opt);
  if (!st.ok()) throw ScenarioError("scenario JSON: " + std::string(st.message()));
  try {
    JsonShape(json).check();  // what protobuf's parser lets through: duplicate keys, a value for a list
  } catch (const ScenarioError& e) {
    throw ScenarioError("scenario JSON: " + std::string(e.what()));
  }
  return s;
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

// Engine "vof": the laboratory block, checked and completed with its defaults.
static ResolvedScenario resolve_lab(v1::Scenario s) {
  if (!s.has_lab()) bad("lab", "engine \"vof\" needs the lab block (domain, cells, fill, boundaries)");
  auto* l = s.mutable_lab();
  const double ext = kMaxLabExtent;
  auto coord = [&](const std::string& field, double v) { in_range(field, v, -ext, ext, "m"); };
  coord("lab.x_min", l->x_min());
  coord("lab.x_max", l->x_max());
  coord("lab.y_min", l->y_min());
  coord("lab.y_max", l->y_max());
  coord("lab.z_min", l->z_min());
  coord("lab.z_max", l->z_max());
  if (!(l->x_max() > l->x_min())) bad("lab.x_max", "must exceed lab.x_min");
  if (!(l->y_max() > l->y_min())) bad("lab.y_max", "must exceed lab.y_min");
  if (l->nx() < 2 || l->ny() < 2) bad("lab.nx", "lab.nx and lab.ny must be at least 2");
  if (l->nz() < 0) bad("lab.nz", "must be >= 0 (0: a plane set-up)");
  if (l->nz() > 0 && !(l->z_max() > l->z_min())) bad("lab.z_max", "must exceed lab.z_min");
  if (double(l->nx()) * l->ny() * std::max(1, l->nz()) > 4e6) bad("lab.nx", "more than 4 million cells");
  const bool three_d = l->nz() > 0;
  for (int k = 0; k < l->obstacles_size(); ++k) {
    const auto& o = l->obstacles(k);
    const std::string f = "lab.obstacles[" + std::to_string(k) + "]";
    for (int j = 0; j < o.polygon_xy_size(); ++j) coord(f + ".polygon_xy[" + std::to_string(j) + "]", o.polygon_xy(j));
    coord(f + ".x", o.x());
    coord(f + ".z", o.z());
    for (auto [name, v] : {std::pair<const char*, double>{"radius", o.radius()}, {"height", o.height()}, {"edge", o.edge()}})
      in_range(f + "." + name, v, 0, ext, "m");
    if (o.shape() == "polygon") {
      if (o.polygon_xy_size() < 6 || o.polygon_xy_size() % 2) bad(f + ".polygon_xy", "needs x, y pairs of at least 3 corners");
    } else if (o.shape() == "cylinder" || o.shape() == "tetrahedron-edge" || o.shape() == "tetrahedron-face") {
      if (!three_d) bad(f + ".shape", "'" + o.shape() + "' needs a 3D set-up (lab.nz > 0)");
      if (o.shape() == "cylinder" && !(o.radius() > 0 && o.height() > 0)) bad(f + ".radius", "a cylinder needs radius > 0 and height > 0");
      if (o.shape() != "cylinder" && !(o.edge() > 0)) bad(f + ".edge", "a tetrahedron needs edge > 0");
    } else {
      bad(f + ".shape", "unknown '" + o.shape() + "' (valid: polygon, cylinder, tetrahedron-edge, tetrahedron-face)");
    }
  }
  if (!(l->inclination_deg() > -90 && l->inclination_deg() < 90)) bad("lab.inclination_deg", "must lie in (-90, 90)");
  bool fed = false;
  for (const auto& b : l->boundaries()) fed |= b.kind() == "inflow";
  if (l->fill().empty() && !fed) bad("lab.fill", "at least one region of granular material is needed (or an inflow)");
  if (l->has_chute()) {
    const auto& c = l->chute();
    if (!three_d) bad("lab.chute", "a curved chute needs a 3D set-up (lab.nz > 0)");
    if (l->y_min() != 0) bad("lab.y_min", "must be 0 with a chute (y is the height above its bed)");
    if (!(c.bend_deg() > 0 && c.bend_deg() < 90)) bad("lab.chute.bend_deg", "must lie in (0, 90) deg");
    if (!(c.bend_end_m() > c.bend_start_m() && c.bend_start_m() > l->x_min())) bad("lab.chute.bend_end_m", "needs x_min < bend_start_m < bend_end_m");
    coord("lab.chute.bend_start_m", c.bend_start_m());
    coord("lab.chute.bend_end_m", c.bend_end_m());
    in_range("lab.chute.channel_radius_m", c.channel_radius_m(), 0, ext, "m", false, false, " (0: flat across)");
    // The normals of the bend meet at its centre of curvature: the mesh must stay below it.
    const double radius = (c.bend_end_m() - c.bend_start_m()) / (c.bend_deg() * 3.14159265358979323846 / 180);
    const double zmax = std::max(std::abs(l->z_min()), std::abs(l->z_max()));
    const double bed_max = c.channel_radius_m() > 0 ? zmax * zmax / (2 * c.channel_radius_m()) : 0;
    if (!(l->y_max() + bed_max < 0.9 * radius))
      bad("lab.y_max", "the mesh (" + std::to_string(l->y_max() + bed_max) + " m above the reference surface) must stay well below the bend's radius of curvature (" +
                           std::to_string(radius) + " m)");
    if (!l->obstacles().empty()) bad("lab.obstacles", "obstacles are not supported on a curved chute");
  }
  if (l->has_phi_deg() && !(l->phi_deg() > 0 && l->phi_deg() < 80)) bad("lab.phi_deg", "must lie in (0, 80) deg");
  if (l->has_bed_friction_deg() && !(l->bed_friction_deg() >= 0 && l->bed_friction_deg() < 80)) bad("lab.bed_friction_deg", "must lie in [0, 80) deg");
  for (int k = 0; k < l->fill_size(); ++k) {
    const auto& f = l->fill(k);
    const std::string fk = "lab.fill[" + std::to_string(k) + "]";
    coord(fk + ".x_min", f.x_min());
    coord(fk + ".x_max", f.x_max());
    coord(fk + ".y_min", f.y_min());
    coord(fk + ".y_max", f.y_max());
    coord(fk + ".cap_x", f.cap_x());
    coord(fk + ".cap_z", f.cap_z());
    in_range(fk + ".cap_radius", f.cap_radius(), 0, ext, "m");
    in_range(fk + ".cap_height", f.cap_height(), 0, ext, "m");
    for (int j = 0; j < f.polygon_xy_size(); ++j) coord(fk + ".polygon_xy[" + std::to_string(j) + "]", f.polygon_xy(j));
    if (f.cap_radius() != 0 || f.cap_height() != 0) {
      if (!three_d) bad("lab.fill[" + std::to_string(k) + "].cap_radius", "a spherical cap needs a 3D set-up (lab.nz > 0)");
      if (!(f.cap_radius() > 0 && f.cap_height() > 0 && f.cap_height() <= f.cap_radius()))
        bad("lab.fill[" + std::to_string(k) + "].cap_height", "a cap needs cap_radius > 0 and 0 < cap_height <= cap_radius");
    } else if (f.polygon_xy_size() > 0) {
      if (f.polygon_xy_size() < 6 || f.polygon_xy_size() % 2)
        bad("lab.fill[" + std::to_string(k) + "].polygon_xy", "needs x, y pairs of at least 3 corners");
    } else if (!(f.x_max() > f.x_min() && f.y_max() > f.y_min())) {
      bad("lab.fill[" + std::to_string(k) + "]", "needs x_max > x_min and y_max > y_min (or polygon_xy)");
    }
  }
  if (l->material().empty()) l->set_material("pvc");
  if (l->material() != "pvc" && l->material() != "sand" && l->material() != "fine-sand")
    bad("lab.material", "unknown '" + l->material() + "' (valid: pvc, sand, fine-sand)");
  in_range("lab.rotation_period_s", l->rotation_period_s(), 0, 1e6, "s", false, false, " (0: no rotation)");
  for (int k = 0; k < l->stations_x_size(); ++k) coord("lab.stations_x[" + std::to_string(k) + "]", l->stations_x(k));
  for (int k = 0; k < l->boundaries_size(); ++k) {
    const auto& b = l->boundaries(k);
    const std::string f = "lab.boundaries[" + std::to_string(k) + "]";
    if (b.has_from()) coord(f + ".from", b.from());
    if (b.has_to()) coord(f + ".to", b.to());
    in_range(f + ".inflow_u0", b.inflow_u0(), -100, 100, "m/s");
    in_range(f + ".inflow_dudy", b.inflow_dudy(), -1e4, 1e4, "1/s");
    in_range(f + ".inflow_height", b.inflow_height(), 0, ext, "m");
    if (b.side() != "bottom" && b.side() != "top" && b.side() != "left" && b.side() != "right" && b.side() != "obstacle" &&
        !(three_d && (b.side() == "back" || b.side() == "front")))
      bad(f + ".side", "unknown '" + b.side() + "' (valid: bottom, top, left, right, obstacle; 3D also back, front)");
    if (b.kind() != "wall" && b.kind() != "coulomb-slip" && b.kind() != "coulomb-friction" && b.kind() != "atmosphere" && b.kind() != "outflow" &&
        b.kind() != "inflow" && b.kind() != "symmetry")
      bad(f + ".kind", "unknown '" + b.kind() + "' (valid: wall, coulomb-slip, coulomb-friction, atmosphere, outflow, inflow, symmetry)");
    if (b.kind() == "inflow" && !(b.inflow_height() > 0)) bad(f + ".inflow_height", "an inflow needs a fill height > 0 m");
    if (b.kind() == "inflow" && b.side() != "left") bad(f + ".side", "inflow is supported on the left side only");
    if (b.has_from() && b.has_to() && !(b.to() > b.from())) bad(f + ".to", "must exceed from");
    if (l->has_chute() && (b.has_from() || b.has_to())) bad(f + ".from", "a curved chute takes whole sides only (no from/to)");
    if (l->has_chute() && b.kind() == "inflow") bad(f + ".kind", "inflow is not supported on a curved chute");
  }
  if (l->end_time_s() == 0) l->set_end_time_s(1.0);
  in_range("lab.end_time_s", l->end_time_s(), 0, kMaxLabTime, "s", true);
  if (l->write_interval_s() == 0) l->set_write_interval_s(0.05);
  in_range("lab.write_interval_s", l->write_interval_s(), 0, kMaxLabTime, "s");
  if (l->active_layers() == 0) l->set_active_layers(4);
  if (l->active_layers() < -1 || l->active_layers() > 1000) bad("lab.active_layers", "must be -1 (every cell) or 1-1000");
  in_range("lab.checkpoint_interval_s", l->checkpoint_interval_s(), 0, kMaxLabTime, "s", false, false, " (0: only when interrupted)");
  if (l->max_courant() == 0) l->set_max_courant(0.2);
  in_range("lab.max_courant", l->max_courant(), 0.01, 1);
  if (l->correctors() == 0) l->set_correctors(3);
  if (l->correctors() < 1 || l->correctors() > 50) bad("lab.correctors", "must lie in 1..50");
  // One outer corrector, the default, stays unset (the scenario, its hash and its results as before).
  if (l->has_outer_correctors() && (l->outer_correctors() < 1 || l->outer_correctors() > 20))
    bad("lab.outer_correctors", "must lie in 1..20");
  if (l->has_outer_correctors() && l->outer_correctors() == 1) l->clear_outer_correctors();
  if (l->pressure_coupling().empty()) l->set_pressure_coupling("piso");
  if (l->pressure_coupling() != "piso" && l->pressure_coupling() != "consistent")
    bad("lab.pressure_coupling", "unknown '" + l->pressure_coupling() + "' (valid: piso, consistent)");
  // Upwind, the default, stays unset, so that scenarios (and their hashes, checkpoints and cached
  // results) from before the option existed are the same scenarios.
  // The same for the Coulomb viscosity's pressure ("total"), the pressure preconditioner ("gamg")
  // and the walls' viscosity ("face"; results version 5 tells its results from the cell's).
  if (unset_default(l->momentum_convection(), "lab.momentum_convection", {"upwind", "limited_linear"})) l->clear_momentum_convection();
  if (unset_default(l->coulomb_pressure(), "lab.coulomb_pressure", {"total", "excess"})) l->clear_coulomb_pressure();
  if (unset_default(l->pressure_preconditioner(), "lab.pressure_preconditioner", {"gamg", "hypre"}))
    l->clear_pressure_preconditioner();
  if (unset_default(l->wall_viscosity(), "lab.wall_viscosity", {"face", "cell"})) l->clear_wall_viscosity();
  if (l->viscous_transpose().empty()) l->set_viscous_transpose("harmonic");
  if (l->viscous_transpose() != "explicit" && l->viscous_transpose() != "harmonic" && l->viscous_transpose() != "off")
    bad("lab.viscous_transpose", "unknown '" + l->viscous_transpose() + "' (valid: explicit, harmonic, off)");
  if (l->has_reference()) {
    const auto& ref = l->reference();
    auto check = [](bool has, double v, const char* name) {
      if (has && !(std::isfinite(v) && v >= 0)) bad(std::string("lab.reference.") + name, "must be a number >= 0");
    };
    check(ref.has_front_x_min(), std::abs(ref.front_x_min()), "front_x_min");
    check(ref.has_front_x_max(), std::abs(ref.front_x_max()), "front_x_max");
    check(ref.has_surface_angle_deg(), ref.surface_angle_deg(), "surface_angle_deg");
    check(ref.has_fluidised_time_s(), ref.fluidised_time_s(), "fluidised_time_s");
    check(ref.has_outflow_l_s(), ref.outflow_l_s(), "outflow_l_s");
    check(ref.has_gate_strain_rate_1_s(), ref.gate_strain_rate_1_s(), "gate_strain_rate_1_s");
    check(ref.has_depth_ratio_max(), ref.depth_ratio_max(), "depth_ratio_max");
    if (ref.has_front_x_min() != ref.has_front_x_max() || (ref.has_front_x_min() && ref.front_x_max() < ref.front_x_min()))
      bad("lab.reference.front_x_max", "the front is a range: give front_x_min and front_x_max >= front_x_min");
    if (ref.has_surface_angle_deg() && ref.surface_angle_deg() >= 90) bad("lab.reference.surface_angle_deg", "must lie below 90 deg");
  }
  require_finite(s, "");
  ResolvedScenario r;
  r.vof = true;
  r.scenario = std::move(s);
  return r;
}

ResolvedScenario resolve_scenario(v1::Scenario s, const std::string& base) {
  ResolvedScenario r;
  if (s.engine().empty()) s.set_engine("depth-averaged");
  if (s.engine() != "depth-averaged" && s.engine() != "vof") bad("engine", "unknown '" + s.engine() + "' (valid: depth-averaged, vof)");
  if (s.engine() == "vof") return resolve_lab(std::move(s));

  // DEM, area, grid.
  r.dem.dem_path = path_in(base, s.dem().path(), "dem.path");
  r.dem.dem_crs = s.dem().crs();
  r.input_files.push_back(r.dem.dem_path);
  // Companion files that change how the DEM reads (ESRI ASCII .prj) are part of the input.
  for (const char* ext : {".prj", ".hdr", ".tfw"}) {
    fs::path side = fs::path(r.dem.dem_path).replace_extension(ext);
    if (side != fs::path(r.dem.dem_path) && companion(side, "dem.path")) r.input_files.push_back(side.string());
  }
  if (companion(r.dem.dem_path + ".aux.xml", "dem.path")) r.input_files.push_back(r.dem.dem_path + ".aux.xml");  // GDAL's PAM file
  if (!s.area_of_interest().path().empty()) {
    r.dem.aoi_path = path_in(base, s.area_of_interest().path(), "area_of_interest.path");
    r.input_files.push_back(r.dem.aoi_path);
  }
  const auto& gcrs = s.grid().crs();
  if (!(gcrs.empty() || gcrs == "utm" || gcrs == "dem" || gcrs.rfind("EPSG:", 0) == 0))
    bad("grid.crs", "unknown '" + gcrs + "' (valid: \"utm\" (default), \"dem\", \"EPSG:<code>\")");
  r.dem.target_crs = gcrs;
  if (s.grid().resolution_m() != 0)
    in_range("grid.resolution_m", s.grid().resolution_m(), 0, kMaxCell, "m", true, false, " (0 or unset: the DEM's)");
  r.dem.resolution = s.grid().resolution_m();
  static const std::vector<std::string> resamplings = {"near", "bilinear", "cubic", "cubicspline", "lanczos", "average"};
  if (s.grid().resampling().empty()) s.mutable_grid()->set_resampling("cubic");
  if (std::find(resamplings.begin(), resamplings.end(), s.grid().resampling()) == resamplings.end())
    bad("grid.resampling", "unknown '" + s.grid().resampling() + "' (valid: near, bilinear, cubic, cubicspline, lanczos, average)");
  r.dem.resampling = s.grid().resampling();

  // Releases.
  if (s.releases().empty()) bad("releases", "at least one release is needed");
  for (int k = 0; k < s.releases_size(); ++k) {
    const auto& rl = s.releases(k);
    const std::string f = "releases[" + std::to_string(k) + "]";
    terrain::ReleaseRequest q;
    q.path = path_in(base, rl.path(), f + ".path");
    r.input_files.push_back(q.path);
    for (const char* ext : {".shx", ".dbf", ".prj", ".cpg"}) {
      fs::path side = fs::path(q.path).replace_extension(ext);
      if (fs::path(q.path).extension() == ".shp" && companion(side, f + ".path")) r.input_files.push_back(side.string());
    }
    q.has_thickness = rl.has_thickness_m();
    q.thickness = rl.thickness_m();
    q.thickness_attribute = rl.thickness_attribute();
    if (q.has_thickness && !(q.thickness > 0 && q.thickness <= kMaxThickness))
      bad(f + ".thickness_m", "must be > 0 m and at most " + num(kMaxThickness) + " m, got " + num(q.thickness));
    if (!q.has_thickness && q.thickness_attribute.empty())
      bad(f, "needs thickness_m or thickness_attribute");
    if (!(rl.thickness_measured().empty() || rl.thickness_measured() == "normal" || rl.thickness_measured() == "vertical"))
      bad(f + ".thickness_measured", "unknown '" + rl.thickness_measured() + "' (valid: normal, vertical)");
    q.vertical = rl.thickness_measured() == "vertical";
    q.has_min_slope = rl.has_min_slope_deg();
    q.min_slope = rl.min_slope_deg();
    q.has_max_slope = rl.has_max_slope_deg();
    q.max_slope = rl.max_slope_deg();
    if (q.has_min_slope && !(q.min_slope >= 0 && q.min_slope < 90)) bad(f + ".min_slope_deg", "must lie in [0, 90) deg, got " + num(q.min_slope));
    if (q.has_max_slope && !(q.max_slope > 0 && q.max_slope <= 90)) bad(f + ".max_slope_deg", "must lie in (0, 90] deg, got " + num(q.max_slope));
    if (q.has_min_slope && q.has_max_slope && !(q.min_slope < q.max_slope))
      bad(f, "min_slope_deg must be below max_slope_deg");
    q.crs = rl.crs();
    q.min_slope_attribute = rl.min_slope_attribute();
    q.max_slope_attribute = rl.max_slope_attribute();
    r.releases.push_back(q);
  }

  // Material.
  auto* m = s.mutable_material();
  auto& mat = r.config.material;
  mat.rheology = enum_of(engine::kRheologyNames, "material.rheology", m->rheology(), "coulomb");
  if (m->rheology().empty()) m->set_rheology("coulomb");
  if (m->density_kg_m3() == 0) m->set_density_kg_m3(300);
  in_range("material.density_kg_m3", m->density_kg_m3(), 0, kMaxDensity, "kg/m3", true);
  mat.density = m->density_kg_m3();
  // Every value given is checked, also one the rheology does not use.
  const double delta = m->has_bed_friction_deg() ? angle("material.bed_friction_deg", m->bed_friction_deg()) : 0.0;
  if (m->has_voellmy_mu() && !(m->voellmy_mu() >= 0 && m->voellmy_mu() < 5))
    bad("material.voellmy_mu", "must lie in [0, 5), got " + num(m->voellmy_mu()));
  if (m->has_voellmy_xi()) in_range("material.voellmy_xi", m->voellmy_xi(), 0, kMaxXi, "m/s^2", true);
  if (mat.rheology == engine::Rheology::coulomb) {
    if (!m->has_bed_friction_deg()) bad("material.bed_friction_deg", "needed by the coulomb rheology");
    mat.delta = delta;
  } else {
    if (!m->has_voellmy_mu()) bad("material.voellmy_mu", "needed by the voellmy rheology");
    if (!m->has_voellmy_xi()) bad("material.voellmy_xi", "needed by the voellmy rheology");
    mat.mu = m->voellmy_mu();
    mat.xi = m->voellmy_xi();
  }
  mat.earth_pressure = enum_of(engine::kEarthPressureNames, "material.earth_pressure", m->earth_pressure(), "unity");
  if (m->earth_pressure().empty()) m->set_earth_pressure("unity");
  if (m->has_internal_friction_deg()) mat.phi = angle("material.internal_friction_deg", m->internal_friction_deg());
  if (mat.earth_pressure == engine::EarthPressure::active_passive && !m->has_internal_friction_deg())
    bad("material.internal_friction_deg", "needed by earth_pressure active-passive");
  try {
    mat.validate();
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(e.what());
  }

  // Numerics.
  auto* nm = s.mutable_numerics();
  if (nm->scheme().empty()) nm->set_scheme("noc-tvd");
  if (nm->scheme() != "noc-tvd")
    bad("numerics.scheme", "unknown value '" + nm->scheme() + "' (valid: noc-tvd)");
  r.config.limiter = enum_of(engine::kLimiterNames, "numerics.limiter", nm->limiter(), "minmod");
  if (nm->limiter().empty()) nm->set_limiter("minmod");
  if (!nm->has_cfl()) nm->set_cfl(0.45);
  in_range("numerics.cfl", nm->cfl(), 0.01, 0.5);
  if (!nm->has_end_time_s()) nm->set_end_time_s(600);
  in_range("numerics.end_time_s", nm->end_time_s(), 0, kMaxEndTime, "s", true);
  if (!nm->has_stop_fraction()) nm->set_stop_fraction(0.01);
  if (!(nm->stop_fraction() >= 0 && nm->stop_fraction() < 1))
    bad("numerics.stop_fraction", "must lie in [0, 1), got " + num(nm->stop_fraction()));
  const auto b = enum_of(engine::kBoundary2DNames, "numerics.boundary", nm->boundary(), "outflow");
  if (nm->boundary().empty()) nm->set_boundary("outflow");
  r.config.west = r.config.east = r.config.south = r.config.north = b;
  r.config.time.cfl = nm->cfl();
  r.config.time.t_end = nm->end_time_s();
  r.config.time.stop_fraction = nm->stop_fraction();
  r.config.curvature = !nm->curvature_off();

  // Outputs.
  auto* o = s.mutable_outputs();
  if (o->rasters().empty())
    for (const auto& n : raster_names()) o->add_rasters(n);
  for (const auto& n : o->rasters()) {
    if (std::find(raster_names().begin(), raster_names().end(), n) == raster_names().end())
      bad("outputs.rasters", "unknown '" + n + "' (valid: max_depth, max_speed, max_pressure, deposit, arrival_time)");
    r.rasters.push_back(n);
  }
  if (!o->has_outline_threshold_m()) o->set_outline_threshold_m(0.1);
  in_range("outputs.outline_threshold_m", o->outline_threshold_m(), 0, kMaxDepthThreshold, "m", true);
  r.outline_threshold = o->outline_threshold_m();
  if (!o->has_flow_threshold_m()) o->set_flow_threshold_m(0.01);
  in_range("outputs.flow_threshold_m", o->flow_threshold_m(), 0, kMaxDepthThreshold, "m", true);
  r.config.flow_threshold = o->flow_threshold_m();
  in_range("outputs.timeseries_interval_s", o->timeseries_interval_s(), 0, kMaxEndTime, "s", false, false, " (0: none)");
  r.timeseries_interval = o->timeseries_interval_s();
  require_finite(s, "");
  r.scenario = std::move(s);
  return r;
}

std::string scenario_hash(const ResolvedScenario& r, int depth_averaged_version, int vof_version) {
  v1::Scenario s = r.scenario;
  s.mutable_dem()->clear_path();
  s.mutable_area_of_interest()->clear_path();
  for (auto& rel : *s.mutable_releases()) rel.clear_path();
  s.clear_limits();  // a job's limits do not change what it computes
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
  if (r.vof) h.update("\nvof results " + std::to_string(vof_version));
  else h.update("\ndepth-averaged results " + std::to_string(depth_averaged_version));
  for (const auto& f : r.input_files) {
    h.update("\n");
    h.update(fs::path(f).extension().string());
    h.update(" ");
    h.update(sha256_file(f));
  }
  return h.hex();
}

}  // namespace runout::jobs
