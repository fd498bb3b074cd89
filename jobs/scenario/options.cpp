#include "jobs/scenario/options.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/reflection.h>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "jobs/scenario/scenario.hpp"
#include "jobs/scenario/scenario_impl.hpp"

namespace runout::jobs {

namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

// One place an option occurs: a field of a message, or one element of a repeated scalar field.
struct Location {
  Message* msg;
  const FieldDescriptor* f;
  int index;          // element of a repeated field; -1: the field itself
  std::string label;  // "releases[0].thickness_m"
};

// Every place `path` (from `at` on) occurs in `m`. A missing sub-message is created only when the
// option fills a default into it (as the resolver always did), else skipped.
void locate(Message& m, std::string_view path, const std::string& prefix, bool create, std::vector<Location>& out) {
  const auto dot = path.find('.');
  std::string_view seg = path.substr(0, dot);
  const bool each = seg.size() > 2 && seg.substr(seg.size() - 2) == "[]";
  if (each) seg.remove_suffix(2);
  const FieldDescriptor* f = m.GetDescriptor()->FindFieldByName(std::string(seg));
  if (!f) throw std::logic_error("scenario option table: no field '" + std::string(path) + "' under '" + prefix + "'");
  const std::string name = prefix.empty() ? f->name() : prefix + "." + f->name();
  const auto* refl = m.GetReflection();
  if (dot == std::string_view::npos) {
    if (each) {
      for (int k = 0; k < refl->FieldSize(m, f); ++k) out.push_back({&m, f, k, name + "[" + std::to_string(k) + "]"});
    } else {
      out.push_back({&m, f, -1, name});
    }
    return;
  }
  const auto rest = path.substr(dot + 1);
  if (each) {
    for (int k = 0; k < refl->FieldSize(m, f); ++k)
      locate(*refl->MutableRepeatedMessage(&m, f, k), rest, name + "[" + std::to_string(k) + "]", create, out);
  } else if (create || refl->HasField(m, f)) {
    locate(*refl->MutableMessage(&m, f), rest, name, create, out);
  }
}

bool is_set(const Location& l) {
  const auto* refl = l.msg->GetReflection();
  if (l.index >= 0) return true;
  if (l.f->is_repeated()) return refl->FieldSize(*l.msg, l.f) > 0;
  if (l.f->has_presence()) return refl->HasField(*l.msg, l.f);
  switch (l.f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE: return refl->GetDouble(*l.msg, l.f) != 0;
    case FieldDescriptor::CPPTYPE_FLOAT: return refl->GetFloat(*l.msg, l.f) != 0;
    case FieldDescriptor::CPPTYPE_INT32: return refl->GetInt32(*l.msg, l.f) != 0;
    case FieldDescriptor::CPPTYPE_INT64: return refl->GetInt64(*l.msg, l.f) != 0;
    case FieldDescriptor::CPPTYPE_BOOL: return refl->GetBool(*l.msg, l.f);
    case FieldDescriptor::CPPTYPE_STRING: return !refl->GetString(*l.msg, l.f).empty();
    default: return true;
  }
}

double number(const Location& l) {
  const auto* refl = l.msg->GetReflection();
  switch (l.f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE:
      return l.index >= 0 ? refl->GetRepeatedDouble(*l.msg, l.f, l.index) : refl->GetDouble(*l.msg, l.f);
    case FieldDescriptor::CPPTYPE_INT32: return refl->GetInt32(*l.msg, l.f);
    case FieldDescriptor::CPPTYPE_INT64: return double(refl->GetInt64(*l.msg, l.f));
    case FieldDescriptor::CPPTYPE_UINT64: return double(refl->GetUInt64(*l.msg, l.f));
    default: throw std::logic_error("scenario option table: " + l.label + " is not a number");
  }
}

void set_default(const Option& o, const Location& l) {
  const auto* refl = l.msg->GetReflection();
  switch (l.f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE: refl->SetDouble(l.msg, l.f, std::stod(o.default_value)); break;
    case FieldDescriptor::CPPTYPE_INT32: refl->SetInt32(l.msg, l.f, std::stoi(o.default_value)); break;
    case FieldDescriptor::CPPTYPE_STRING:
      if (l.f->is_repeated()) {
        for (const auto& c : o.choices) refl->AddString(l.msg, l.f, c);
      } else {
        refl->SetString(l.msg, l.f, o.default_value);
      }
      break;
    default: throw std::logic_error("scenario option table: no default for " + l.label);
  }
}

bool equals_default(const Option& o, const Location& l) {
  if (o.default_value.empty()) return false;
  if (l.f->cpp_type() == FieldDescriptor::CPPTYPE_STRING) return l.msg->GetReflection()->GetString(*l.msg, l.f) == o.default_value;
  if (l.f->cpp_type() == FieldDescriptor::CPPTYPE_BOOL) return l.msg->GetReflection()->GetBool(*l.msg, l.f) == (o.default_value == "true");
  return number(l) == std::stod(o.default_value);
}

bool is_choice(const Option& o, const std::string& v) {
  for (const auto& c : o.choices) {
    const auto open = c.find('<');
    if (open == std::string::npos ? v == c : v.size() > open && v.compare(0, open, c, 0, open) == 0) return true;
  }
  return false;
}

void check_choice(const Option& o, const std::string& label, const std::string& v) {
  if (!is_choice(o, v)) bad(label, "unknown '" + v + "' (valid: " + join_names(o.choices) + ")");
}

void check(const Option& o, const Location& l) {
  const auto* refl = l.msg->GetReflection();
  if (o.type == OptionType::choice) {
    check_choice(o, l.label, refl->GetString(*l.msg, l.f));
  } else if (o.type == OptionType::choice_list) {
    for (int k = 0; k < refl->FieldSize(*l.msg, l.f); ++k) check_choice(o, l.label, refl->GetRepeatedString(*l.msg, l.f, k));
  } else if (o.range) {
    const Range& r = *o.range;
    const double v = number(l);
    const bool ok = std::isfinite(v) && (r.lo_open ? v > r.lo : v >= r.lo) && (r.hi_open ? v < r.hi : v <= r.hi);
    if (!ok)
      bad(l.label, "must lie in " + range_text(r, o.type) + (o.unit.empty() ? "" : " " + o.unit) +
                       (o.zero.empty() ? "" : " (0: " + o.zero + ")") + ", got " + num(v));
  }
}

}  // namespace

