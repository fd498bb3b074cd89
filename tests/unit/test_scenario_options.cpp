// The scenario option tables (jobs/scenario/options.hpp): every field declared once, the tables'
// ranges and names refused with the field, the value and the valid ones, defaults that keep their
// hashes, the generated reference page current, and no silent fallback for an unknown name at any
// layer (scenario, friction laws, name tables, lab materials).
#include <gtest/gtest.h>

#include <google/protobuf/descriptor.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "engine/friction/registry.hpp"
#include "engine/limiters.hpp"
#include "engine/rheology.hpp"
#include "engine/sh2d.hpp"
#include "jobs/scenario/inputs.hpp"
#include "jobs/scenario/options.hpp"
#include "jobs/scenario/scenario.hpp"

using namespace runout;
using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

namespace {

const std::string kSrc = RUNOUT_SOURCE_DIR;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

v1::Scenario arelen() { return jobs::parse_scenario_json(read_text(kSrc + "/tests/data/arelen-30m.json")); }
v1::Scenario b10() { return jobs::parse_scenario_json(read_text(kSrc + "/scenarios/lab/b10-column-a0.5.json")); }
const std::string kDataDir = kSrc + "/tests/data";
const std::string kLabDir = kSrc + "/scenarios/lab";

std::string resolve_error(const v1::Scenario& s, const std::string& base) {
  try {
    jobs::resolve_scenario(s, base);
  } catch (const jobs::ScenarioError& e) {
    return e.what();
  }
  return "";
}

std::vector<const jobs::OptionTable*> tables() {
  return {&jobs::scenario_options(), &jobs::depth_averaged_options(), &jobs::lab_options(), &jobs::terrain_vof_options()};
}

// Every scalar field under `d` (paths as the tables spell them; "[]" for lists).
void leaves(const Descriptor* d, const std::string& prefix, std::set<std::string>& out) {
  for (int k = 0; k < d->field_count(); ++k) {
    const FieldDescriptor* f = d->field(k);
    std::string p = (prefix.empty() ? "" : prefix + ".") + f->name();
    const bool list = f->is_repeated();
    if (f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      leaves(f->message_type(), p + (list ? "[]" : ""), out);
    } else {
      out.insert(p + (list && f->cpp_type() != FieldDescriptor::CPPTYPE_STRING ? "[]" : ""));
    }
  }
}

// The field at a path without "[]", created on the way.
std::pair<Message*, const FieldDescriptor*> field_at(Message& m, const std::string& path) {
  const auto dot = path.find('.');
  std::string seg = path.substr(0, dot);
  const bool each = seg.size() > 2 && seg.compare(seg.size() - 2, 2, "[]") == 0;  // a list of blocks: its first
  if (each) seg.resize(seg.size() - 2);
  const auto* f = m.GetDescriptor()->FindFieldByName(seg);
  if (dot == std::string::npos) return {&m, f};
  auto* next = each ? m.GetReflection()->MutableRepeatedMessage(&m, f, 0) : m.GetReflection()->MutableMessage(&m, f);
  return field_at(*next, path.substr(dot + 1));
}

// As field_at, adding the first element of a list of blocks where there is none.
std::pair<Message*, const FieldDescriptor*> field_made(Message& m, const std::string& path) {
  const auto dot = path.find('.');
  std::string seg = path.substr(0, dot);
  const bool each = seg.size() > 2 && seg.compare(seg.size() - 2, 2, "[]") == 0;
  if (each) seg.resize(seg.size() - 2);
  const auto* f = m.GetDescriptor()->FindFieldByName(seg);
  if (dot == std::string::npos) return {&m, f};
  const auto* r = m.GetReflection();
  auto* next = !each ? r->MutableMessage(&m, f) : r->FieldSize(m, f) > 0 ? r->MutableRepeatedMessage(&m, f, 0) : r->AddMessage(&m, f);
  return field_made(*next, path.substr(dot + 1));
}

// The base scenario and its folder of an option's table.
std::pair<v1::Scenario, std::string> base_of(const jobs::OptionTable* t) {
  if (t == &jobs::lab_options()) return {b10(), kLabDir};
  if (t == &jobs::terrain_vof_options()) {  // the 3D engine on the same DEM
    auto s = arelen();
    s.set_engine("vof");
    s.mutable_material()->set_internal_friction_deg(20);
    return {s, kDataDir};
  }
  return {arelen(), kDataDir};
}

}  // namespace

