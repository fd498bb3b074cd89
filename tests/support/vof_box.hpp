#pragma once
// The VOF engine's small plane test set-ups: a 0.2 m x 0.1 m box of 5 mm cells with walls and an
// atmosphere on top, the heap of B9 in it, and the figures the tests read (surface angle, centroid).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "engine/vof/solver.hpp"

namespace runout::test_support {

using namespace runout::engine::vof;

inline Mesh box(int nx = 40, int ny = 20) {
  BlockSpec b;
  b.x0 = 0;
  b.x1 = 0.2;
  b.y0 = 0;
  b.y1 = 0.1;
  b.nx = nx;
  b.ny = ny;
  b.thickness = 0.005;
  return block_mesh(b);
}

inline VofConfig box_config() {
  VofConfig c;
  c.bc["bottom"].kind = Bc::wall;
  c.bc["left"].kind = Bc::wall;
  c.bc["right"].kind = Bc::wall;
  c.bc["top"].kind = Bc::atmosphere;
  return c;
}

// Surface angle of a heap against the left wall of a mesh of 5 mm columns: from the column heights
// between 80 % and 20 % of the height at the wall.
inline double surface_angle_deg(const Mesh& m, const VofSolver& s, int columns) {
  std::vector<double> h(std::size_t(columns), 0.0);
  for (int k = 0; k < m.cells(); ++k) h[std::size_t(m.centre[std::size_t(k)].x / 0.005)] += s.alpha()[std::size_t(k)] * 0.005;
  const double hi = 0.8 * h[0], lo = 0.2 * h[0];
  double xhi = 0, xlo = 0;
  for (int i = columns - 1; i >= 0; --i) {
    if (h[std::size_t(i)] < hi) xhi = (i + 0.5) * 0.005;
    if (h[std::size_t(i)] < lo) xlo = (i + 0.5) * 0.005;
  }
  return std::atan((hi - lo) / std::max(1e-9, xlo - xhi)) * 180 / 3.14159265358979;
}

// Centre of the material along x.
inline double centroid_x(const Mesh& m, const VofSolver& s) {
  double mx = 0, mv = 0;
  for (int k = 0; k < m.cells(); ++k) {
    mx += s.alpha()[std::size_t(k)] * m.volume[std::size_t(k)] * m.centre[std::size_t(k)].x;
    mv += s.alpha()[std::size_t(k)] * m.volume[std::size_t(k)];
  }
  return mx / mv;
}

struct HeapRun {
  double max_speed_end = 0, volume0 = 0, volume1 = 0, alpha_min = 1, alpha_max = 0, divergence = 0, angle_deg = 0;
};

// A heap whose surface falls at `slope` from the left wall; run to t_end; surface angle from the
// column heights between 80 % and 20 % of the left-wall height.
inline HeapRun heap(double top, double slope, double t_end) {
  Mesh m = box();
  VofSolver s(m, box_config());
  std::vector<double> a(std::size_t(m.cells()));
  for (int k = 0; k < m.cells(); ++k) a[std::size_t(k)] = m.centre[std::size_t(k)].y < top - slope * m.centre[std::size_t(k)].x ? 1 : 0;
  s.initialise(a);
  HeapRun r;
  for (int k = 0; k < m.cells(); ++k) r.volume0 += a[std::size_t(k)] * m.volume[std::size_t(k)];
  s.run(t_end, [&](const StepStats& st) {
    r.alpha_min = std::min(r.alpha_min, st.alpha_min);
    r.alpha_max = std::max(r.alpha_max, st.alpha_max);
    r.divergence = std::max(r.divergence, st.divergence);
    r.max_speed_end = st.max_speed;
    r.volume1 = st.granular_volume;
    return true;
  });
  r.angle_deg = surface_angle_deg(m, s, 40);
  return r;
}


// A steep heap against the left wall of box() collapsing under `c` until t_end: its fields.
struct CollapsedHeap {
  std::vector<Vec> U;
  std::vector<double> p, alpha;
  double t = 0;
};
inline CollapsedHeap collapse_heap(const VofConfig& c, double t_end) {
  Mesh m = box();
  VofSolver s(m, c);
  std::vector<double> a(std::size_t(m.cells()));
  for (int k = 0; k < m.cells(); ++k) {
    const Vec x = m.centre[std::size_t(k)];
    a[std::size_t(k)] = x.x < 0.08 && x.y < 0.075 - 0.6 * x.x ? 1.0 : 0.0;
  }
  s.initialise(a);
  s.run(t_end);
  return {s.velocity(), s.pressure(), s.alpha(), s.time()};
}
/// Two collapses alike bit for bit, and that they flowed (faster than 5 cm/s somewhere).
inline void expect_same_collapse(const CollapsedHeap& a, const CollapsedHeap& b) {
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.p, b.p);
  EXPECT_EQ(a.alpha, b.alpha);
  ASSERT_EQ(a.U.size(), b.U.size());
  double umax = 0;
  for (std::size_t k = 0; k < a.U.size(); ++k) {
    ASSERT_EQ(std::memcmp(&a.U[k], &b.U[k], sizeof(Vec)), 0) << "cell " << k;
    umax = std::max(umax, norm(a.U[k]));
  }
  EXPECT_GT(umax, 0.05);  // it flowed
}

}  // namespace runout::test_support
