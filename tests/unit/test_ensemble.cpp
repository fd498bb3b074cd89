// Ensembles: the members a `variations` block makes (cross product, latin hypercube, lists, ranges,
// percentages, distributions, releases left out) and the aggregate's statistics in the cases whose
// answer is exact (identical members: 0 or 1; two members: 0.5; percentiles of known values).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "jobs/ensemble/statistics.hpp"
#include "jobs/ensemble/variations.hpp"
#include "jobs/scenario/inputs.hpp"
#include "jobs/scenario/scenario.hpp"

using namespace runout;
namespace ens = runout::jobs::ensemble;

namespace {

const std::string kSrc = RUNOUT_SOURCE_DIR;

std::string read_text(const std::string& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

v1::Scenario arelen() { return jobs::parse_scenario_json(read_text(kSrc + "/tests/data/arelen-30m.json")); }

v1::Variation* vary(v1::Scenario& s, const std::string& parameter) {
  auto* v = s.mutable_variations()->add_parameters();
  v->set_parameter(parameter);
  return v;
}

void values(v1::Variation* v, std::initializer_list<double> x) {
  for (double d : x) v->add_values(d);
}

std::string expand_error(const v1::Scenario& s) {
  try {
    ens::expand(s);
  } catch (const jobs::ScenarioError& e) {
    return e.what();
  }
  return "";
}

ens::MemberStack stack_of(const std::vector<std::vector<float>>& members) {
  ens::MemberStack s;
  s.cells = members.front().size();
  s.members = int(members.size());
  for (const auto& m : members) s.v.insert(s.v.end(), m.begin(), m.end());
  return s;
}

}  // namespace

TEST(Ensemble, CrossProductTakesEveryCombinationLastParameterFastest) {
  auto s = arelen();
  values(vary(s, "material.bed_friction_deg"), {14, 16});
  auto* t = vary(s, "releases[].thickness_factor");
  t->set_from(0.8);
  t->set_to(1.2);
  t->set_step(0.2);
  const auto m = ens::expand(s);
  ASSERT_EQ(m.size(), 6u);
  EXPECT_EQ(m[0].values[0].value, 14);
  EXPECT_DOUBLE_EQ(m[0].values[1].value, 0.8);
  EXPECT_DOUBLE_EQ(m[1].values[1].value, 1.0);
  EXPECT_EQ(m[3].values[0].value, 16);
  EXPECT_DOUBLE_EQ(m[5].scenario.releases(0).thickness_factor(), 0.8 + 2 * 0.2);
  EXPECT_EQ(m[4].scenario.material().bed_friction_deg(), 16);
  for (std::size_t k = 0; k < m.size(); ++k) {
    EXPECT_EQ(m[k].index, int(k));
    EXPECT_FALSE(m[k].scenario.has_variations());
    EXPECT_FALSE(m[k].scenario.outputs().maps());  // members write rasters and run.json only
  }
}

TEST(Ensemble, PercentAroundTheScenariosOwnValueOrTheDefault) {
  auto s = arelen();
  auto* d = vary(s, "material.bed_friction_deg");
  d->set_percent(20);
  auto* t = vary(s, "releases[].thickness_factor");  // unset: its default 1
  t->set_percent(10);
  t->set_count(2);
  const auto m = ens::expand(s);
  ASSERT_EQ(m.size(), 6u);
  EXPECT_DOUBLE_EQ(m[0].values[0].value, 12);
  EXPECT_DOUBLE_EQ(m[2].values[0].value, 15);
  EXPECT_DOUBLE_EQ(m[4].values[0].value, 18);
  EXPECT_DOUBLE_EQ(m[0].values[1].value, 0.9);
  EXPECT_DOUBLE_EQ(m[1].values[1].value, 1.1);
}

TEST(Ensemble, AMemberWithTheScenariosOwnValuesIsTheSingleRun) {
  // With member_outputs "all" a member is the scenario itself: the same hash, so a result computed
  // by a single run answers it.
  auto s = arelen();
  values(vary(s, "material.bed_friction_deg"), {15, 17});
  s.mutable_variations()->set_member_outputs("all");
  const auto m = ens::expand(s);
  const std::string dir = kSrc + "/tests/data";
  EXPECT_EQ(jobs::scenario_hash(jobs::resolve_scenario(m[0].scenario, dir)), jobs::scenario_hash(jobs::resolve_scenario(arelen(), dir)));
  EXPECT_NE(jobs::scenario_hash(jobs::resolve_scenario(m[1].scenario, dir)), jobs::scenario_hash(jobs::resolve_scenario(arelen(), dir)));
}

TEST(Ensemble, LatinHypercubeUsesEachStratumOnceAndIsReproducible) {
  auto s = arelen();
  s.mutable_variations()->set_design("latin-hypercube");
  s.mutable_variations()->set_samples(20);
  auto* d = vary(s, "material.bed_friction_deg");
  d->set_from(12);
  d->set_to(18);
  auto* n = vary(s, "material.density_kg_m3");
  n->set_distribution("normal");
  n->set_mean(300);
  n->set_sd(30);
  const auto a = ens::expand(s), b = ens::expand(s);
  ASSERT_EQ(a.size(), 20u);
  std::set<int> strata_d, strata_n;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].values[0].value, b[k].values[0].value);  // the same seed: the same members
    EXPECT_EQ(a[k].values[1].value, b[k].values[1].value);
    strata_d.insert(int(std::floor((a[k].values[0].value - 12) / 6 * 20)));
    // The normal's strata: its probability, cut into 20.
    strata_n.insert(int(std::floor(0.5 * std::erfc(-(a[k].values[1].value - 300) / 30 / std::sqrt(2.0)) * 20)));
  }
  EXPECT_EQ(strata_d.size(), 20u);
  EXPECT_EQ(strata_n.size(), 20u);
  s.mutable_variations()->set_seed(7);
  EXPECT_NE(ens::expand(s)[0].values[0].value, a[0].values[0].value);
}