// Every option that names an input file is in the list of input fields (jobs/scenario/inputs.hpp)
// that the service's client uploads and an ensemble makes absolute: one missing there would reach
// the server as a path on the client's machine.
TEST(ScenarioOptions, EveryInputFileFieldIsInTheInputList) {
  int paths = 0;
  for (const auto* t : tables())
    for (const auto& o : *t) {
      if (o.type != jobs::OptionType::path) continue;
      ++paths;
      v1::Scenario s;
      auto [m, f] = field_made(s, o.path);
      m->GetReflection()->SetString(m, f, "marker.file");
      int seen = 0;
      jobs::for_each_input_path(s, [&](const std::string&, std::string* p) { seen += *p == "marker.file"; });
      EXPECT_EQ(seen, 1) << o.path;
    }
  EXPECT_GE(paths, 8);
}

TEST(ScenarioOptions, EveryFieldIsDeclaredOnceInOneTable) {
  std::set<std::string> fields, declared;
  leaves(v1::Scenario::descriptor(), "", fields);
  for (const auto* t : tables())
    for (const auto& o : *t) {
      EXPECT_TRUE(declared.insert(o.path).second) << o.path << " is declared twice";
      EXPECT_TRUE(fields.count(o.path)) << o.path << " is no field of runout.v1.Scenario";
      EXPECT_FALSE(o.doc.empty()) << o.path;
    }
  for (const auto& f : fields) EXPECT_TRUE(declared.count(f)) << f << " is in scenario.proto but in no option table";
}

TEST(ScenarioOptions, ReferencePageIsCurrent) {
  const std::string page = kSrc + "/docs/user/scenario-reference.md";
  EXPECT_EQ(read_text(page), jobs::scenario_reference_markdown())
      << page << " is stale: regenerate it with\n  build-opt/bin/runout_scenario_tool reference > docs/user/scenario-reference.md";
}

// Every choice of the tables outside lists: an unknown name is refused with the field, the name and
// every valid one (no fallback to the default).
TEST(ScenarioOptions, AnUnknownNameIsRefusedWithTheValidOnes) {
  int tried = 0;
  for (const auto* t : tables())
    for (const auto& o : *t) {
      if (o.path.find("[]") != std::string::npos || o.choices.empty() || o.path == "engine") continue;
      auto [s, dir] = base_of(t);
      auto [m, f] = field_at(s, o.path);
      if (f->is_repeated()) m->GetReflection()->AddString(m, f, "no-such-name");
      else m->GetReflection()->SetString(m, f, "no-such-name");
      const auto e = resolve_error(s, dir);
      EXPECT_EQ(e, o.path + ": unknown 'no-such-name' (valid: " + jobs::join_names(o.choices) + ")") << o.path;
      ++tried;
    }
  EXPECT_GE(tried, 14);
  v1::Scenario s = arelen();
  s.set_engine("lbm");
  EXPECT_EQ(resolve_error(s, kDataDir), "engine: unknown 'lbm' (valid: depth-averaged, vof)");
}

TEST(ScenarioOptions, UnknownNamesInListsAreRefused) {
  v1::Scenario s = b10();
  s.mutable_lab()->mutable_boundaries(0)->set_kind("slip");
  EXPECT_EQ(resolve_error(s, kLabDir),
            "lab.boundaries[0].kind: unknown 'slip' (valid: wall, coulomb-slip, coulomb-friction, atmosphere, outflow, inflow, symmetry)");
  s = b10();
  s.mutable_lab()->mutable_boundaries(1)->set_side("east");
  EXPECT_EQ(resolve_error(s, kLabDir), "lab.boundaries[1].side: unknown 'east' (valid: bottom, top, left, right, back, front, obstacle)");
  s = b10();
  s.mutable_lab()->mutable_boundaries(1)->set_side("back");
  EXPECT_EQ(resolve_error(s, kLabDir), "lab.boundaries[1].side: 'back' needs a 3D set-up (lab.nz > 0)");
  s = b10();
  s.mutable_lab()->add_obstacles()->set_shape("cube");
  EXPECT_EQ(resolve_error(s, kLabDir), "lab.obstacles[0].shape: unknown 'cube' (valid: polygon, cylinder, tetrahedron-edge, tetrahedron-face)");
  s = arelen();
  s.mutable_releases(0)->set_thickness_measured("slope");
  EXPECT_EQ(resolve_error(s, kDataDir), "releases[0].thickness_measured: unknown 'slope' (valid: normal, vertical)");
  s = arelen();
  s.mutable_grid()->set_crs("LV95");
  EXPECT_EQ(resolve_error(s, kDataDir), "grid.crs: unknown 'LV95' (valid: utm, dem, EPSG:<code>)");
}

