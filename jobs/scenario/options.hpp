#pragma once
// Every scenario option declared once: one table per engine set-up (the scenario's own fields, the
// depth-averaged engine's, the VOF laboratory's `lab` block). An entry names the field (its path in
// runout.v1.Scenario), its type, default, range or choices, unit and one line of documentation,
// and how it maps into the resolved scenario or the engine's configuration. The tables drive
//   - validation: a value outside the range or not among the choices is a ScenarioError naming the
//     field, the value and the valid range or choices (apply_option_rules);
//   - resolution: defaults are filled in, or left unset (Unset);
//   - hashing: the scenario hash is the resolved message's, so the Unset rule of each option decides
//     what the hash holds (it reproduces the hashes of every scenario written before the tables);
//   - the reference page docs/user/scenario-reference.md (scenario_reference_markdown,
//     `runout_scenario_tool reference`; a test fails when the committed page is stale).
// Checks between fields (a release needs a thickness or an attribute; lab.x_max > lab.x_min; ...)
// and input files stay in code beside the tables (scenario.cpp, lab.cpp).
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/names.hpp"
#include "runout/v1/scenario.pb.h"

namespace runout::jobs {

struct ResolvedScenario;

enum class OptionType {
  number,       ///< a double
  integer,      ///< an int32 or int64
  flag,         ///< a bool
  text,         ///< free text
  path,         ///< an input file, relative to the scenario's folder
  choice,       ///< one name of `choices`
  choice_list,  ///< a list of names of `choices`
};

/// What an option that is not given becomes (and so what the scenario hash holds).
enum class Unset {
  as_given,  ///< stays unset; the engine reads unset as the default
  fill,      ///< the default is written into the scenario, as if given
  keep,      ///< stays unset, and a value equal to the default is cleared: both are the same scenario
             ///< (options added after scenarios were cached: their hashes stay the same)
  required,  ///< an error when missing
};

struct Range {
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
};

struct Option {
  std::string path;  ///< e.g. "numerics.cfl"; "[]" marks every element of a list: "releases[].thickness_m"
  OptionType type = OptionType::number;
  Unset unset = Unset::as_given;
  std::string default_value;         ///< as JSON spells it ("0.45", "minmod"); for a choice list: every choice
  std::optional<Range> range;        ///< number, integer
  std::vector<std::string> choices;  ///< choice, choice_list; "EPSG:<code>" takes any value with that prefix
  std::string unit;
  std::string doc;      ///< one line
  std::string maps_to;  ///< where the value goes (ResolvedScenario, Sh2dConfig, VofConfig, ...)
  std::string zero;     ///< a number without presence: what 0 (the same as unset) means
  /// Into the resolved scenario or the engine's configuration (after validation); null: the mapping
  /// lives where maps_to says (a release's fields, the lab block's driver).
  void (*apply)(const v1::Scenario&, ResolvedScenario&) = nullptr;
};

using OptionTable = std::vector<Option>;

/// name, engine, limits: the fields of every scenario.
const OptionTable& scenario_options();
/// engine "depth-averaged": dem, area_of_interest, grid, releases, material, numerics, outputs.
const OptionTable& depth_averaged_options();
/// engine "vof" with a `lab` block: the laboratory set-up.
const OptionTable& lab_options();
/// engine "vof" without `lab`: the 3D engine on the DEM, blocks `mesh` and `vof` (with the
/// depth-averaged table's DEM, releases, material, numerics and outputs).
const OptionTable& terrain_vof_options();

/// A granular material of the laboratory cases (lab.material; validation.md part B).
struct LabMaterial {
  std::string name;
  double rho, phi_deg, delta_deg;  ///< density [kg/m^3], internal and bed friction angles [deg]
  std::string doc;
  /// mu(I)'s parameters (lab.rheology "mu_i"): the measured angle of repose as mu_s = tan(repose),
  /// mu_2 = tan(repose + kMuIRise) (the rise of the glass beads of Jop et al. 2006, 20.9 to 32.76
  /// deg: not measured for these materials), the measured mean grain diameter [m] and grain
  /// density [kg/m^3]; I_0 is the engine's (the beads', 0.279).
  double repose_deg, grain_diameter, grain_density;
  static constexpr double kMuIRise = 32.76 - 20.9;
};
const std::vector<LabMaterial>& lab_materials();
/// The boundary conditions' names as scenarios spell them (engine/vof/bc/conditions.hpp's rows);
/// `bed`: those that may be the ground of the 3D engine on the DEM.
std::vector<std::string> condition_names(bool bed);
/// The granular viscosity models' parameters a lab material gives, by the rows' lab field
/// (engine/vof/models): lab.phi_deg, and mu(I)'s from the angle of repose, grain diameter and
/// density. The lab block's defaults of those fields.
std::vector<std::pair<std::string, double>> lab_model_defaults(const LabMaterial& m);
/// The material called `name` ("" is the default, pvc); an unknown name is a ScenarioError listing
/// the valid ones. For the lab driver's mapping into VofConfig.
const LabMaterial& lab_material(const std::string& name);

/// The option of `table` at `path` (as the table spells it); throws std::out_of_range.
const Option& option(const OptionTable& table, const std::string& path);

/// Apply each option's Unset rule (fill or clear defaults) and check its range or choices wherever
/// it occurs in `s`. Throws ScenarioError "field: problem".
void apply_option_rules(const OptionTable& table, v1::Scenario& s);
/// Each option's `apply`, after apply_option_rules.
void map_options(const OptionTable& table, const v1::Scenario& s, ResolvedScenario& r);

/// One table as a Markdown table (field, type, default, valid, unit, description, maps to).
std::string option_table_markdown(const OptionTable& table);
/// The reference page of every table (Markdown), as committed in docs/user/scenario-reference.md.
std::string scenario_reference_markdown();

/// A range as the messages and the reference write it: "[0, 5)", integers "1..20".
std::string range_text(const Range& r, OptionType type);
/// "a, b, c"
std::string join_names(const std::vector<std::string>& names);
/// The names of an engine's name table, as an option's choices.
template <class E, std::size_t N>
std::vector<std::string> names_of(const engine::NameTable<E, N>& table) {
  std::vector<std::string> v;
  for (const auto& [name, value] : table) v.emplace_back(name);
  return v;
}

}  // namespace runout::jobs