TEST(Ensemble, NormalQuantileMatchesKnownValues) {
  EXPECT_NEAR(ens::normal_quantile(0.975), 1.959963984540054, 1e-14);
  EXPECT_NEAR(ens::normal_quantile(0.5), 0.0, 1e-15);
  EXPECT_NEAR(ens::normal_quantile(1e-10), -6.361340902404056, 1e-12);
}

TEST(Ensemble, DistributionsDrawTheirCountReproducibly) {
  auto s = arelen();
  auto* d = vary(s, "material.bed_friction_deg");
  d->set_distribution("uniform");
  d->set_from(13);
  d->set_to(17);
  d->set_count(5);
  const auto m = ens::expand(s);
  ASSERT_EQ(m.size(), 5u);
  for (const auto& x : m) {
    EXPECT_GE(x.values[0].value, 13);
    EXPECT_LE(x.values[0].value, 17);
  }
  EXPECT_EQ(ens::expand(s)[3].values[0].value, m[3].values[0].value);
}

TEST(Ensemble, AReleaseLeftOutAndMembersWithoutAnyReleaseSkipped) {
  auto s = arelen();
  *s.add_releases() = s.releases(0);
  s.mutable_releases(1)->set_thickness_m(1.5);
  s.mutable_releases(1)->clear_thickness_attribute();
  values(vary(s, "releases[0].active"), {0, 1});
  values(vary(s, "releases[1].active"), {0, 1});
  const auto m = ens::expand(s);
  ASSERT_EQ(m.size(), 3u);  // (0, 0) releases nothing
  EXPECT_EQ(m[0].scenario.releases_size(), 1);
  EXPECT_TRUE(m[0].scenario.releases(0).has_thickness_m());  // release 0 left out: release 1 remains
  EXPECT_EQ(m[2].scenario.releases_size(), 2);
}

