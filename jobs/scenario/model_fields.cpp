// The granular viscosity models' parameters in the scenario, read through the rows of
// engine/vof/models/registry.hpp (model_fields.hpp).
#include "jobs/scenario/model_fields.hpp"

#include <cmath>

#include "jobs/scenario/scenario_impl.hpp"

namespace runout::jobs {

namespace {

namespace vof = engine::vof;
using google::protobuf::FieldDescriptor;

Range range_of(const vof::ModelParameter& p) { return Range{p.lo, p.hi, p.lo_open, p.hi_open}; }

// The rows' parameters, each field once (models may share one: mu_i and mu_i_unregularised), with
// the names of the models that read it.
std::vector<std::pair<const vof::ModelParameter*, std::string>> parameter_fields() {
  std::vector<std::pair<const vof::ModelParameter*, std::string>> out;
  for (const auto* m : vof::granular_viscosity_models())
    for (const auto& p : m->parameters) {
      if (p.field.empty()) break;
      auto it = std::find_if(out.begin(), out.end(), [&](const auto& e) { return e.first->field == p.field; });
      if (it == out.end()) out.emplace_back(&p, std::string(m->name));
      else it->second += ", " + std::string(m->name);
    }
  return out;
}

}  // namespace

std::string model_field(const vof::ModelParameter& p, ModelBlock block) {
  return block == ModelBlock::lab ? "lab." + std::string(p.field) : "material." + std::string(p.material_name());
}

void set_model_parameter(std::string_view field, double value, vof::VofConfig& c) {
  for (const auto* m : vof::granular_viscosity_models())
    for (const auto& p : m->parameters)
      if (!p.field.empty() && p.field == field) p.value(c) = value;
}

void take_model_fields(const google::protobuf::Message& msg, ModelBlock block, vof::VofConfig& c) {
  const auto* refl = msg.GetReflection();
  for (const auto& [p, models] : parameter_fields()) {
    const auto* f = msg.GetDescriptor()->FindFieldByName(std::string(block == ModelBlock::lab ? p->field : p->material_name()));
    if (!f || f->cpp_type() != FieldDescriptor::CPPTYPE_DOUBLE || f->is_repeated())
      throw std::logic_error("granular viscosity rows: no number field " + model_field(*p, block) + " in the scenario");
    if (refl->HasField(msg, f)) p->value(c) = refl->GetDouble(msg, f);
  }
}

void check_model(const vof::VofConfig& c, ModelBlock block) {
  const vof::GranularViscosityModel* m = vof::find_granular_viscosity(c.rheology);
  const std::string rheology = block == ModelBlock::lab ? "lab.rheology" : "material.rheology";
  if (!m) bad(rheology, "unknown '" + c.rheology + "' (valid: " + join_names(vof::granular_viscosity_names()) + ")");
  vof::VofConfig values = c;
  for (const auto& p : m->parameters) {
    if (p.field.empty()) break;
    const double v = p.value(values);
    if (!(std::isfinite(v) && p.in_range(v)))
      bad(model_field(p, block), "must lie in " + range_text(range_of(p), OptionType::number) + (p.unit.empty() ? "" : " " + std::string(p.unit)) +
                                     " (" + std::string(m->name) + "), got " + num(v));
  }
  if (const vof::ModelProblem problem = m->check(c)) {
    std::string field = block == ModelBlock::lab ? "lab." + std::string(problem.field) : "material." + std::string(problem.field);
    for (const auto& p : m->parameters)
      if (!p.field.empty() && p.field == problem.field) field = model_field(p, block);
    bad(field, problem.what);
  }
}

OptionTable lab_model_parameter_options(const std::vector<std::string>& material_defaults) {
  std::string captions;
  for (const auto* m : vof::granular_viscosity_models()) captions += (captions.empty() ? "" : ", ") + std::string(m->caption);
  OptionTable t = {{"lab.rheology", OptionType::choice, Unset::keep, vof::VofConfig{}.rheology, {},
                    vof::granular_viscosity_names(), "", "the granular viscosity: " + captions + " (the section below)",
                    "VofConfig::rheology", "", nullptr}};
  for (const auto& [p, models] : parameter_fields()) {
    const bool material = std::find(material_defaults.begin(), material_defaults.end(), p->field) != material_defaults.end();
    t.push_back({"lab." + std::string(p->field), OptionType::number, Unset::as_given, material ? "" : num(p->default_value()), range_of(*p),
                 {}, std::string(p->unit), models + ": " + std::string(p->symbol) + ", " + std::string(p->doc) + (material ? " (default: the lab material's)" : ""),
                 "VofConfig, models/registry.hpp", "", nullptr});
  }
  return t;
}

}  // namespace runout::jobs