// Every number with a range outside lists: just above the range, NaN and infinity are refused with
// the field, the range and the value.
TEST(ScenarioOptions, ValuesOutsideTheRangeAreRefusedWithTheRange) {
  int tried = 0;
  for (const auto* t : tables())
    for (const auto& o : *t) {
      if (o.path.find("[]") != std::string::npos || !o.range || !std::isfinite(o.range->hi)) continue;
      for (double v : {o.range->hi + 1, -o.range->hi - 1e9}) {
        auto [s, dir] = base_of(t);
        auto [m, f] = field_at(s, o.path);
        if (f->cpp_type() == FieldDescriptor::CPPTYPE_DOUBLE) m->GetReflection()->SetDouble(m, f, v);
        else m->GetReflection()->SetInt32(m, f, int(v));
        const auto e = resolve_error(s, dir);
        EXPECT_EQ(e.rfind(o.path + ": must lie in ", 0), 0u) << o.path << ": " << e;
        EXPECT_NE(e.find(", got "), std::string::npos) << e;
        ++tried;
      }
    }
  EXPECT_GE(tried, 40);
}

// Options kept unset when they equal their default: giving the default is the same scenario.
TEST(ScenarioOptions, GivingAKeptDefaultKeepsTheHash) {
  for (const auto* t : tables())
    for (const auto& o : *t) {
      if (o.unset != jobs::Unset::keep) continue;
      auto [s, dir] = base_of(t);
      const auto h0 = jobs::scenario_hash(jobs::resolve_scenario(s, dir));
      auto [m, f] = field_at(s, o.path);
      if (f->cpp_type() == FieldDescriptor::CPPTYPE_STRING) m->GetReflection()->SetString(m, f, o.default_value);
      else if (f->cpp_type() == FieldDescriptor::CPPTYPE_DOUBLE) m->GetReflection()->SetDouble(m, f, std::stod(o.default_value));
      else if (f->cpp_type() == FieldDescriptor::CPPTYPE_BOOL) m->GetReflection()->SetBool(m, f, o.default_value == "true");
      else m->GetReflection()->SetInt32(m, f, std::stoi(o.default_value));
      EXPECT_EQ(jobs::scenario_hash(jobs::resolve_scenario(s, dir)), h0) << o.path;
    }
}

TEST(ScenarioOptions, FrictionLawsAreOneTable) {
  EXPECT_EQ(&engine::friction_law("coulomb"), &engine::friction::coulomb);
  EXPECT_EQ(&engine::friction_law("voellmy"), &engine::friction::voellmy);
  try {
    engine::friction_law("bingham");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "unknown friction law 'bingham' (valid: coulomb, voellmy, pouliquen_forterre, mu_i)");
  }
  // The coefficients are today's expressions, bit for bit.
  engine::FrictionParams p;
  p.delta = 0.4;
  p.mu = 0.2;
  p.xi = 1500;
  EXPECT_EQ(engine::friction::coulomb.coefficients(p).mu, std::tan(0.4));
  EXPECT_EQ(engine::friction::coulomb.coefficients(p).inv_xi, 0.0);
  EXPECT_EQ(engine::friction::voellmy.coefficients(p).mu, 0.2);
  EXPECT_EQ(engine::friction::voellmy.coefficients(p).inv_xi, 1.0 / 1500);
  // A law's parameters come from the scenario fields it names.
  v1::Scenario s = arelen();
  s.mutable_material()->set_rheology("voellmy");
  s.mutable_material()->set_voellmy_mu(0.2);
  EXPECT_EQ(resolve_error(s, kDataDir), "material.voellmy_xi: needed by the voellmy rheology");
  s.mutable_material()->set_voellmy_xi(1500);
  const auto r = jobs::resolve_scenario(s, kDataDir);
  EXPECT_EQ(r.config.material.rheology, &engine::friction::voellmy);
  EXPECT_EQ(r.config.material.coulomb_coefficient(), 0.2);
  s.mutable_material()->set_rheology("bingham");
  EXPECT_EQ(resolve_error(s, kDataDir), "material.rheology: unknown 'bingham' (valid: coulomb, voellmy, pouliquen_forterre, mu_i)");
}