// Integers as lo..hi (every whole number between), numbers as intervals.
std::string range_text(const Range& r, OptionType type) {
  if (type == OptionType::integer && std::isfinite(r.lo) && std::isfinite(r.hi))
    return std::to_string((long long)r.lo) + ".." + std::to_string((long long)r.hi);
  return (r.lo_open ? "(" : "[") + num(r.lo) + ", " + num(r.hi) + (r.hi_open || std::isinf(r.hi) ? ")" : "]");
}

std::string join_names(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

const Option& option(const OptionTable& table, const std::string& path) {
  for (const auto& o : table)
    if (o.path == path) return o;
  throw std::out_of_range("no scenario option '" + path + "'");
}

void apply_option_rules(const OptionTable& table, v1::Scenario& s) {
  for (const auto& o : table) {
    std::vector<Location> at;
    locate(s, o.path, "", o.unset == Unset::fill, at);
    for (const auto& l : at) {
      if (!is_set(l)) {
        if (o.unset == Unset::required) bad(l.label, "missing");
        if (o.unset != Unset::fill) continue;
        set_default(o, l);
      } else if (o.unset == Unset::keep && equals_default(o, l)) {
        l.msg->GetReflection()->ClearField(l.msg, l.f);
        continue;
      }
      check(o, l);
    }
  }
}

void map_options(const OptionTable& table, const v1::Scenario& s, ResolvedScenario& r) {
  for (const auto& o : table)
    if (o.apply) o.apply(s, r);
}

const LabMaterial& lab_material(const std::string& name) {
  const std::string n = name.empty() ? option(lab_options(), "lab.material").default_value : name;
  std::vector<std::string> valid;
  for (const auto& m : lab_materials()) {
    if (m.name == n) return m;
    valid.push_back(m.name);
  }
  bad("lab.material", "unknown '" + n + "' (valid: " + join_names(valid) + ")");
}

// ---- the reference page ----------------------------------------------------------------------

namespace {

const char* type_name(OptionType t) {
  switch (t) {
    case OptionType::number: return "number";
    case OptionType::integer: return "integer";
    case OptionType::flag: return "true/false";
    case OptionType::text: return "text";
    case OptionType::path: return "path";
    case OptionType::choice: return "name";
    case OptionType::choice_list: return "list of names";
  }
  return "";
}

std::string cell(std::string s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string default_text(const Option& o) {
  if (o.unset == Unset::required) return "required";
  std::string d = o.type == OptionType::choice_list && !o.default_value.empty() ? "all"
                  : o.default_value.empty()                                     ? ""
                                                                                : "`" + o.default_value + "`";
  if (!o.zero.empty()) d += (d.empty() ? "0: " : "; 0: ") + o.zero;
  if (o.unset == Unset::keep) d += " (kept unset)";
  return d.empty() ? "-" : d;
}

std::string valid_text(const Option& o) {
  if (!o.choices.empty()) {
    std::string s;
    for (const auto& c : o.choices) s += (s.empty() ? "" : ", ") + ("`" + c + "`");
    return s;
  }
  if (o.range) return range_text(*o.range, o.type);
  return "-";
}

}  // namespace

std::string option_table_markdown(const OptionTable& table) {
  std::string s = "| Field | Type | Default | Valid | Unit | Description | Maps to |\n|---|---|---|---|---|---|---|\n";
  for (const auto& o : table)
    s += "| `" + o.path + "` | " + type_name(o.type) + " | " + cell(default_text(o)) + " | " + cell(valid_text(o)) + " | " +
         (o.unit.empty() ? "-" : cell(o.unit)) + " | " + cell(o.doc) + " | " + (o.maps_to.empty() ? "-" : cell(o.maps_to)) + " |\n";
  return s;
}

}  // namespace runout::jobs
