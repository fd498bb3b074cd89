#pragma once
// TVD slope limiters for the NOC scheme (Tai et al. 2002; dissertation section 4.2).
// Every function takes the backward and forward undivided differences a = w_i - w_{i-1},
// b = w_{i+1} - w_i and returns the limited undivided slope sigma_i * dx, which equals
// phi(theta) * b with theta = a / b:
//   minmod   phi = max(0, min(1, theta))              (Harten 1983; the default)
//   vanleer  phi = (theta + |theta|) / (1 + |theta|)  (van Leer 1974)
//   superbee phi = max(0, min(2 theta, 1), min(theta, 2)) (Roe 1985)
#include <algorithm>
#include <cmath>

#include "engine/names.hpp"

namespace runout::engine {

enum class Limiter { minmod, vanleer, superbee };

inline constexpr NameTable<Limiter, 3> kLimiterNames{{
    {"minmod", Limiter::minmod}, {"vanleer", Limiter::vanleer}, {"superbee", Limiter::superbee}}};

inline double minmod2(double a, double b) {
  if (a * b <= 0.0) return 0.0;
  return a > 0.0 ? std::min(a, b) : std::max(a, b);
}

inline double limited_slope(Limiter l, double a, double b) {
  switch (l) {
    case Limiter::minmod:
      return minmod2(a, b);
    case Limiter::vanleer: {
      const double p = a * b;
      return p > 0.0 ? 2.0 * p / (a + b) : 0.0;
    }
    case Limiter::superbee: {
      if (a * b <= 0.0) return 0.0;
      const double s1 = minmod2(2.0 * a, b), s2 = minmod2(a, 2.0 * b);
      return std::abs(s1) > std::abs(s2) ? s1 : s2;
    }
  }
  return 0.0;
}

}  // namespace runout::engine
