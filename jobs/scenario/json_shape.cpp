#include "jobs/scenario/json_shape.hpp"

#include <google/protobuf/descriptor.h>

#include <set>
#include <string>

#include "jobs/scenario/scenario.hpp"
#include "jobs/scenario/scenario_impl.hpp"

namespace runout::jobs {

namespace {

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

}  // namespace

void check_json_shape(const std::string& json) { JsonShape(json).check(); }

}  // namespace runout::jobs
