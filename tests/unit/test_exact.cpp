// The exact solutions themselves, against the reference numbers of docs/validation/verification.md.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/verification/exact.hpp"

using namespace runout::engine::exact;
constexpr double kDeg = M_PI / 180.0;

TEST(Exact, DamBreakReferenceNumbers) {
  const DamBreak d{22 * kDeg, 21 * kDeg, 1.0};
  EXPECT_NEAR(d.front(1), 6.124, 2e-3);
  EXPECT_NEAR(d.front(5), 32.451, 2e-3);
  EXPECT_NEAR(d.front(10), 69.488, 2e-3);
  double h, u;
  d.at(0, 1, h, u);
  EXPECT_NEAR(h, 0.4581, 2e-4);
  d.at(0, 5, h, u);
  EXPECT_NEAR(h, 0.5146, 2e-4);
  d.at(0, 10, h, u);
  EXPECT_NEAR(h, 0.5898, 2e-4);
  // Continuity at the rarefaction's tail and dry beyond the front.
  const double t = 3, xt = 0.5 * d.m() * t * t - d.c0() * t;
  d.at(xt + 1e-9, t, h, u);
  EXPECT_NEAR(h, 1.0, 1e-6);
  EXPECT_NEAR(u, d.m() * t, 1e-6);
  d.at(d.front(t) + 0.01, t, h, u);
  EXPECT_EQ(h, 0.0);
}

TEST(Exact, ParabolicCapDoublesAtTheReferenceTime) {
  const ParabolicCap c{35 * kDeg, 25 * kDeg, 1.0, 80.0, 4.0};
  EXPECT_NEAR(c.time_of(2.0), 16.196, 2e-3);
  EXPECT_NEAR(c.half_length(16.196), 160.0, 0.02);
  // Volume is conserved: integral of h = (4/3) H0 L0 at every time.
  for (double t : {0.0, 5.0, 12.0}) {
    double vol = 0;
    const double L = c.half_length(t), xc = c.centre(t), dx = L / 2000;
    for (double x = xc - L; x < xc + L; x += dx) {
      double h, u;
      c.at(x + 0.5 * dx, t, h, u);
      vol += h * dx;
    }
    EXPECT_NEAR(vol, 4.0 / 3.0 * 4.0 * 80.0, 1e-3);
  }
}

TEST(Exact, EllipticCapReferenceNumbers) {
  const EllipticCap e{35 * kDeg, 25 * kDeg, 1.0, 1.0, 80.0, 80.0, 4.0};
  auto s = e.at(5.0);
  EXPECT_NEAR(s.centre, 23.495, 5e-3);
  EXPECT_NEAR(s.max_depth, 3.4356, 5e-4);
  EXPECT_NEAR(s.half_length, 89.60, 0.01);
  EXPECT_NEAR(s.half_width, 83.16, 0.01);
  s = e.at(10.0);
  EXPECT_NEAR(s.centre, 93.980, 5e-3);
  EXPECT_NEAR(s.max_depth, 2.4588, 5e-4);
  EXPECT_NEAR(s.half_length, 114.47, 0.01);
  EXPECT_NEAR(s.half_width, 90.96, 0.01);
}

TEST(Exact, SteadyChuteSolvesTheSteadyEquations) {
  const SteadyChute c{35 * kDeg, 25 * kDeg, 1.0, 1.0, 5.0};
  EXPECT_NEAR(c.velocity(0), 5.0, 1e-12);
  // u u' + beta h' = g (sin - tan delta cos) with h = q / u, checked by differences.
  const double g = 9.81, beta = g * std::cos(c.zeta), a = g * (std::sin(c.zeta) - std::tan(c.delta) * std::cos(c.zeta));
  for (double x : {1.0, 20.0, 80.0}) {
    const double e = 1e-4;
    const double du = (c.velocity(x + e) - c.velocity(x - e)) / (2 * e);
    const double dh = (c.depth(x + e) - c.depth(x - e)) / (2 * e);
    EXPECT_NEAR(c.velocity(x) * du + beta * dh, a, 1e-6);
    EXPECT_NEAR(c.depth(x) * c.velocity(x), 5.0, 1e-12);
  }
}