TEST(Ensemble, ErrorsNameTheField) {
  auto s = arelen();
  vary(s, "material.no_such_thing")->add_values(1);
  EXPECT_NE(expand_error(s).find("variations.parameters[0].parameter: 'material.no_such_thing' is not a number"), std::string::npos)
      << expand_error(s);
  s = arelen();
  vary(s, "material.bed_friction_deg")->set_from(13);
  EXPECT_NE(expand_error(s).find("variations.parameters[0]: a range needs from and to"), std::string::npos) << expand_error(s);
  s = arelen();
  vary(s, "releases[3].thickness_m")->add_values(1);
  EXPECT_NE(expand_error(s).find("releases[3]: the scenario has 1"), std::string::npos) << expand_error(s);
  s = arelen();
  s.mutable_variations();
  EXPECT_EQ(expand_error(s), "variations.parameters: at least one parameter to vary");
  s = arelen();
  auto* r = vary(s, "material.bed_friction_deg");
  r->set_from(0);
  r->set_to(1e6);
  r->set_step(1);
  EXPECT_NE(expand_error(s).find("at most 100000"), std::string::npos) << expand_error(s);
  s = arelen();
  vary(s, "material.bed_friction_deg")->add_values(14);
  vary(s, "material.bed_friction_deg")->add_values(15);
  EXPECT_NE(expand_error(s).find("is varied twice"), std::string::npos);
}

TEST(Ensemble, AMemberOutsideTheValidRangeIsNamedByThePlan) {
  auto s = arelen();
  values(vary(s, "material.bed_friction_deg"), {15, 95});
  jobs::absolute_inputs(s, kSrc + "/tests/data");
  const auto r = jobs::resolve_scenario(s, "/");
  try {
    ens::plan(r);
    FAIL();
  } catch (const jobs::ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("variations: member 1 (material.bed_friction_deg = 95): material.bed_friction_deg"),
              std::string::npos)
        << e.what();
  }
}

TEST(Ensemble, EnsembleHashFollowsTheMembersAndTheSettings) {
  ens::AggregateSettings a{{0.1}, {1}, {3, 30}, {5, 50, 95}, true, "arelen"};
  const auto h = ens::ensemble_hash({"m1", "m2"}, a);
  EXPECT_EQ(h, ens::ensemble_hash({"m1", "m2"}, a));
  EXPECT_NE(h, ens::ensemble_hash({"m2", "m1"}, a));
  a.percentiles = {50};
  EXPECT_NE(h, ens::ensemble_hash({"m1", "m2"}, a));
  a.percentiles = {5, 50, 95};
  a.maps = false;  // an aggregate without maps is another result
  EXPECT_NE(h, ens::ensemble_hash({"m1", "m2"}, a));
}

TEST(Ensemble, ARangeEndsOnItsUpperBound) {
  auto s = arelen();
  auto* r = vary(s, "material.bed_friction_deg");
  r->set_from(13);
  r->set_to(17.5);
  r->set_step(0.1);
  const auto m = ens::expand(s);
  ASSERT_EQ(m.size(), 46u);
  EXPECT_EQ(m.back().values[0].value, 17.5);
}

TEST(EnsembleStatistics, IdenticalMembersGiveProbabilitiesOfExactlyZeroOrOne) {
  const std::vector<float> m = {0.0f, 0.05f, 0.1f, 0.100001f, 2.0f, 30.0f};
  const auto s = stack_of({m, m, m, m, m});
  const auto p = ens::exceedance_probability(s, 0.1, true, {});
  const std::vector<double> want = {0, 0, 0, 1, 1, 1};
  EXPECT_EQ(p, want);
  const auto q = ens::exceedance_probability(s, 30, false, {});  // at least the threshold
  EXPECT_EQ(q, (std::vector<double>{0, 0, 0, 0, 0, 1}));
  const auto pc = ens::percentiles(s, {5, 50, 95}, {});
  for (std::size_t c = 0; c < m.size(); ++c)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(pc[std::size_t(k)][c], double(m[c]));
}

