#pragma once
// Inside jobs/scenario: the granular viscosity models' parameters (the rows of
// engine/vof/models/registry.hpp) as the laboratory block (lab.<field>) and the material block
// (material.<field>, or the row's material_field) give them, the lab option table's entries made
// from the rows, and the models' checks as scenario errors.
#include <google/protobuf/message.h>

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "engine/vof/models/registry.hpp"
#include "jobs/scenario/options.hpp"

namespace runout::jobs {

/// Which block of the scenario gives a model's parameters.
enum class ModelBlock { lab, material };

/// The parameter `field` (a row's lab field) of every model that reads it, in `c`.
void set_model_parameter(std::string_view field, double value, engine::vof::VofConfig& c);
/// Every model parameter that `msg` (v1::Lab or v1::Material, as `block` says) sets, into `c`; the
/// others stay as they are.
void take_model_fields(const google::protobuf::Message& msg, ModelBlock block, engine::vof::VofConfig& c);
/// The model c.rheology names: each of its parameters in its row's range, then the model's own
/// check; a failure is a ScenarioError naming the block's field ("lab.mu_2", "material.mu_2").
void check_model(const engine::vof::VofConfig& c, ModelBlock block);
/// The scenario's field of parameter `p` in `block`, e.g. "material.internal_friction_deg".
std::string model_field(const engine::vof::ModelParameter& p, ModelBlock block);

/// The lab block's options of the models: lab.rheology (the rows' names) and one option per
/// parameter field (the rows' unit, range and doc; `material_defaults`: the fields whose default is
/// the lab material's).
OptionTable lab_model_parameter_options(const std::vector<std::string>& material_defaults);

}  // namespace runout::jobs
