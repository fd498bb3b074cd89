#pragma once
// Ensembles: a scenario with a `variations` block stands for many runs, and so does one with a
// `zoning` block (one run per return period). This file turns the block into its members (each a
// whole scenario of its own, without the block) and into the settings of the aggregate. Everything here is deterministic: the same scenario gives the same members, in the same
// order, on every machine (the random draws use std::mt19937_64, whose sequence the standard fixes,
// and our own mapping from its integers to numbers).
#include <cstdint>
#include <string>
#include <vector>

#include "jobs/scenario/scenario.hpp"
#include "runout/v1/scenario.pb.h"

namespace runout::jobs::ensemble {

/// One varied parameter's value in a member.
struct ParameterValue {
  std::string parameter;  ///< as the variation names it ("material.bed_friction_deg")
  double value = 0;
};

/// One member: its place in the ensemble, the values that make it, and its scenario.
struct Member {
  int index = 0;
  double return_period_y = 0;  ///< a zoning's member: its return period (0 in a variations ensemble)
  std::vector<ParameterValue> values;
  v1::Scenario scenario;  ///< the ensemble's scenario with the values set, without `variations`
};

/// What the aggregate computes (variations' thresholds and percentiles, defaults filled in).
struct AggregateSettings {
  std::vector<double> depth_m;       ///< probability of max depth > each
  std::vector<double> speed_m_s;     ///< probability of max speed >= each
  std::vector<double> pressure_kpa;  ///< probability of max pressure >= each
  std::vector<double> percentiles;   ///< of max depth, speed and pressure per cell, ascending, in [0, 100]
  bool maps = true;                  ///< the aggregate's maps (outputs.maps)
  std::string name;                  ///< the scenario's name (the maps' titles)
  /// A zoning (scenario zoning): its rule, defaults filled in (0: not a zoning).
  double red_pressure_kpa = 0, frequent_y = 0, design_y = 0;
  std::vector<double> return_periods_y;  ///< per member, in order (plan fills it; part of the hash)
  bool zoning() const { return design_y > 0; }
};

/// The most members one ensemble may have.
inline constexpr int kMaxMembers = 100000;

/// The version of what an ensemble's aggregate contains; part of its hash (ensemble_hash).
inline constexpr int kEnsembleResultsVersion = 1;

/// Whether the scenario is an ensemble (has a `variations` or a `zoning` block).
bool is_ensemble(const v1::Scenario& s);

/// The members of an ensemble's scenario, in order (a zoning's by ascending return period). Throws
/// ScenarioError naming the field ("variations.parameters[1].percent: ...",
/// "zoning.scenarios[2].values: ...") for a block that does not make members: an unknown parameter,
/// a value the parameter cannot take, no values, too many members, both blocks, a return period
/// given twice.
std::vector<Member> expand(const v1::Scenario& s);

/// The aggregate's settings of a resolved ensemble scenario.
AggregateSettings aggregate_settings(const ResolvedScenario& r);

/// The ensemble's hash: its members' hashes in order, the aggregate's settings (thresholds,
/// percentiles, maps and the name in their titles; a zoning's rule and each member's return period)
/// and its results version. Two ensembles with the same hash have the same aggregate.
std::string ensemble_hash(const std::vector<std::string>& member_hashes, const AggregateSettings& a);

/// An ensemble ready to be queued: each member resolved (validated) and hashed, and the ensemble's hash.
struct Plan {
  struct Resolved {
    Member member;
    std::string hash;
  };
  std::vector<Resolved> members;
  AggregateSettings settings;
  std::string hash;
};
/// Expand and resolve every member of a resolved ensemble scenario whose input paths are absolute
/// (jobs/scenario/inputs.hpp, absolute_inputs; the service's are after its checks).
/// Throws ScenarioError or terrain::TerrainError; a member's error names the member and its values.
Plan plan(const ResolvedScenario& ensemble);

/// "material.bed_friction_deg = 17, releases[].thickness_factor = 1.2"
std::string describe(const std::vector<ParameterValue>& values);

/// A varied parameter's path in words for the maps and the report: "releases[].thickness_factor" is
/// "release thickness factor", "releases[0].thickness_m" "release 1 thickness" in m,
/// "material.bed_friction_deg" "bed friction angle" in °, "grid.resolution_m" "grid resolution" in m
/// (the unit from the field's suffix, as the scenario's fields name it).
struct ParameterWords {
  std::string words, unit;  ///< unit "" for a number without one
};
ParameterWords parameter_in_words(const std::string& path);

/// The number at `path` in the scenario ("material.bed_friction_deg", "releases[0].thickness_m");
/// false when the path names no number or the number is unset.
bool number_at(const v1::Scenario& s, const std::string& path, double& value);

/// The standard normal distribution's quantile function (Wichura's AS 241, relative error ~1e-16).
double normal_quantile(double p);

}  // namespace runout::jobs::ensemble
