#include "jobs/formats/run_record.hpp"

#include <google/protobuf/util/json_util.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#ifndef RUNOUT_VERSION
#define RUNOUT_VERSION "unknown"
#endif
#ifndef RUNOUT_GIT_COMMIT
#define RUNOUT_GIT_COMMIT "unknown"
#endif
#ifndef RUNOUT_COMPILER
#define RUNOUT_COMPILER "unknown"
#endif
#ifndef RUNOUT_BUILD_TYPE
#define RUNOUT_BUILD_TYPE "unknown"
#endif

namespace runout::jobs {

namespace {

namespace pb = google::protobuf;

// The record's numbers carry 10 significant digits.
double ten_digits(double v) {
  if (!std::isfinite(v)) return v;
  std::ostringstream o;
  o.precision(10);
  o << v;
  return std::stod(o.str());
}

// Every double of `m` and its messages to 10 digits, except the embedded scenario (as resolved).
void round_doubles(pb::Message& m) {
  const auto* d = m.GetDescriptor();
  const auto* r = m.GetReflection();
  for (int k = 0; k < d->field_count(); ++k) {
    const auto* f = d->field(k);
    if (f->message_type() && f->message_type()->full_name() == "runout.v1.Scenario") continue;
    if (f->is_repeated()) {
      const int n = r->FieldSize(m, f);
      for (int q = 0; q < n; ++q) {
        if (f->cpp_type() == pb::FieldDescriptor::CPPTYPE_DOUBLE) r->SetRepeatedDouble(&m, f, q, ten_digits(r->GetRepeatedDouble(m, f, q)));
        if (f->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE) round_doubles(*r->MutableRepeatedMessage(&m, f, q));
      }
    } else if (f->cpp_type() == pb::FieldDescriptor::CPPTYPE_DOUBLE) {
      if (!f->has_presence() || r->HasField(m, f)) r->SetDouble(&m, f, ten_digits(r->GetDouble(m, f)));
    } else if (f->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE && r->HasField(m, f)) {
      round_doubles(*r->MutableMessage(&m, f));
    }
  }
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw RunRecordError("run record " + path + ": cannot open it");
  std::stringstream ss;
  ss << in.rdbuf();
  if (!in && !in.eof()) throw RunRecordError("run record " + path + ": reading failed");
  return ss.str();
}

}  // namespace

void write_run_record(const std::string& path, const v1::RunRecord& record) { write_record_json(path, record); }

void write_record_json(const std::string& path, const google::protobuf::Message& record) {
  std::unique_ptr<pb::Message> copy(record.New());
  copy->CopyFrom(record);
  pb::Message& r = *copy;
  round_doubles(r);
  pb::util::JsonPrintOptions po;
  po.add_whitespace = true;
  po.always_print_primitive_fields = true;
  po.preserve_proto_field_names = true;
  std::string json;
  const auto st = pb::util::MessageToJsonString(r, &json, po);
  if (!st.ok()) throw RunRecordError("run record " + path + ": " + st.ToString());
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f << json;
  if (!json.empty() && json.back() != '\n') f << '\n';
  f.close();
  if (!f) throw RunRecordError("run record " + path + ": writing failed");
}

v1::RunRecord read_run_record(const std::string& path) {
  const std::string json = read_file(path);
  v1::RunRecord r;
  pb::util::JsonParseOptions po;
  po.ignore_unknown_fields = true;
  const auto st = pb::util::JsonStringToMessage(json, &r, po);
  if (!st.ok()) throw RunRecordError("run record " + path + " is not a run record: " + st.ToString());
  return r;
}

bool is_run_record(const std::string& path) {
  try {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec) || std::filesystem::file_size(path, ec) > (std::uintmax_t(256) << 20)) return false;
    return read_run_record(path).software().name() == "runout";
  } catch (const std::exception&) {
    return false;
  }
}

std::vector<ProfilePoint> station_profile(const v1::Station& s) {
  std::vector<ProfilePoint> out;
  for (const auto& l : s.profile_y_alpha_u()) {
    auto num = [&](int k) {
      if (k >= l.values_size()) return double(NAN);
      const auto& v = l.values(k);
      return v.kind_case() == pb::Value::kNumberValue ? v.number_value() : double(NAN);
    };
    out.push_back({num(0), num(1), num(2)});
  }
  return out;
}

pb::ListValue profile_point(double y, double alpha, double u) {
  pb::ListValue l;
  for (double v : {y, alpha, u}) l.add_values()->set_number_value(v);
  return l;
}

namespace {

// The first field named `name` (depth first, field order) that is set: a number, or a list of them.
const pb::Message* owner_of(const pb::Message& m, const std::string& name, const pb::FieldDescriptor** field, bool repeated) {
  const auto* d = m.GetDescriptor();
  const auto* r = m.GetReflection();
  for (int k = 0; k < d->field_count(); ++k) {
    const auto* f = d->field(k);
    if (f->message_type() && f->message_type()->full_name() == "runout.v1.Scenario") continue;
    const bool number = f->cpp_type() == pb::FieldDescriptor::CPPTYPE_DOUBLE || f->cpp_type() == pb::FieldDescriptor::CPPTYPE_INT32;
    if (f->name() == name && number && f->is_repeated() == repeated && (repeated || !f->has_presence() || r->HasField(m, f))) {
      *field = f;
      return &m;
    }
    if (f->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE && !f->is_repeated() && r->HasField(m, f))
      if (const auto* o = owner_of(r->GetMessage(m, f), name, field, repeated)) return o;
  }
  return nullptr;
}

}  // namespace

double figure_by_name(const pb::Message& m, const std::string& name) {
  const pb::FieldDescriptor* f = nullptr;
  const pb::Message* o = owner_of(m, name, &f, false);
  if (!o) return NAN;
  const auto* r = o->GetReflection();
  return f->cpp_type() == pb::FieldDescriptor::CPPTYPE_DOUBLE ? r->GetDouble(*o, f) : double(r->GetInt32(*o, f));
}

std::vector<double> series_by_name(const pb::Message& m, const std::string& name) {
  const pb::FieldDescriptor* f = nullptr;
  const pb::Message* o = owner_of(m, name, &f, true);
  std::vector<double> v;
  if (!o) return v;
  const auto* r = o->GetReflection();
  for (int q = 0; q < r->FieldSize(*o, f); ++q)
    v.push_back(f->cpp_type() == pb::FieldDescriptor::CPPTYPE_DOUBLE ? r->GetRepeatedDouble(*o, f, q) : double(r->GetRepeatedInt32(*o, f, q)));
  return v;
}

v1::Software this_software() {
  v1::Software s;
  s.set_name("runout");
  s.set_version(RUNOUT_VERSION);
  s.set_git_commit(RUNOUT_GIT_COMMIT);
  s.set_compiler(RUNOUT_COMPILER);
  s.set_build_type(RUNOUT_BUILD_TYPE);
  return s;
}

}  // namespace runout::jobs
