#include <gtest/gtest.h>

#include <cmath>

#include "engine/limiters.hpp"
#include "engine/rheology.hpp"

using namespace runout::engine;
constexpr double kDeg = M_PI / 180.0;

TEST(Limiters, MinmodPicksTheSmallerSlopeAndZeroAtExtrema) {
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::minmod, 1.0, 3.0), 1.0);
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::minmod, -2.0, -0.5), -0.5);
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::minmod, 1.0, -1.0), 0.0);
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::minmod, 0.0, 2.0), 0.0);
}

TEST(Limiters, VanLeerIsTheHarmonicMean) {
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::vanleer, 1.0, 3.0), 2.0 * 3.0 / 4.0);
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::vanleer, 1.0, -3.0), 0.0);
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::vanleer, 2.0, 2.0), 2.0);
}

TEST(Limiters, SuperbeeFollowsRoe) {
  // theta = a/b = 0.25: phi = max(min(0.5, 1), min(0.25, 2)) = 0.5
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::superbee, 1.0, 4.0), 2.0);
  // theta = 1.5: phi = max(min(3, 1), min(1.5, 2)) = 1.5
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::superbee, 3.0, 2.0), 3.0);
  // theta = 4: phi = 2
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::superbee, 4.0, 1.0), 2.0);
  EXPECT_DOUBLE_EQ(limited_slope(Limiter::superbee, -1.0, 1.0), 0.0);
}

TEST(Limiters, AllStayInTheSecondOrderTvdRegion) {
  for (auto l : {Limiter::minmod, Limiter::vanleer, Limiter::superbee})
    for (double th = -2; th <= 6; th += 0.25) {
      const double phi = limited_slope(l, th, 1.0);
      EXPECT_GE(phi, 0.0);
      EXPECT_LE(phi, std::max(0.0, std::min(2 * th, 2.0)) + 1e-15);
    }
}

TEST(Names, UnknownNameListsTheValidOnes) {
  EXPECT_EQ(parse_name(kLimiterNames, "limiter", "vanleer"), Limiter::vanleer);
  try {
    parse_name(kLimiterNames, "limiter", "vanLeer");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "unknown limiter 'vanLeer' (valid: minmod, vanleer, superbee)");
  }
  EXPECT_THROW(friction_law("bingham"), std::invalid_argument);
}

TEST(EarthPressure, ActiveBelowOnePassiveAbove) {
  const double phi = 30 * kDeg, delta = 20 * kDeg;
  const double ka = k_x(phi, delta, true), kp = k_x(phi, delta, false);
  EXPECT_LT(ka, 1.0);
  EXPECT_GT(kp, 1.0);
  // Savage & Hutter 1989: K_act + K_pass = 4 / cos^2(phi) - 2.
  EXPECT_NEAR(ka + kp, 4 / std::pow(std::cos(phi), 2) - 2, 1e-12);
  // delta = phi: both equal (1 + sin^2 phi) / cos^2 phi.
  const double kk = (1 + std::pow(std::sin(phi), 2)) / std::pow(std::cos(phi), 2);
  EXPECT_NEAR(k_x(phi, phi, true), kk, 1e-12);
  EXPECT_NEAR(k_x(phi, phi, false), kk, 1e-12);
}

TEST(EarthPressure, CrossSlopeCoefficientBracketsTheDownslopeOne) {
  const double delta = 20 * kDeg;
  for (double kx : {0.6, 1.0, 2.5}) {
    const double a = k_y(kx, delta, true), p = k_y(kx, delta, false);
    EXPECT_LE(a, p);
    // The roots satisfy (K_y - K_x)(K_y - 1) = tan^2(delta).
    EXPECT_NEAR((a - kx) * (a - 1), std::pow(std::tan(delta), 2), 1e-12);
    EXPECT_NEAR((p - kx) * (p - 1), std::pow(std::tan(delta), 2), 1e-12);
  }
}

TEST(Friction, StopsExactlyAndNeverReverses) {
  double mx = 3.0, my = -4.0;  // |m| = 5
  EXPECT_FALSE(apply_friction(mx, my, 5.0, 2.0));
  EXPECT_NEAR(mx, 3.0 * 0.6, 1e-15);
  EXPECT_NEAR(my, -4.0 * 0.6, 1e-15);
  EXPECT_TRUE(apply_friction(mx, my, 3.0, 7.0));
  EXPECT_EQ(mx, 0.0);
  EXPECT_EQ(my, 0.0);
  double a = 0, b = 0;
  EXPECT_TRUE(apply_friction(a, b, 0.0, 0.0));
}

TEST(Material, ValidationNamesTheParameter) {
  Material m;
  m.delta = -1 * kDeg;
  EXPECT_THROW(m.validate(), std::invalid_argument);
  m.delta = 25 * kDeg;
  m.earth_pressure = EarthPressure::active_passive;
  m.phi = 20 * kDeg;
  try {
    m.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("delta <= phi"), std::string::npos);
  }
  m.phi = 30 * kDeg;
  EXPECT_NO_THROW(m.validate());
  m.rheology = &friction::voellmy;
  m.mu = 0.2;
  m.xi = 0;
  EXPECT_THROW(m.validate(), std::invalid_argument);
}