TEST(EnsembleStatistics, TwoMembersGiveExactlyOneHalfWhereOneExceeds) {
  const auto s = stack_of({{0.0f, 1.0f, 5.0f, 0.2f}, {0.0f, 0.0f, 5.0f, 0.05f}});
  const auto p = ens::exceedance_probability(s, 0.1, true, {0, 0, 0, 1});
  EXPECT_EQ(p[0], 0.0);
  EXPECT_EQ(p[1], 0.5);
  EXPECT_EQ(p[2], 1.0);
  EXPECT_TRUE(std::isnan(p[3]));  // outside the domain
}

TEST(EnsembleStatistics, PercentilesInterpolateBetweenOrderStatistics) {
  // numpy.percentile([1, 2, 3, 4], [0, 25, 50, 90, 100]) = 1, 1.75, 2.5, 3.7, 4
  const auto s = stack_of({{4.0f}, {1.0f}, {3.0f}, {2.0f}});
  const auto p = ens::percentiles(s, {0, 25, 50, 90, 100}, {});
  EXPECT_DOUBLE_EQ(p[0][0], 1);
  EXPECT_DOUBLE_EQ(p[1][0], 1.75);
  EXPECT_DOUBLE_EQ(p[2][0], 2.5);
  EXPECT_DOUBLE_EQ(p[3][0], 3.7);
  EXPECT_DOUBLE_EQ(p[4][0], 4);
  std::vector<double> v = {10, 30, 20};
  EXPECT_DOUBLE_EQ(ens::percentile_of(v, 50), 20);
}

namespace {

// A zoning of the test scenario: return periods with the values given.
v1::ReturnPeriodScenario* period(v1::Scenario& s, double years, std::initializer_list<std::pair<const char*, double>> values) {
  auto* p = s.mutable_zoning()->add_scenarios();
  p->set_return_period_y(years);
  for (const auto& [name, value] : values) {
    auto* v = p->add_values();
    v->set_parameter(name);
    v->set_value(value);
  }
  return p;
}

}  // namespace

// A zoning makes one member per return period, ascending whatever the order given, each the scenario
// with its values set, its return period recorded, its own outputs (maps as the scenario says), and
// no zoning block.
TEST(Zoning, OneMemberPerReturnPeriodAscendingWithItsValues) {
  auto s = arelen();
  period(s, 300, {{"releases[].thickness_factor", 1.0}, {"material.bed_friction_deg", 15}});
  period(s, 30, {{"releases[].thickness_factor", 0.6}, {"material.bed_friction_deg", 18}});
  period(s, 100, {});
  ASSERT_TRUE(ens::is_ensemble(s));
  const auto m = ens::expand(s);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0].return_period_y, 30);
  EXPECT_EQ(m[1].return_period_y, 100);
  EXPECT_EQ(m[2].return_period_y, 300);
  EXPECT_EQ(m[0].scenario.material().bed_friction_deg(), 18);
  EXPECT_EQ(m[0].scenario.releases(0).thickness_factor(), 0.6);
  EXPECT_EQ(m[1].scenario.material().bed_friction_deg(), s.material().bed_friction_deg());  // the scenario's own
  EXPECT_EQ(ens::describe(m[0].values), "return_period_y = 30, releases[].thickness_factor = 0.6, material.bed_friction_deg = 18");
  for (const auto& x : m) {
    EXPECT_FALSE(x.scenario.has_zoning());
    EXPECT_FALSE(ens::is_ensemble(x.scenario));
    EXPECT_EQ(x.scenario.outputs().maps(), s.outputs().maps());
  }
}

