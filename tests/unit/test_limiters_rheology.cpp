#include <gtest/gtest.h>

#include <cmath>

#include "engine/limiters.hpp"
#include "engine/rheology.hpp"
#include "tests/support/depth_averaged.hpp"

using namespace runout::engine;
using namespace runout::test_support::depth_averaged;

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

namespace {

// The law's value through the kernels' function.
double mu_of(const BasalFriction& f, double h, double fr, double gn = 9.81) {
  const double speed = fr * std::sqrt(gn * h);
  return f.form() == MuForm::hysteresis ? flow_mu<true>(f, h, speed, gn) : flow_mu<false>(f, h, speed, gn);
}

}  // namespace

TEST(FlowFriction, PouliquenForterreFollowsItsBranches) {
  const auto m = glass_beads_pf(22.0, 0.05);
  ASSERT_NO_THROW(m.validate());
  const auto f = m.friction();
  ASSERT_EQ(f.form(), MuForm::hysteresis);
  const double t1 = std::tan(m.delta1), t2 = std::tan(m.delta2), t3 = std::tan(m.delta3), L = m.pf_length;
  const double beta = m.pf_beta, gamma = m.pf_gamma;
  for (double h : {0.2e-3, 1e-3, 3e-3, 1e-2}) {
    const double mu_stop = t1 + (t2 - t1) / (h / L + 1), mu_start = t3 + (t2 - t1) / (h / L + 1);
    EXPECT_NEAR(mu_of(f, h, 0.0), mu_start, 1e-14) << h;                 // at rest
    EXPECT_NEAR(mu_of(f, h, beta - gamma), mu_stop, 1e-14) << h;         // the branches meet
    for (double fr : {0.2, 0.5, 1.3, 4.0}) {                             // flowing
      const double dyn = t1 + (t2 - t1) / (beta * h / (L * (fr + gamma)) + 1);
      EXPECT_NEAR(mu_of(f, h, fr), dyn, 1e-14) << h << " " << fr;
    }
    const double fr = 0.5 * (beta - gamma);  // slower: (Fr / (beta - gamma))^kappa between the two
    EXPECT_NEAR(mu_of(f, h, fr), std::pow(0.5, 1e-3) * (mu_stop - mu_start) + mu_start, 1e-14);
  }
  // The steady flow rule: on a slope theta, Fr = beta h / h_stop(theta) - gamma has mu = tan(theta).
  const double th = 27 * kDeg, hstop = L * (t2 - std::tan(th)) / (std::tan(th) - t1);
  for (double h : {1.5 * hstop, 4 * hstop}) EXPECT_NEAR(mu_of(f, h, beta * h / hstop - gamma), std::tan(th), 1e-14);
}

TEST(FlowFriction, MuIIsTheBagnoldProfilesBasalFriction) {
  const auto m = glass_beads_mu_i();
  ASSERT_NO_THROW(m.validate());
  const auto f = m.friction();
  ASSERT_EQ(f.form(), MuForm::flow);
  for (double h : {1e-3, 5e-3, 0.02})
    for (double fr : {0.0, 0.1, 0.7, 3.0}) {
      // I = gamma_dot d / sqrt(p / rho_s) at the base of the Bagnold profile: depth-averaged
      // u = (2/5) I sqrt(phi g cos) h^(3/2) / d, so I = 5 Fr d / (2 sqrt(phi) h).
      const double I = 5 * fr * m.grain_diameter / (2 * std::sqrt(0.6) * h);
      const double expect = fr == 0 ? m.mu_s : m.mu_s + (m.mu_2 - m.mu_s) / (m.mu_i0 / I + 1);
      EXPECT_NEAR(mu_of(f, h, fr), expect, 1e-14) << h << " " << fr;
    }
}

TEST(FlowFriction, ConstantLimitAndEdgesAreExact) {
  // mu_2 = mu_s: mu(I) is the constant mu_s, bit for bit, for every state (the engines' Coulomb limit).
  const auto f = mu_i_material(std::tan(0.4), std::tan(0.4), 0.3, 0.01, 2500, 1500).friction();
  for (double h : {0.0, 1e-300, 1e-6, 2.0})
    for (double speed : {0.0, 1e-300, 0.3, 80.0})
      for (double gn : {0.0, 9.81, 30.0}) EXPECT_EQ(flow_mu<false>(f, h, speed, gn), std::tan(0.4));
  // Every law's mu stays finite on a dry cell, at rest and without load.
  const auto pf = glass_beads_pf(23.0, 0.02).friction();
  for (double h : {0.0, 1e-3})
    for (double speed : {0.0, 1.0})
      for (double gn : {0.0, 9.81}) EXPECT_TRUE(std::isfinite(flow_mu<true>(pf, h, speed, gn)));
}

TEST(FlowFriction, BadParametersAreRejectedNamingTheField) {
  auto expect = [](const Material& m, const std::string& field) {
    try {
      m.validate();
      ADD_FAILURE() << "accepted, expected an error naming " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  auto m = glass_beads_pf(22.0, 0.0);
  m.delta2 = m.delta1;
  expect(m, "bed_friction_2_deg");
  m = glass_beads_pf(19.0, 0.0);
  expect(m, "bed_friction_3_deg");
  m = glass_beads_pf(22.0, 0.0);
  m.pf_beta = 0;
  expect(m, "pf_beta");
  m = glass_beads_pf(22.0, 0.0);
  m.pf_length = -1e-3;
  expect(m, "pf_length_m");
  expect(glass_beads_pf(22.0, -0.1), "pf_gamma");
  expect(glass_beads_pf(22.0, 0.2), "pf_gamma");  // gamma >= beta: no static branch left
  auto i = mu_i_material(0.4, 0.3, 0.3, 1e-3, 2500, 1500);
  expect(i, "mu_2");
  i.mu_2 = 0.6;
  i.grain_diameter = 0;
  expect(i, "grain_diameter_m");
  i.grain_diameter = 1e-3;
  i.density = 3000;  // phi > 1
  expect(i, "grain_density_kg_m3");
  i.density = 1500;
  i.mu_i0 = 0;
  expect(i, "mu_i0");
}
