#include "engine/verification/exact.hpp"

#include <cmath>
#include <algorithm>
#include <stdexcept>

namespace runout::engine::exact {

double DamBreak::c0() const { return std::sqrt(g * h0 * std::cos(zeta)); }
double DamBreak::m() const { return g * std::cos(zeta) * (std::tan(zeta) - std::tan(delta)); }
double DamBreak::front(double t) const { return 2 * c0() * t + 0.5 * m() * t * t; }
void DamBreak::at(double x, double t, double& h, double& u) const {
  const double c = c0(), mm = m();
  if (t <= 0) {
    h = x <= 0 ? h0 : 0.0;
    u = 0;
    return;
  }
  if (x <= 0.5 * mm * t * t - c * t) {
    h = h0;
    u = mm * t;
  } else if (x <= 0.5 * mm * t * t + 2 * c * t) {
    const double a = 2 * c - x / t + 0.5 * mm * t;
    h = a * a / (9 * g * std::cos(zeta));
    u = 2.0 / 3.0 * (c + x / t + mm * t);
  } else {
    h = 0;
    u = 0;
  }
}

double ParabolicCap::accel() const { return g * (std::sin(zeta) - std::tan(delta) * std::cos(zeta)); }
double ParabolicCap::time_of(double s) const {
  const double k = L0 / std::sqrt(4 * K * g * std::cos(zeta) * H0);
  return k * (std::sqrt(s * (s - 1)) + std::log(std::sqrt(s) + std::sqrt(s - 1)));
}
double ParabolicCap::half_length(double t) const {
  if (t <= 0) return L0;
  double lo = 1.0, hi = 2.0;
  while (time_of(hi) < t) hi *= 2;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (time_of(mid) < t ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi) * L0;
}
double ParabolicCap::spreading_rate(double t) const {
  const double L = half_length(t);
  return std::sqrt(std::max(0.0, 4 * K * g * std::cos(zeta) * H0 * (1 - L0 / L)));
}
double ParabolicCap::centre(double t) const { return x0 + 0.5 * accel() * t * t; }
void ParabolicCap::at(double x, double t, double& h, double& u) const {
  const double L = half_length(t), xi = (x - centre(t)) / L;
  if (std::abs(xi) >= 1) {
    h = 0;
    u = 0;
    return;
  }
  h = H0 * L0 / L * (1 - xi * xi);
  u = accel() * t + xi * spreading_rate(t);
}

EllipticCap::Shape EllipticCap::at(double t) const {
  const double T = std::sqrt(Lx / g), tau_end = t / T;
  const double A = std::sin(zeta), C = std::cos(zeta) * std::tan(delta);
  if (!(A > C)) throw std::invalid_argument("elliptic cap: needs tan(zeta) > tan(delta)");
  const double B = H / Lx * std::cos(zeta) * Kx;
  const double D = (H / Ly) * (H / Ly) / (H / Lx) * std::cos(zeta) * Ky;
  const double E = (A - C) / A;
  double gg, gp, f, fp;
  auto series = [&](double tau) {
    gg = 1 + B * tau * tau;
    gp = 2 * B * tau;
    f = 1 + D * E * tau * tau;
    fp = 2 * D * E * tau;
  };
  const double tau0 = 0.1;
  if (tau_end <= tau0) {
    series(tau_end);
  } else {
    series(tau0);
    auto rhs = [&](double tau, const double y[4], double dy[4]) {
      dy[0] = y[1];
      dy[1] = 2 * B / (y[0] * y[0] * y[2]);
      dy[2] = y[3];
      dy[3] = 2 * D / (y[0] * y[2] * y[2]) - C * y[3] / ((A - C) * tau);
    };
    double y[4] = {gg, gp, f, fp};
    const int nsteps = 20000;
    const double h = (tau_end - tau0) / nsteps;
    double tau = tau0;
    for (int s = 0; s < nsteps; ++s) {
      double k1[4], k2[4], k3[4], k4[4], tmp[4];
      rhs(tau, y, k1);
      for (int q = 0; q < 4; ++q) tmp[q] = y[q] + 0.5 * h * k1[q];
      rhs(tau + 0.5 * h, tmp, k2);
      for (int q = 0; q < 4; ++q) tmp[q] = y[q] + 0.5 * h * k2[q];
      rhs(tau + 0.5 * h, tmp, k3);
      for (int q = 0; q < 4; ++q) tmp[q] = y[q] + h * k3[q];
      rhs(tau + h, tmp, k4);
      for (int q = 0; q < 4; ++q) y[q] += h / 6 * (k1[q] + 2 * k2[q] + 2 * k3[q] + k4[q]);
      tau += h;
    }
    gg = y[0];
    f = y[2];
  }
  Shape s;
  s.centre = Lx * 0.5 * (A - C) * tau_end * tau_end;
  s.max_depth = H / (f * gg);
  s.half_length = Lx * gg;
  s.half_width = Ly * f;
  return s;
}

double EllipticCap::depth(double x, double y, double t) const {
  const Shape s = at(t);
  const double X = (x - s.centre) / s.half_length, Y = y / s.half_width;
  return std::max(0.0, s.max_depth * (1 - X * X - Y * Y));
}

double SteadyChute::velocity(double x) const {
  const double a = g * (std::sin(zeta) - std::tan(delta) * std::cos(zeta));
  const double beta = K * g * std::cos(zeta);
  const double Q = 2 * a * (x - x0) + u0 * u0 + 2 * beta * h0;
  const double arg = -beta * h0 * u0 * std::pow(3.0 / Q, 1.5);
  return 2 * std::sqrt(Q / 3) * std::cos(std::acos(std::clamp(arg, -1.0, 1.0)) / 3);
}

}  // namespace runout::engine::exact
