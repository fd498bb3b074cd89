#include "jobs/ensemble/variations.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/reflection.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "jobs/digest/sha256.hpp"
#include "jobs/scenario/options.hpp"

namespace runout::jobs::ensemble {

namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

[[noreturn]] void bad(const std::string& field, const std::string& problem) { throw ScenarioError(field + ": " + problem); }

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

// ---- numbers of the scenario by their path --------------------------------------------------

// One number of the scenario: a singular numeric field of a (sub-)message.
struct Slot {
  Message* msg;
  const FieldDescriptor* f;
};

// Every slot `path` names ("a.b", "releases[].x" every release, "releases[2].x" one); `create`: make
// missing sub-messages. An empty result with `why` set: the path names nothing.
std::vector<Slot> slots(Message& root, const std::string& path, bool create, std::string& why) {
  std::vector<Message*> at = {&root};
  std::size_t pos = 0;
  std::vector<Slot> out;
  while (pos <= path.size()) {
    const std::size_t dot = path.find('.', pos);
    std::string seg = path.substr(pos, dot == std::string::npos ? std::string::npos : dot - pos);
    const bool last = dot == std::string::npos;
    int index = -2;  // -2: a singular field, -1: every element, k: element k
    if (const auto open = seg.find('['); open != std::string::npos) {
      const auto close = seg.find(']', open);
      if (close != seg.size() - 1) return why = "'" + seg + "' is not a field name", out;
      const std::string inner = seg.substr(open + 1, close - open - 1);
      if (inner.empty()) {
        index = -1;
      } else if (inner.find_first_not_of("0123456789") == std::string::npos && inner.size() < 7) {
        index = std::stoi(inner);
      } else {
        return why = "'" + seg + "': the index must be a whole number", out;
      }
      seg = seg.substr(0, open);
    }
    std::vector<Message*> next;
    for (Message* m : at) {
      const FieldDescriptor* f = m->GetDescriptor()->FindFieldByName(seg);
      if (!f) return why = "the scenario has no field '" + seg + "' there", out;
      const auto* refl = m->GetReflection();
      if (index != -2 && !(f->is_repeated() && f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE))
        return why = "'" + seg + "' is not a list of blocks", out;
      if (index == -2 && f->is_repeated()) return why = "'" + seg + "' is a list: name its elements ('" + seg + "[]' or '" + seg + "[0]')", out;
      if (last) {
        if (index != -2 || f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE || f->cpp_type() == FieldDescriptor::CPPTYPE_STRING ||
            f->cpp_type() == FieldDescriptor::CPPTYPE_BOOL || f->cpp_type() == FieldDescriptor::CPPTYPE_ENUM)
          return why = "'" + seg + "' is not a number", out;
        out.push_back({m, f});
        continue;
      }
      if (index == -2) {
        if (f->cpp_type() != FieldDescriptor::CPPTYPE_MESSAGE) return why = "'" + seg + "' is not a block", out;
        if (create || refl->HasField(*m, f)) next.push_back(refl->MutableMessage(m, f));
      } else {
        const int n = refl->FieldSize(*m, f);
        if (index >= n) return why = seg + "[" + std::to_string(index) + "]: the scenario has " + std::to_string(n), out;
        for (int k = index < 0 ? 0 : index; k < (index < 0 ? n : index + 1); ++k) next.push_back(refl->MutableRepeatedMessage(m, f, k));
      }
    }
    if (last) break;
    at = std::move(next);
    pos = dot + 1;
  }
  return out;
}

bool slot_set(const Slot& s) {
  const auto* refl = s.msg->GetReflection();
  if (s.f->has_presence()) return refl->HasField(*s.msg, s.f);
  return true;
}

double slot_get(const Slot& s) {
  const auto* refl = s.msg->GetReflection();
  switch (s.f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE: return refl->GetDouble(*s.msg, s.f);
    case FieldDescriptor::CPPTYPE_FLOAT: return refl->GetFloat(*s.msg, s.f);
    case FieldDescriptor::CPPTYPE_INT32: return refl->GetInt32(*s.msg, s.f);
    case FieldDescriptor::CPPTYPE_INT64: return double(refl->GetInt64(*s.msg, s.f));
    case FieldDescriptor::CPPTYPE_UINT32: return refl->GetUInt32(*s.msg, s.f);
    default: return double(refl->GetUInt64(*s.msg, s.f));
  }
}

// false: the field holds whole numbers and v is not one.
bool slot_put(const Slot& s, double v) {
  const auto* refl = s.msg->GetReflection();
  if (s.f->cpp_type() != FieldDescriptor::CPPTYPE_DOUBLE && s.f->cpp_type() != FieldDescriptor::CPPTYPE_FLOAT && v != std::floor(v))
    return false;
  switch (s.f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE: refl->SetDouble(s.msg, s.f, v); break;
    case FieldDescriptor::CPPTYPE_FLOAT: refl->SetFloat(s.msg, s.f, float(v)); break;
    case FieldDescriptor::CPPTYPE_INT32: refl->SetInt32(s.msg, s.f, std::int32_t(v)); break;
    case FieldDescriptor::CPPTYPE_INT64: refl->SetInt64(s.msg, s.f, std::int64_t(v)); break;
    case FieldDescriptor::CPPTYPE_UINT32: refl->SetUInt32(s.msg, s.f, std::uint32_t(std::max(0.0, v))); break;
    default: refl->SetUInt64(s.msg, s.f, std::uint64_t(std::max(0.0, v))); break;
  }
  return true;
}

// "releases[3].thickness_m" -> "releases[].thickness_m": the option tables' spelling.
std::string table_path(const std::string& path) {
  std::string out;
  for (std::size_t k = 0; k < path.size(); ++k) {
    out += path[k];
    if (path[k] == '[') {
      while (k + 1 < path.size() && path[k + 1] != ']') ++k;
    }
  }
  return out;
}

// The option table's entry for the path (the scenario's documented numbers), or null.
const Option* documented(const std::string& path) {
  const std::string p = table_path(path);
  for (const auto* t : {&depth_averaged_options(), &terrain_vof_options()})
    for (const auto& o : *t)
      if (o.path == p && (o.type == OptionType::number || o.type == OptionType::integer)) return &o;
  return nullptr;
}

// A release left out by "releases[K].active" = 0.
bool is_active_path(const std::string& path, int& release) {
  if (path.rfind("releases[", 0) != 0) return false;
  const auto close = path.find(']');
  if (close == std::string::npos || path.substr(close) != "].active") return false;
  const std::string inner = path.substr(9, close - 9);
  if (inner.empty() || inner.size() > 6 || inner.find_first_not_of("0123456789") != std::string::npos) return false;
  release = std::stoi(inner);
  return true;
}

// ---- random numbers, the same on every machine ----------------------------------------------

// Uniform in [0, 1) from the top 53 bits (std::uniform_real_distribution's algorithm is left to the
// library; this one is fixed).
double uniform01(std::mt19937_64& g) { return double(g() >> 11) * 0x1.0p-53; }

// The stream of parameter k: the seed mixed with k (SplitMix64's constant), so that adding a
// parameter at the end leaves the draws of the others alone.
std::mt19937_64 stream(std::uint64_t seed, std::size_t k) { return std::mt19937_64(seed ^ (0x9E3779B97F4A7C15ull * (k + 1))); }

double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

// ---- one parameter ----------------------------------------------------------------------------

struct Param {
  std::string field;  // "variations.parameters[k]"
  std::string path;
  int release = -1;   // >= 0: "releases[K].active"
  std::vector<double> values;  // a list (values, range, percent)
  enum class Law { none, uniform, normal } law = Law::none;
  double lo = 0, hi = 0, mean = 0, sd = 0;
  bool cut = false;   // normal cut to [lo, hi]
};

// The law's quantile at u in (0, 1).
double quantile(const Param& p, double u) {
  if (p.law == Param::Law::uniform) return p.lo + u * (p.hi - p.lo);
  if (!p.cut) return p.mean + p.sd * normal_quantile(u);
  const double a = normal_cdf((p.lo - p.mean) / p.sd), b = normal_cdf((p.hi - p.mean) / p.sd);
  return std::clamp(p.mean + p.sd * normal_quantile(a + u * (b - a)), p.lo, p.hi);
}

Param read_param(const v1::Variation& v, std::size_t index, const v1::Scenario& s, bool lhs) {
  const std::string field = "variations.parameters[" + std::to_string(index) + "]";
  Param p;
  p.field = field;
  p.path = v.parameter();
  if (p.path.empty()) bad(field + ".parameter", "missing (e.g. \"material.bed_friction_deg\")");
  const bool active = is_active_path(p.path, p.release);
  if (active && p.release >= s.releases_size())
    bad(field + ".parameter", "'" + p.path + "': the scenario has " + std::to_string(s.releases_size()) + " release(s)");
  const Option* opt = active ? nullptr : documented(p.path);
  v1::Scenario probe = s;
  std::string why;
  if (!active) {
    if (!opt)
      bad(field + ".parameter", "'" + p.path + "' is not a number of the scenario that may vary (e.g. material.bed_friction_deg, "
                                "material.voellmy_mu, material.voellmy_xi, material.density_kg_m3, releases[].thickness_factor, "
                                "releases[0].thickness_m, grid.resolution_m, releases[0].active; docs/user/ensembles.md)");
    if (slots(probe, p.path, true, why).empty()) bad(field + ".parameter", "'" + p.path + "': " + why);
  }
  const bool dist = !v.distribution().empty();
  const int ways = (v.values_size() > 0) + ((v.has_from() || v.has_to() || v.has_step()) && !dist) + (v.has_percent() && !dist) + dist;
  if (ways == 0) bad(field, "give values, from/to/step, percent or a distribution");
  if (ways > 1) bad(field, "give one of values, from/to/step, percent or a distribution");
  if (active && v.values_size() == 0) bad(field, "releases[K].active takes values (0: left out, 1: in)");
  const int count = v.count() > 0 ? v.count() : 3;
  // What a percentage is of: the scenario's own value, or the option's default.
  auto base_value = [&] {
    double base = 0;
    if (number_at(s, p.path, base)) return base;
    if (!opt || opt->default_value.empty())
      bad(field + ".percent", "'" + p.path + "' is not set in the scenario: give its value, or values instead of percent");
    return std::stod(opt->default_value);
  };
  if (v.values_size() > 0) {
    p.values.assign(v.values().begin(), v.values().end());
    if (active)
      for (double x : p.values)
        if (x != 0 && x != 1) bad(field + ".values", "releases[K].active takes 0 (left out) or 1 (in), got " + num(x));
  } else if (v.has_percent()) {
    const double base = base_value(), f = v.percent() / 100;
    if (lhs) {
      p.law = Param::Law::uniform;
      p.lo = base * (1 - f), p.hi = base * (1 + f);
    } else {
      for (int k = 0; k < count; ++k) p.values.push_back(count == 1 ? base : base * (1 + f * (-1 + 2.0 * k / (count - 1))));
    }
  } else if (v.distribution().empty()) {  // a range
    if (!v.has_from() || !v.has_to()) bad(field, "a range needs from and to");
    if (v.to() < v.from()) bad(field + ".to", "must be at least from (" + num(v.from()) + "), got " + num(v.to()));
    if (lhs) {
      if (v.has_step()) bad(field + ".step", "a latin hypercube samples the range from..to: leave step out (or give values)");
      p.law = Param::Law::uniform;
      p.lo = v.from(), p.hi = v.to();
    } else {
      if (!v.has_step()) bad(field + ".step", "missing: a range from..to in the cross product needs a step");
      const double n = std::floor((v.to() - v.from()) / v.step() + 1e-9) + 1;
      if (n > kMaxMembers) bad(field + ".step", "makes " + num(n) + " values; at most " + std::to_string(kMaxMembers));
      for (int k = 0; k < int(n); ++k) {  // the last value is `to` when the steps reach it (no 17.500000000000004)
        const double x = v.from() + k * v.step();
        p.values.push_back(std::abs(x - v.to()) <= 1e-9 * v.step() ? v.to() : x);
      }
    }
  } else {  // a distribution
    if (v.distribution() == "uniform") {
      p.law = Param::Law::uniform;
      if (v.has_from() && v.has_to()) {
        p.lo = v.from(), p.hi = v.to();
      } else if (v.has_percent()) {
        const double base = base_value();
        p.lo = base * (1 - v.percent() / 100), p.hi = base * (1 + v.percent() / 100);
      } else {
        bad(field, "a uniform distribution needs from and to, or percent");
      }
      if (p.hi < p.lo) bad(field + ".to", "must be at least from");
    } else {
      p.law = Param::Law::normal;
      if (!v.has_mean() || !v.has_sd()) bad(field, "a normal distribution needs mean and sd");
      p.mean = v.mean(), p.sd = v.sd();
      p.cut = v.has_from() || v.has_to();
      if (p.cut) {
        if (!v.has_from() || !v.has_to()) bad(field, "a normal distribution is cut to from..to: give both");
        p.lo = v.from(), p.hi = v.to();
        if (!(p.lo < p.hi)) bad(field + ".to", "must be above from");
      }
    }
    if (!lhs && v.count() <= 0) bad(field + ".count", "missing: how many values to draw from the distribution");
  }
  if (!lhs && p.law != Param::Law::none) {
    auto g = stream(s.variations().has_seed() ? s.variations().seed() : 1, index);
    for (int k = 0; k < v.count(); ++k) p.values.push_back(quantile(p, std::max(uniform01(g), 0x1.0p-60)));
    p.law = Param::Law::none;
  }
  return p;
}

// The member with these values, or false when it releases nothing (every release left out).
bool make_member(const v1::Scenario& base, const std::vector<Param>& params, const std::vector<double>& values, Member& m) {
  m.scenario = base;
  m.scenario.clear_variations();
  m.values.clear();
  std::set<int> out;
  for (std::size_t k = 0; k < params.size(); ++k) {
    const Param& p = params[k];
    m.values.push_back({p.path, values[k]});
    if (p.release >= 0) {
      if (values[k] == 0) out.insert(p.release);
      continue;
    }
    std::string why;
    for (const auto& sl : slots(m.scenario, p.path, true, why))
      if (!slot_put(sl, values[k])) bad(p.field, "'" + p.path + "' takes whole numbers, got " + num(values[k]));
  }
  if (!out.empty()) {
    auto* rel = m.scenario.mutable_releases();
    for (auto it = out.rbegin(); it != out.rend(); ++it) rel->DeleteSubrange(*it, 1);
    if (std::all_of(rel->begin(), rel->end(), [](const v1::Release& r) { return r.secondary(); })) return false;
  }
  if (base.variations().member_outputs() != "all") {  // members feed the aggregate: no maps, no time series, no report
    m.scenario.mutable_outputs()->set_maps(false);
    m.scenario.mutable_outputs()->clear_timeseries_interval_s();
    m.scenario.mutable_outputs()->clear_report();
  }
  auto* rasters = m.scenario.mutable_outputs()->mutable_rasters();
  if (!rasters->empty())  // the aggregate reads these three of every member
    for (const char* r : {"max_depth", "max_speed", "max_pressure"})
      if (std::find(rasters->begin(), rasters->end(), r) == rasters->end()) rasters->Add(r);
  return true;
}

// A zoning's members: one per return period, ascending, each the scenario with its values (every
// value's path checked as a variation's is), its own maps and outputs, without the zoning block.
std::vector<Member> expand_zoning(const v1::Scenario& s) {
  const auto& z = s.zoning();
  if (s.has_variations()) bad("zoning", "a scenario takes variations or zoning, not both");
  if (s.has_lab()) bad("zoning", "zones are drawn on a DEM; a laboratory set-up (lab) takes none");
  if (z.scenarios_size() < 2) bad("zoning.scenarios", "at least two scenarios by return period (e.g. 30, 100 and 300 years)");
  if (z.has_red_pressure_kpa() && !(z.red_pressure_kpa() > 0 && z.red_pressure_kpa() <= 10000))
    bad("zoning.red_pressure_kpa", "must lie in (0, 10000] kPa, got " + num(z.red_pressure_kpa()));
  const double frequent = z.has_frequent_y() ? z.frequent_y() : 30, design = z.has_design_y() ? z.design_y() : 300;
  if (!(frequent >= 1 && frequent <= 100000)) bad("zoning.frequent_y", "must lie in [1, 100000] years, got " + num(frequent));
  if (!(design >= frequent && design <= 100000))
    bad("zoning.design_y", "must lie in [frequent_y (" + num(frequent) + "), 100000] years, got " + num(design));
  std::vector<int> order(std::size_t(z.scenarios_size()));
  for (int k = 0; k < z.scenarios_size(); ++k) {
    order[std::size_t(k)] = k;
    const double t = z.scenarios(k).return_period_y();
    if (!(t >= 1 && t <= 100000 && t == std::floor(t)))
      bad("zoning.scenarios[" + std::to_string(k) + "].return_period_y", "must be a whole number of years in [1, 100000], got " + num(t));
    for (int j = 0; j < k; ++j)
      if (z.scenarios(j).return_period_y() == t)
        bad("zoning.scenarios[" + std::to_string(k) + "].return_period_y", num(t) + " years is also scenarios[" + std::to_string(j) + "]'s");
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) { return z.scenarios(a).return_period_y() < z.scenarios(b).return_period_y(); });
  std::vector<Member> out;
  for (int k : order) {
    const auto& rp = z.scenarios(k);
    const std::string field = "zoning.scenarios[" + std::to_string(k) + "].values";
    std::vector<Param> params;
    std::vector<double> values;
    std::set<std::string> seen;
    for (int j = 0; j < rp.values_size(); ++j) {
      const std::string at = field + "[" + std::to_string(j) + "]";
      if (!rp.values(j).has_value()) bad(at + ".value", "missing: the number this scenario gives '" + rp.values(j).parameter() + "'");
      v1::Variation v;
      v.set_parameter(rp.values(j).parameter());
      v.add_values(rp.values(j).value());
      try {
        params.push_back(read_param(v, 0, s, false));
      } catch (const ScenarioError& e) {  // named as this value, not as a variation
        throw ScenarioError(at + std::string(e.what()).substr(24));
      }
      params.back().field = at;
      if (!seen.insert(params.back().path).second) bad(at + ".parameter", "'" + params.back().path + "' is given twice");
      values.push_back(rp.values(j).value());
    }
    Member m;
    if (!make_member(s, params, values, m)) bad(field, "leaves out every release");
    m.scenario.clear_zoning();
    *m.scenario.mutable_outputs() = s.outputs();  // each scenario's maps and files, as the scenario asks
    auto* rasters = m.scenario.mutable_outputs()->mutable_rasters();
    if (!rasters->empty())  // the zones read these two of every scenario
      for (const char* r : {"max_depth", "max_pressure"})
        if (std::find(rasters->begin(), rasters->end(), r) == rasters->end()) rasters->Add(r);
    m.return_period_y = rp.return_period_y();
    m.values.insert(m.values.begin(), {"return_period_y", rp.return_period_y()});
    m.index = int(out.size());
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace

bool is_ensemble(const v1::Scenario& s) { return s.has_variations() || s.has_zoning(); }

bool number_at(const v1::Scenario& s, const std::string& path, double& value) {
  v1::Scenario copy = s;
  std::string why;
  const auto at = slots(copy, path, false, why);
  if (at.empty() || !slot_set(at.front())) return false;
  value = slot_get(at.front());
  for (const auto& sl : at)
    if (!slot_set(sl) || slot_get(sl) != value) return false;  // releases[] with different values: no one number
  return true;
}

std::vector<Member> expand(const v1::Scenario& s) {
  if (s.has_zoning()) return expand_zoning(s);
  const auto& var = s.variations();
  if (s.engine() == "vof" && s.has_lab()) bad("variations", "ensembles run on a DEM; a laboratory set-up (lab) takes none");
  if (var.parameters().empty()) bad("variations.parameters", "at least one parameter to vary");
  const bool lhs = var.design() == "latin-hypercube";
  if (!lhs && var.samples() != 0) bad("variations.samples", "is for design \"latin-hypercube\"; the cross product takes every combination");
  if (lhs && var.samples() < 2) bad("variations.samples", "a latin hypercube needs at least 2 samples, got " + std::to_string(var.samples()));
  std::vector<Param> params;
  std::set<std::string> seen;
  for (int k = 0; k < var.parameters_size(); ++k) {
    params.push_back(read_param(var.parameters(k), std::size_t(k), s, lhs));
    if (!seen.insert(params.back().path).second) bad(params.back().field + ".parameter", "'" + params.back().path + "' is varied twice");
  }
  std::vector<Member> out;
  auto add = [&](const std::vector<double>& values) {
    Member m;
    if (!make_member(s, params, values, m)) return;
    m.index = int(out.size());
    out.push_back(std::move(m));
  };
  if (lhs) {
    const int n = var.samples();
    std::vector<std::vector<double>> u(params.size(), std::vector<double>(std::size_t(n)));
    for (std::size_t p = 0; p < params.size(); ++p) {
      auto g = stream(var.has_seed() ? var.seed() : 1, p);
      std::vector<int> perm(static_cast<std::size_t>(n));
      for (int k = 0; k < n; ++k) perm[std::size_t(k)] = k;
      for (int k = n - 1; k > 0; --k) std::swap(perm[std::size_t(k)], perm[std::size_t(g() % std::uint64_t(k + 1))]);  // Fisher-Yates
      for (int k = 0; k < n; ++k) u[p][std::size_t(k)] = (perm[std::size_t(k)] + std::max(uniform01(g), 0x1.0p-60)) / n;
    }
    for (int k = 0; k < n; ++k) {
      std::vector<double> values;
      for (std::size_t p = 0; p < params.size(); ++p) {
        const double uk = u[p][std::size_t(k)];
        const Param& q = params[p];
        values.push_back(q.law == Param::Law::none ? q.values[std::min(q.values.size() - 1, std::size_t(uk * double(q.values.size())))]
                                                   : quantile(q, uk));
      }
      add(values);
    }
  } else {
    double total = 1;
    for (const auto& p : params) total *= double(p.values.size());
    if (total > kMaxMembers)
      bad("variations", "the cross product makes " + num(total) + " members; at most " + std::to_string(kMaxMembers) +
                            " (vary fewer values, or use design \"latin-hypercube\")");
    std::vector<std::size_t> at(params.size(), 0);
    for (long m = 0; m < long(total); ++m) {  // the last parameter varies fastest
      std::vector<double> values;
      for (std::size_t p = 0; p < params.size(); ++p) values.push_back(params[p].values[at[p]]);
      add(values);
      for (std::size_t p = params.size(); p-- > 0;) {
        if (++at[p] < params[p].values.size()) break;
        at[p] = 0;
      }
    }
  }
  if (out.empty()) bad("variations", "every member leaves out every release");
  return out;
}

AggregateSettings aggregate_settings(const ResolvedScenario& r) {
  const auto& v = r.scenario.variations();
  AggregateSettings a;
  a.depth_m.assign(v.depth_thresholds_m().begin(), v.depth_thresholds_m().end());
  if (a.depth_m.empty()) a.depth_m = {r.outline_threshold};
  a.speed_m_s.assign(v.speed_thresholds_m_s().begin(), v.speed_thresholds_m_s().end());
  if (a.speed_m_s.empty()) a.speed_m_s = {1.0};
  a.pressure_kpa.assign(v.pressure_thresholds_kpa().begin(), v.pressure_thresholds_kpa().end());
  if (a.pressure_kpa.empty())
    for (const auto& z : r.pressure_zones) a.pressure_kpa.push_back(z.from_kpa);
  a.percentiles.assign(v.percentiles().begin(), v.percentiles().end());
  if (a.percentiles.empty()) a.percentiles = {5, 50, 95};
  a.maps = r.maps;
  a.name = r.scenario.name();
  if (r.scenario.has_zoning()) {
    const auto& z = r.scenario.zoning();
    a.red_pressure_kpa = z.has_red_pressure_kpa() ? z.red_pressure_kpa() : 30;
    a.frequent_y = z.has_frequent_y() ? z.frequent_y() : 30;
    a.design_y = z.has_design_y() ? z.design_y() : 300;
  }
  for (auto* list : {&a.depth_m, &a.speed_m_s, &a.pressure_kpa, &a.percentiles}) {
    std::sort(list->begin(), list->end());
    list->erase(std::unique(list->begin(), list->end()), list->end());
  }
  return a;
}

std::string ensemble_hash(const std::vector<std::string>& member_hashes, const AggregateSettings& a) {
  Sha256 h;
  h.update("runout ensemble results " + std::to_string(kEnsembleResultsVersion) + "\n");
  auto list = [&](const char* name, const std::vector<double>& v) {
    h.update(name);
    for (double x : v) h.update(" " + num(x));
    h.update("\n");
  };
  list("depth_m", a.depth_m);
  list("speed_m_s", a.speed_m_s);
  list("pressure_kpa", a.pressure_kpa);
  list("percentiles", a.percentiles);
  h.update(std::string("maps ") + (a.maps ? "1" : "0") + "\nname " + a.name + "\n");  // the maps and their titles
  if (a.zoning()) {  // the rule, and which member is which return period (a member's own hash does not say)
    h.update("zoning " + num(a.red_pressure_kpa) + " " + num(a.frequent_y) + " " + num(a.design_y) + "\n");
    for (double t : a.return_periods_y) h.update("return period " + num(t) + "\n");
  }
  for (const auto& m : member_hashes) h.update(m + "\n");
  return h.hex();
}

Plan plan(const ResolvedScenario& e) {
  Plan p;
  std::vector<std::string> hashes;
  for (auto& m : expand(e.scenario)) {
    std::string hash;
    try {
      hash = scenario_hash(resolve_scenario(m.scenario, "/"));
    } catch (const ScenarioError& x) {
      throw ScenarioError(std::string(e.scenario.has_zoning() ? "zoning" : "variations") + ": member " + std::to_string(m.index) + " (" +
                          describe(m.values) + "): " + x.what());
    }
    hashes.push_back(hash);
    p.members.push_back({std::move(m), hash});
  }
  p.settings = aggregate_settings(e);
  for (const auto& m : p.members) p.settings.return_periods_y.push_back(m.member.return_period_y);
  p.hash = ensemble_hash(hashes, p.settings);
  return p;
}

std::string describe(const std::vector<ParameterValue>& values) {
  std::string s;
  for (const auto& v : values) s += (s.empty() ? "" : ", ") + v.parameter + " = " + num(v.value);
  return s;
}

ParameterWords parameter_in_words(const std::string& path) {
  // "releases[0].thickness_factor" -> the block ("releases", a list: "release 1"), the field.
  std::string block = path.substr(0, path.rfind('.') == std::string::npos ? 0 : path.rfind('.'));
  std::string field = path.substr(path.rfind('.') == std::string::npos ? 0 : path.rfind('.') + 1);
  ParameterWords w;
  // The unit from the field's suffix, as the scenario's fields name it.
  static const std::pair<const char*, const char*> kUnits[] = {{"_deg", "°"}, {"_kg_m3", "kg/m³"}, {"_m_s2", "m/s²"}, {"_m_s", "m/s"},
                                                               {"_kpa", "kPa"}, {"_pa", "Pa"}, {"_m3", "m³"}, {"_m", "m"}, {"_s", "s"}};
  for (const auto& [suffix, unit] : kUnits) {
    const std::string sfx(suffix);
    if (field.size() > sfx.size() && field.compare(field.size() - sfx.size(), sfx.size(), sfx) == 0) {
      field.resize(field.size() - sfx.size());
      w.unit = unit;
      break;
    }
  }
  std::replace(field.begin(), field.end(), '_', ' ');
  if (w.unit == "°" && field.find("angle") == std::string::npos) field += " angle";
  std::string owner;
  if (block.rfind("releases", 0) == 0) {  // every release, or release k + 1
    const auto open = block.find('['), close = block.find(']');
    const std::string index = open != std::string::npos && close > open + 1 ? block.substr(open + 1, close - open - 1) : "";
    owner = index.empty() ? "release " : "release " + std::to_string(std::stoi(index) + 1) + " ";
  } else if (block == "grid" || block == "numerics") {
    owner = block + " ";
  }
  w.words = owner + field;
  return w;
}

double normal_quantile(double p) {
  // Wichura, M. J. (1988), Algorithm AS 241: The percentage points of the normal distribution.
  const double q = p - 0.5;
  if (std::abs(q) <= 0.425) {
    const double r = 0.180625 - q * q;
    return q *
           (((((((2509.0809287301226727 * r + 33430.575583588128105) * r + 67265.770927008700853) * r + 45921.953931549871457) * r +
               13731.693765509461125) * r + 1971.5909503065514427) * r + 133.14166789178437745) * r + 3.387132872796366608) /
           (((((((5226.495278852545925 * r + 28729.085735721942674) * r + 39307.89580009271061) * r + 21213.794301586595867) * r +
               5394.1960214247511077) * r + 687.1870074920579083) * r + 42.313330701600911252) * r + 1.0);
  }
  double r = q < 0 ? p : 1 - p;
  if (r <= 0) return q < 0 ? -INFINITY : INFINITY;
  r = std::sqrt(-std::log(r));
  double x;
  if (r <= 5) {
    r -= 1.6;
    x = (((((((7.7454501427834140764e-4 * r + 0.0227238449892691845833) * r + 0.24178072517745061177) * r + 1.27045825245236838258) * r +
            3.64784832476320460504) * r + 5.7694972214606914055) * r + 4.6303378461565452959) * r + 1.42343711074968357734) /
        (((((((1.05075007164441684324e-9 * r + 5.475938084995344946e-4) * r + 0.0151986665636164571966) * r + 0.14810397642748007459) * r +
            0.68976733498510000455) * r + 1.6763848301838038494) * r + 2.05319162663775882187) * r + 1.0);
  } else {
    r -= 5;
    x = (((((((2.01033439929228813265e-7 * r + 2.71155556874348757815e-5) * r + 0.0012426609473880784386) * r + 0.026532189526576123093) * r +
            0.29656057182850489123) * r + 1.7848265399172913358) * r + 5.4637849111641143699) * r + 6.6579046435011037772) /
        (((((((2.04426310338993978564e-15 * r + 1.4215117583164458887e-7) * r + 1.8463183175100546818e-5) * r + 7.868691311456132591e-4) * r +
            0.0148753612908506148525) * r + 0.13692988092273580531) * r + 0.59983220655588793769) * r + 1.0);
  }
  return q < 0 ? -x : x;
}

}  // namespace runout::jobs::ensemble