// A zoning that cannot make its members is refused naming the field.
TEST(Zoning, ErrorsNameTheField) {
  auto s = arelen();
  period(s, 30, {});
  EXPECT_EQ(expand_error(s), "zoning.scenarios: at least two scenarios by return period (e.g. 30, 100 and 300 years)");
  period(s, 30, {});
  EXPECT_EQ(expand_error(s), "zoning.scenarios[1].return_period_y: 30 years is also scenarios[0]'s");
  s = arelen();
  period(s, 30, {});
  period(s, 300, {{"material.bed_friction_deg", 15}, {"material.no_such_thing", 1}});
  EXPECT_NE(expand_error(s).find("zoning.scenarios[1].values[1].parameter: 'material.no_such_thing' is not a number"), std::string::npos)
      << expand_error(s);
  s = arelen();
  period(s, 30, {{"material.bed_friction_deg", 15}, {"material.bed_friction_deg", 16}});
  period(s, 300, {});
  EXPECT_NE(expand_error(s).find("zoning.scenarios[0].values[1].parameter: 'material.bed_friction_deg' is given twice"), std::string::npos)
      << expand_error(s);
  s = arelen();
  period(s, 0.5, {});
  period(s, 300, {});
  EXPECT_EQ(expand_error(s), "zoning.scenarios[0].return_period_y: must be a whole number of years in [1, 100000], got 0.5");
  s = arelen();
  period(s, 30, {});
  period(s, 300, {})->add_values()->set_parameter("material.bed_friction_deg");
  EXPECT_EQ(expand_error(s), "zoning.scenarios[1].values[0].value: missing: the number this scenario gives 'material.bed_friction_deg'");
  s = arelen();
  period(s, 30, {});
  period(s, 300, {});
  s.mutable_zoning()->set_design_y(10);
  EXPECT_EQ(expand_error(s), "zoning.design_y: must lie in [frequent_y (30), 100000] years, got 10");
  vary(s, "material.bed_friction_deg")->add_values(14);
  EXPECT_EQ(expand_error(s), "zoning: a scenario takes variations or zoning, not both");
}

// The zoning's rule is part of its hash: another red pressure or return period is another result.
TEST(Zoning, HashFollowsTheRule) {
  ens::AggregateSettings a{{0.1}, {1}, {3, 30}, {5, 50, 95}, true, "arelen"};
  a.red_pressure_kpa = 30, a.frequent_y = 30, a.design_y = 300;
  const auto h = ens::ensemble_hash({"m1", "m2"}, a);
  a.red_pressure_kpa = 25;
  EXPECT_NE(h, ens::ensemble_hash({"m1", "m2"}, a));
  a.red_pressure_kpa = 30, a.design_y = 100;
  EXPECT_NE(h, ens::ensemble_hash({"m1", "m2"}, a));
  // The same members as other return periods: other zones (a member's hash does not hold its period).
  a.design_y = 300;
  a.return_periods_y = {30, 100};
  const auto h2 = ens::ensemble_hash({"m1", "m2"}, a);
  a.return_periods_y = {30, 1000};
  EXPECT_NE(h2, ens::ensemble_hash({"m1", "m2"}, a));
}

// The varied parameters in words on the ensemble's maps (not the scenario's field paths).
TEST(Ensemble, VariedParametersAreNamedInWordsWithTheirUnits) {
  auto w = jobs::ensemble::parameter_in_words("releases[].thickness_factor");
  EXPECT_EQ(w.words, "release thickness factor");
  EXPECT_EQ(w.unit, "");
  w = jobs::ensemble::parameter_in_words("releases[1].thickness_m");
  EXPECT_EQ(w.words, "release 2 thickness");
  EXPECT_EQ(w.unit, "m");
  w = jobs::ensemble::parameter_in_words("material.bed_friction_deg");
  EXPECT_EQ(w.words, "bed friction angle");
  EXPECT_EQ(w.unit, "°");
  w = jobs::ensemble::parameter_in_words("material.density_kg_m3");
  EXPECT_EQ(w.words, "density");
  EXPECT_EQ(w.unit, "kg/m³");
  w = jobs::ensemble::parameter_in_words("grid.resolution_m");
  EXPECT_EQ(w.words, "grid resolution");
  EXPECT_EQ(w.unit, "m");
  w = jobs::ensemble::parameter_in_words("material.voellmy_xi");
  EXPECT_EQ(w.words, "voellmy xi");
  EXPECT_EQ(w.unit, "");
}
