#include "engine/vof/mesh_quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace runout::engine::vof {

MeshQuality mesh_quality(const Mesh& m) {
  MeshQuality q;
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  double sum_angle = 0, sum_skew = 0;
  for (int f = 0; f < m.n_internal; ++f) {
    const Vec a = m.centre[m.owner[f]], b = m.centre[m.neighbour[f]], d = b - a;
    const double dd = norm(d), sf = m.magSf[f];
    const double c = std::clamp(dot(d, m.Sf[f]) / (dd * sf), -1.0, 1.0);
    const double angle = std::acos(c) * kDeg;
    q.non_orthogonality_max_deg = std::max(q.non_orthogonality_max_deg, angle);
    sum_angle += angle;
    // Where the line a-b crosses the face's plane, against the face centre.
    const double t = dot(m.Cf[f] - a, m.Sf[f]) / dot(d, m.Sf[f]);
    const double skew = norm(m.Cf[f] - (a + t * d)) / dd;
    q.skewness_max = std::max(q.skewness_max, skew);
    sum_skew += skew;
  }
  if (m.n_internal > 0) {
    q.non_orthogonality_mean_deg = sum_angle / m.n_internal;
    q.skewness_mean = sum_skew / m.n_internal;
  }
  std::vector<double> largest(std::size_t(m.cells()), 0.0), smallest(std::size_t(m.cells()), std::numeric_limits<double>::infinity());
  auto see = [&](int c, double a) {
    largest[std::size_t(c)] = std::max(largest[std::size_t(c)], a);
    smallest[std::size_t(c)] = std::min(smallest[std::size_t(c)], a);
  };
  for (int f = 0; f < m.faces(); ++f) {
    see(m.owner[f], m.magSf[f]);
    if (f < m.n_internal) see(m.neighbour[f], m.magSf[f]);
  }
  double sum_ratio = 0;
  for (int c = 0; c < m.cells(); ++c) {
    const double r = smallest[std::size_t(c)] > 0 ? largest[std::size_t(c)] / smallest[std::size_t(c)] : 1.0;
    q.aspect_ratio_max = std::max(q.aspect_ratio_max, r);
    sum_ratio += r;
  }
  if (m.cells() > 0) q.aspect_ratio_mean = sum_ratio / m.cells();
  return q;
}

}  // namespace runout::engine::vof
