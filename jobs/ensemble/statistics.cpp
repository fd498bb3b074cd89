#include "jobs/ensemble/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace runout::jobs::ensemble {

namespace {

// Type 7 on sorted values: h = (n - 1) p / 100, between the order statistics floor(h) and floor(h) + 1.
template <class T>
double type7(const std::vector<T>& sorted, double p) {
  const std::size_t n = sorted.size();
  if (n == 0) return NAN;
  const double h = double(n - 1) * p / 100;
  const std::size_t lo = std::min(n - 1, std::size_t(std::floor(h)));
  const double f = h - double(lo);
  if (lo + 1 >= n || f == 0) return double(sorted[lo]);
  return double(sorted[lo]) + f * (double(sorted[lo + 1]) - double(sorted[lo]));
}

}  // namespace

std::vector<double> exceedance_probability(const MemberStack& s, double threshold, bool strict, const std::vector<std::uint8_t>& outside) {
  std::vector<double> p(s.cells, NAN);
  const float t = float(threshold);  // compared as the Float32 rasters hold the values
#pragma omp parallel for schedule(static)
  for (std::size_t c = 0; c < s.cells; ++c) {
    if (!outside.empty() && outside[c]) continue;
    int n = 0;
    for (int m = 0; m < s.members; ++m) {
      const float v = s.at(m, c);
      n += strict ? v > t : v >= t;
    }
    p[c] = double(n) / double(s.members);
  }
  return p;
}

std::vector<std::vector<double>> percentiles(const MemberStack& s, const std::vector<double>& p, const std::vector<std::uint8_t>& outside) {
  std::vector<std::vector<double>> out(p.size(), std::vector<double>(s.cells, NAN));
#pragma omp parallel
  {
    std::vector<float> col(std::size_t(s.members));
#pragma omp for schedule(static)
    for (std::size_t c = 0; c < s.cells; ++c) {
      if (!outside.empty() && outside[c]) continue;
      for (int m = 0; m < s.members; ++m) col[std::size_t(m)] = std::isfinite(s.at(m, c)) ? s.at(m, c) : 0.0f;  // no data: not reached
      std::sort(col.begin(), col.end());
      for (std::size_t k = 0; k < p.size(); ++k) out[k][c] = type7(col, p[k]);
    }
  }
  return out;
}

double percentile_of(std::vector<double>& values, double p) {
  std::sort(values.begin(), values.end());
  return type7(values, p);
}

}  // namespace runout::jobs::ensemble
