#include "jobs/scenario/text_limits.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/reflection.h>

#include <cstdio>

#include "jobs/scenario/scenario.hpp"

namespace runout::jobs {

namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::size_t limit_of(const std::string& field) {
  if (field == "thickness_raster" || ends_with(field, "path")) return kMaxPathBytes;
  if (field == "crs" || ends_with(field, "_crs")) return kMaxCrsBytes;
  return kMaxTextBytes;
}

void check_message(const Message& m, const std::string& prefix) {
  const auto* d = m.GetDescriptor();
  const auto* r = m.GetReflection();
  for (int k = 0; k < d->field_count(); ++k) {
    const FieldDescriptor* f = d->field(k);
    const std::string name = prefix.empty() ? f->name() : prefix + "." + f->name();
    auto one = [&](const std::string& field, auto get) {
      if (f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
        check_message(get.message(), field);
      } else if (f->cpp_type() == FieldDescriptor::CPPTYPE_STRING) {
        const std::string p = text_problem(get.text(), limit_of(f->name()));
        if (!p.empty()) throw ScenarioError(field + ": " + p);
      }
    };
    struct Single {
      const Message& m;
      const google::protobuf::Reflection* r;
      const FieldDescriptor* f;
      const Message& message() const { return r->GetMessage(m, f); }
      std::string text() const { return r->GetString(m, f); }
    };
    struct Item {
      const Message& m;
      const google::protobuf::Reflection* r;
      const FieldDescriptor* f;
      int i;
      const Message& message() const { return r->GetRepeatedMessage(m, f, i); }
      std::string text() const { return r->GetRepeatedString(m, f, i); }
    };
    if (f->is_repeated()) {
      const int n = r->FieldSize(m, f);
      for (int i = 0; i < n; ++i) one(name + "[" + std::to_string(i) + "]", Item{m, r, f, i});
    } else if (f->cpp_type() != FieldDescriptor::CPPTYPE_MESSAGE || r->HasField(m, f)) {
      one(name, Single{m, r, f});
    }
  }
}

}  // namespace

std::string text_problem(const std::string& value, std::size_t max_bytes) {
  if (value.size() > max_bytes)
    return "longer than " + std::to_string(max_bytes) + " bytes (" + std::to_string(value.size()) + " bytes)";
  for (std::size_t k = 0; k < value.size(); ++k) {
    const auto c = static_cast<unsigned char>(value[k]);
    if (c < 0x20 || c == 0x7f) {
      char u[16];
      std::snprintf(u, sizeof u, "U+%04X", unsigned(c));
      return std::string("holds a control character (") + u + ") at byte " + std::to_string(k + 1) + ", which no name or path may hold";
    }
  }
  return "";
}

void check_text_limits(const Message& m) { check_message(m, ""); }

}  // namespace runout::jobs