// The flow-dependent laws: their fields in radians and SI, the optional ones unset, and every bad
// value refused with the field.
TEST(ScenarioOptions, FlowDependentLawsTakeTheirFields) {
  v1::Scenario s = arelen();
  auto* m = s.mutable_material();
  m->set_rheology("pouliquen_forterre");
  m->set_bed_friction_1_deg(20.9);
  m->set_bed_friction_2_deg(32.76);
  m->set_pf_beta(0.136);
  EXPECT_EQ(resolve_error(s, kDataDir), "material.pf_length_m: needed by the pouliquen_forterre rheology");
  m->set_pf_length_m(0.5);
  auto r = jobs::resolve_scenario(s, kDataDir);
  const auto& mat = r.config.material;
  EXPECT_EQ(mat.rheology, &engine::friction::pouliquen_forterre);
  EXPECT_DOUBLE_EQ(mat.delta1, 20.9 * M_PI / 180);
  EXPECT_TRUE(std::isnan(mat.delta3));  // delta_1: no start/stop hysteresis
  EXPECT_EQ(mat.pf_gamma, 0.0);
  EXPECT_EQ(mat.friction().form(), engine::MuForm::flow);
  m->set_bed_friction_3_deg(23);
  m->set_pf_gamma(0.05);
  r = jobs::resolve_scenario(s, kDataDir);
  EXPECT_EQ(r.config.material.friction().form(), engine::MuForm::hysteresis);
  EXPECT_EQ(r.config.material.pf_gamma, 0.05);
  auto refused = [&](auto change, const std::string& field) {
    v1::Scenario bad = s;
    change(*bad.mutable_material());
    const std::string e = resolve_error(bad, kDataDir);
    EXPECT_NE(e.find(field), std::string::npos) << e;
  };
  refused([](v1::Material& x) { x.set_bed_friction_2_deg(20); }, "bed_friction_2_deg");
  refused([](v1::Material& x) { x.set_bed_friction_3_deg(15); }, "bed_friction_3_deg");
  refused([](v1::Material& x) { x.set_pf_gamma(0.2); }, "pf_gamma");
  refused([](v1::Material& x) { x.set_pf_gamma(-1); }, "material.pf_gamma: must lie in [0, 10]");
  refused([](v1::Material& x) { x.set_pf_beta(0); }, "material.pf_beta: must lie in (0, 10]");
  refused([](v1::Material& x) { x.set_pf_length_m(0); }, "material.pf_length_m: must lie in (0, 100] m");
  s = arelen();
  m = s.mutable_material();
  m->set_rheology("mu_i");
  m->set_mu_s(0.38);
  m->set_mu_2(0.64);
  m->set_mu_i0(0.279);
  m->set_grain_diameter_m(0.5e-3);
  EXPECT_EQ(resolve_error(s, kDataDir), "material.grain_density_kg_m3: needed by the mu_i rheology");
  m->set_grain_density_kg_m3(2450);
  r = jobs::resolve_scenario(s, kDataDir);
  EXPECT_EQ(r.config.material.rheology, &engine::friction::mu_i);
  EXPECT_EQ(r.config.material.grain_diameter, 0.5e-3);
  EXPECT_EQ(r.config.material.friction().form(), engine::MuForm::flow);
  refused([](v1::Material& x) { x.set_mu_2(0.3); }, "mu_2");
  refused([](v1::Material& x) { x.set_density_kg_m3(3000); }, "grain_density_kg_m3");
  refused([](v1::Material& x) { x.set_mu_i0(0); }, "material.mu_i0: must lie in (0, 10]");
  refused([](v1::Material& x) { x.set_grain_diameter_m(-1); }, "material.grain_diameter_m: must lie in (0, 100] m");
}

TEST(ScenarioOptions, NameTablesHaveNoFallback) {
  EXPECT_THROW(engine::parse_name(engine::kBoundary2DNames, "boundary", "periodic"), std::invalid_argument);
  EXPECT_THROW(engine::parse_name(engine::kEarthPressureNames, "earth pressure", "rankine"), std::invalid_argument);
  EXPECT_THROW(engine::name_of(engine::kLimiterNames, engine::Limiter(7)), std::logic_error);
  EXPECT_EQ(engine::name_of(engine::kLimiterNames, engine::Limiter::superbee), "superbee");
  engine::Material m;
  m.rheology = nullptr;
  EXPECT_THROW(m.validate(), std::invalid_argument);
}

TEST(ScenarioOptions, LabMaterialsByNameWithoutFallback) {
  EXPECT_EQ(jobs::lab_material("").name, "pvc");
  EXPECT_EQ(jobs::lab_material("fine-sand").rho, 1855);
  try {
    jobs::lab_material("glass-beads");
    FAIL();
  } catch (const jobs::ScenarioError& e) {
    EXPECT_STREQ(e.what(), "lab.material: unknown 'glass-beads' (valid: pvc, sand, fine-sand)");
  }
  v1::Scenario s = b10();
  s.mutable_lab()->set_material("glass-beads");
  EXPECT_EQ(resolve_error(s, kLabDir), "lab.material: unknown 'glass-beads' (valid: pvc, sand, fine-sand)");
}

// The bundled scenarios' hashes, recorded before the option tables replaced the hand-written
// resolver: the tables' defaults reproduce them. (A results version enters its engine's hashes: a
// bump, or an edit of a file, records that file's hash anew.)
TEST(ScenarioOptions, BundledScenarioHashesAreUnchanged) {
  const std::vector<std::pair<std::string, std::string>> pinned = {
#include "tests/unit/scenario_hashes.inc"
  };
  ASSERT_FALSE(pinned.empty());
  for (const auto& [file, hash] : pinned) {
    if (!std::ifstream(kSrc + "/" + file)) continue;  // a scenario removed since
    EXPECT_EQ(jobs::scenario_hash(jobs::load_scenario(kSrc + "/" + file)), hash) << file;
  }
}
