// A granular viscosity model and a boundary condition that are in neither of the engine's tables,
// each defined here as a production one would be in its own file (its class and its row) and added
// with one line (add_granular_viscosity, add_boundary_condition): the scenario's checks take them,
// the option tables and the reference page describe them, and the 3D solver runs them. Each is an
// existing one in other words (the Coulomb viscosity with the coefficient mu_s for tan(phi); the stick
// wall), so that the runs must agree with the built-in ones bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/bc/conditions.hpp"
#include "engine/vof/models/registry.hpp"
#include "engine/vof/solver.hpp"
#include "jobs/drivers/run.hpp"
#include "jobs/drivers/vof_lab/config.hpp"
#include "jobs/scenario/options.hpp"
#include "jobs/scenario/scenario.hpp"
#include "tests/support/run_record.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/vof_box.hpp"

namespace {

using namespace runout;
using namespace runout::engine::vof;

// The example rheology: a friction coefficient instead of an angle, nu = mu_s p / (rho1 |strain rate|).
class FrictionCoefficientViscosity final : public GranularViscosity {
 public:
  explicit FrictionCoefficientViscosity(const VofConfig& c) : mu_(c.mu_i.mu_s), rho1_(c.rho1), nu_min_(c.nu_min), nu_max_(c.nu_max) {}
  double nu(double p, double sr) const override {
    const double nu = mu_ * p / (rho1_ * std::max(sr, 1e-300));
    return std::clamp(std::isfinite(nu) ? nu : nu_max_, nu_min_, nu_max_);
  }

 private:
  double mu_, rho1_, nu_min_, nu_max_;
};

constexpr GranularViscosityModel kExampleModel{
    "example_friction_coefficient",
    "friction-coefficient viscosity",
    "nu = mu_s p / (rho \\|strain rate\\|) (an example model of the unit tests)",
    {{{"mu_s", "mu_s", "μs", "", 0, 5, true, false, "the friction coefficient", [](VofConfig& c) -> double& { return c.mu_i.mu_s; }}}},
    [](const VofConfig& c) -> ModelProblem {
      if (c.mu_i.mu_s <= 1.5) return {};
      return {"mu_s", "example model: must not exceed 1.5"};
    },
    [](const VofConfig& c) -> std::unique_ptr<GranularViscosity> { return std::make_unique<FrictionCoefficientViscosity>(c); }};

// The example boundary condition: a stick wall.
class ExampleStick final : public BoundaryCondition {
 public:
  Vec velocity(const BcContext&, int) const override { return {}; }
  void momentum(const BcContext& c, int f, const Vec& Ub, double& diag, Vec& source) const override {
    wall_shear(c, f, Ub, c.wall_viscosity == WallViscosity::face, alpha(c, f), diag, source);
  }
};
constexpr BoundaryConditionRow kExampleCondition{"example_stick", "example stick wall", "an example condition of the unit tests: a stick wall",
                                                 true, false};
std::unique_ptr<BoundaryCondition> make_example_stick(const std::string&, const PatchBc&) { return std::make_unique<ExampleStick>(); }

// The one line each.
const bool kModelAdded = add_granular_viscosity(kExampleModel);
const bool kConditionAdded = add_boundary_condition(kExampleCondition, make_example_stick);

// The heap of tests/support/vof_box.hpp collapsing for 0.2 s with `rheology` and `bottom`.
test_support::CollapsedHeap collapse(const std::string& rheology, const std::string& bottom) {
  auto c = test_support::box_config();
  c.phi_deg = 30;
  c.rheology = rheology;
  c.mu_i.mu_s = std::tan(c.phi_deg * 3.14159265358979323846 / 180);
  c.bc["bottom"].type = bottom;
  return test_support::collapse_heap(c, 0.2);
}

}  // namespace

TEST(ExampleModels, TheExampleRheologyAndConditionRunInTheSolverAsTheirBuiltInTwins) {
  ASSERT_TRUE(kModelAdded && kConditionAdded);
  test_support::expect_same_collapse(collapse("coulomb", "wall"), collapse("example_friction_coefficient", "example_stick"));
  // The row's check comes before the model is made.
  auto c = test_support::box_config();
  c.rheology = "example_friction_coefficient";
  c.mu_i.mu_s = 2;
  try {
    VofSolver s(test_support::box(), c);
    ADD_FAILURE() << "mu_s = 2 accepted";
  } catch (const VofError& e) {
    EXPECT_NE(std::string(e.what()).find("mu_s example model: must not exceed 1.5"), std::string::npos) << e.what();
  }
}

