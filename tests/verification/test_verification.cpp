// Every verification case of `runout verify` at its default resolutions: each row within tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "engine/verification/cases.hpp"

namespace ver = runout::engine::verification;

class Verification : public ::testing::TestWithParam<std::string> {};

TEST_P(Verification, EveryFigureWithinTolerance) {
  const auto rows = ver::run_case(GetParam(), ver::Options{});
  ASSERT_FALSE(rows.empty());
  int checked = 0;
  for (const auto& r : rows) {
    for (const auto& m : r.metrics) {
      EXPECT_TRUE(m.ok()) << r.case_id << " " << r.variant << " dx=" << r.dx << ": " << m.name << " = " << m.value
                          << " (limit " << m.limit << ")";
      checked += !std::isnan(m.limit);
    }
  }
  EXPECT_GT(checked, 0) << "a case must check at least one figure";
}

INSTANTIATE_TEST_SUITE_P(Cases, Verification, ::testing::ValuesIn(ver::case_ids()),
                         [](const auto& info) { return info.param; });

TEST(VerificationHarness, UnknownCaseIsRejected) {
  EXPECT_THROW(ver::run_case("A9", ver::Options{}), std::invalid_argument);
}

TEST(VerificationHarness, ConvergenceOrdersAreReported) {
  const auto rows = ver::run_case("A1", ver::Options{});
  int with_order = 0;
  for (const auto& r : rows) with_order += std::isfinite(r.order);
  EXPECT_GE(with_order, 4);  // 1D: four resolutions -> three orders; 2D: two more
  for (const auto& r : rows) {
    if (std::isfinite(r.order)) {
      EXPECT_GT(r.order, 0.7);
    }
  }
}

// The VOF engine's cases (vof_cases.cpp) are in the same list, after the depth-averaged ones, with
// their descriptions (`runout verify` lists and dispatches them from it).
TEST(VerificationHarness, VofCasesAreListed) {
  const auto ids = ver::case_ids();
  for (const char* id : {"V1", "V2", "V3", "V4", "V5", "V6", "V7"}) {
    EXPECT_NE(std::find(ids.begin(), ids.end(), id), ids.end()) << id;
    EXPECT_NE(ver::describe(id).find("VOF"), std::string::npos) << id;
  }
  EXPECT_EQ(ids.front(), "A1");
}
