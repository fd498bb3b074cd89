#include "jobs/drivers/vof_lab/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace runout::jobs::vof_lab {

namespace vof = engine::vof;
constexpr double kPi = 3.14159265358979323846;

bool in_polygon(const google::protobuf::RepeatedField<double>& xy, double x, double y) {
  bool in = false;  // even-odd rule
  const int n = xy.size() / 2;
  for (int a = 0, b = n - 1; a < n; b = a++) {
    const double xa = xy.Get(2 * a), ya = xy.Get(2 * a + 1), xb = xy.Get(2 * b), yb = xy.Get(2 * b + 1);
    if ((ya > y) != (yb > y) && x < (xb - xa) * (y - ya) / (yb - ya) + xa) in = !in;
  }
  return in;
}

bool in_obstacle(const v1::LabObstacle& o, const vof::Vec& c, double y0) {
  if (o.shape() == "polygon") return in_polygon(o.polygon_xy(), c.x, c.y);
  if (o.shape() == "cylinder") return std::hypot(c.x - o.x(), c.z - o.z()) < o.radius() && c.y - y0 < o.height();
  // A regular tetrahedron standing on a face: footprint an equilateral triangle of edge a around
  // (x, z), apex at height a sqrt(2/3); "edge" puts a corner of the footprint upstream (the flow
  // meets the edge from it to the apex), "face" a side (the flow meets an inclined face).
  const double a = o.edge(), R = a / std::sqrt(3.0), H = a * std::sqrt(2.0 / 3.0);
  const double sgn = o.shape() == "tetrahedron-edge" ? -1 : 1;
  const vof::Vec v[4] = {{o.x() + sgn * R, y0, o.z()}, {o.x() - sgn * R / 2, y0, o.z() - a / 2}, {o.x() - sgn * R / 2, y0, o.z() + a / 2},
                         {o.x(), y0 + H, o.z()}};
  static const int faces[4][4] = {{0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}};  // three corners and the opposite one
  for (const auto& f : faces) {
    const vof::Vec e1 = v[f[1]] - v[f[0]], e2 = v[f[2]] - v[f[0]];
    const vof::Vec n{e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
    const double side_opposite = vof::dot(n, v[f[3]] - v[f[0]]), side_c = vof::dot(n, c - v[f[0]]);
    if (side_c * side_opposite < 0) return false;
  }
  return true;
}

ChuteBed::ChuteBed(const v1::Lab& L)
    : s1_(L.chute().bend_start_m()), s2_(L.chute().bend_end_m()), beta_(L.chute().bend_deg() * kPi / 180),
      R_(L.chute().channel_radius_m()), k_(beta_ / (s2_ - s1_)) {}

vof::Vec ChuteBed::point(double s, double n, double z) const {
  double x, y, a;  // the reference point and its tangent's angle to X
  if (s <= s1_) {
    x = s, y = 0, a = 0;
  } else if (s <= s2_) {
    a = k_ * (s - s1_);
    x = s1_ + std::sin(a) / k_, y = (1 - std::cos(a)) / k_;
  } else {
    a = beta_;
    x = s1_ + std::sin(beta_) / k_ + (s - s2_) * std::cos(beta_), y = (1 - std::cos(beta_)) / k_ + (s - s2_) * std::sin(beta_);
  }
  double f = 1;  // the parabola's share: 1 on the chute, smoothly 0 over the bend
  if (s > s1_) {
    const double q = std::clamp((s2_ - s) / (s2_ - s1_), 0.0, 1.0);
    f = q * q * (3 - 2 * q);
  }
  const double h = (R_ > 0 ? z * z / (2 * R_) * f : 0) + n;
  return {x - std::sin(a) * h, y + std::cos(a) * h, z};
}

}  // namespace runout::jobs::vof_lab