namespace {

std::string lab_scenario(const std::string& rheology, const std::string& bottom, const std::string& more = "") {
  return R"({"engine": "vof", "lab": {"x_max": 0.2, "y_max": 0.1, "nx": 20, "ny": 10, "end_time_s": 0.1, "write_interval_s": 0,
      "fill": [{"x_max": 0.08, "y_max": 0.06}], "rheology": ")" +
         rheology + "\"" + more + R"(, "boundaries": [{"side": "top", "kind": "atmosphere"}, {"side": "bottom", "kind": ")" + bottom +
         R"("}]}})";
}

std::string resolve_error(const std::string& json) {
  try {
    jobs::resolve_scenario(jobs::parse_scenario_json(json), ".");
  } catch (const jobs::ScenarioError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(ExampleModels, TheScenarioTakesThemAndTheReferenceDescribesThem) {
  const auto& kinds = jobs::option(jobs::lab_options(), "lab.boundaries[].kind").choices;
  EXPECT_NE(std::find(kinds.begin(), kinds.end(), "example-stick"), kinds.end());
  const auto& beds = jobs::option(jobs::terrain_vof_options(), "vof.bed").choices;
  EXPECT_NE(std::find(beds.begin(), beds.end(), "example-stick"), beds.end());
  const auto& rheologies = jobs::option(jobs::lab_options(), "lab.rheology").choices;
  EXPECT_NE(std::find(rheologies.begin(), rheologies.end(), "example_friction_coefficient"), rheologies.end());
  EXPECT_NE(jobs::option(jobs::lab_options(), "lab.mu_s").doc.find("example_friction_coefficient"), std::string::npos);
  const std::string page = jobs::scenario_reference_markdown();
  EXPECT_NE(page.find("| `example_friction_coefficient` | friction-coefficient viscosity: nu = mu_s p / (rho"), std::string::npos);
  EXPECT_NE(page.find("| `example-stick` | example stick wall: an example condition of the unit tests"), std::string::npos);

  EXPECT_EQ(resolve_error(lab_scenario("example_friction_coefficient", "example-stick", R"(, "mu_s": 0.5)")), "no error");
  EXPECT_EQ(resolve_error(lab_scenario("example_friction_coefficient", "wall", R"(, "mu_s": 2)")),
            "lab.mu_s: example model: must not exceed 1.5");
  EXPECT_NE(resolve_error(lab_scenario("example_friction_coefficient", "wall", R"(, "mu_s": 0)")).find("lab.mu_s: must lie in (0, 5]"),
            std::string::npos);
  EXPECT_NE(resolve_error(lab_scenario("bingham", "wall")).find("lab.rheology: unknown 'bingham'"), std::string::npos);
  EXPECT_NE(resolve_error(lab_scenario("coulomb", "sticky")).find("lab.boundaries[1].kind: unknown 'sticky'"), std::string::npos);
  const auto r = jobs::resolve_scenario(jobs::parse_scenario_json(lab_scenario("example_friction_coefficient", "wall", R"(, "mu_s": 0.5)")), ".");
  const auto c = jobs::vof_lab::lab_config(r.scenario.lab(), jobs::vof_lab::lab_material(r.scenario.lab()));
  EXPECT_EQ(c.rheology, "example_friction_coefficient");
  EXPECT_EQ(c.mu_i.mu_s, 0.5);
}

// Through the run driver: the lab set-up with the example rheology (PVC's default mu_s, tan 32 deg)
// and the example bottom ends where the Coulomb viscosity (PVC's phi, 32 deg) on a stick wall does.
TEST(ExampleModels, ALabRunWithThemIsTheBuiltInRun) {
  double front[2], iterations[2];
  const char* models[2][2] = {{"coulomb", "wall"}, {"example_friction_coefficient", "example-stick"}};
  for (int k = 0; k < 2; ++k) {
    const auto r = jobs::resolve_scenario(jobs::parse_scenario_json(lab_scenario(models[k][0], models[k][1])), ".");
    test_support::TempDir d;
    ASSERT_EQ(jobs::run_scenario(r, d.p.string()).stop, "end-time");
    front[k] = test_support::record_figure(d.p / "run.json", "front_x_m");
    iterations[k] = test_support::record_figure(d.p / "run.json", "pressure_iterations");
  }
  EXPECT_GT(front[0], 0.08);  // it flowed
  EXPECT_EQ(front[0], front[1]);
  EXPECT_EQ(iterations[0], iterations[1]);
}
