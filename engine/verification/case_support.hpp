#pragma once
// What the depth-averaged verification cases share: resolutions, variant names, observed orders,
// inclined planes and Coulomb materials; and the cases themselves, which cases.cpp lists by id.
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "engine/names.hpp"
#include "engine/sh1d.hpp"
#include "engine/sh2d.hpp"
#include "engine/verification/cases.hpp"

namespace runout::engine::verification::detail {

constexpr double kDeg = M_PI / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

inline std::vector<double> pick(const Options& o, std::vector<double> moderate, const std::vector<double>& finer) {
  if (!o.resolutions.empty()) return o.resolutions;
  if (o.full) moderate.insert(moderate.end(), finer.begin(), finer.end());
  return moderate;
}

inline std::string variant(const std::string& engine, const Options& o) {
  return engine + "-" + std::string(name_of(kLimiterNames, o.limiter));
}

/// Observed order between consecutive rows from the named error metric (rows sorted coarse to fine).
inline void fill_orders(std::vector<Row>& rows, const std::string& metric) {
  for (std::size_t k = 1; k < rows.size(); ++k) {
    const Metric* a = rows[k - 1].metric(metric);
    const Metric* b = rows[k].metric(metric);
    if (!a || !b || a->value <= 0 || b->value <= 0 || rows[k - 1].variant != rows[k].variant) continue;
    rows[k].order = std::log(a->value / b->value) / std::log(rows[k - 1].dx / rows[k].dx);
  }
}

/// Orders from `metric` between neighbouring rows, and the observed order over all rows (least-squares
/// slope of log(error) against log(dx): pairwise orders of tiny errors scatter) checked against
/// `min_order` as `name` on the finest row.
inline void check_order(std::vector<Row>& rows, const std::string& metric, const std::string& name, double min_order) {
  fill_orders(rows, metric);
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const auto& r : rows) {
    const Metric* m = r.metric(metric);
    if (!m || !(m->value > 0)) continue;
    const double x = std::log(r.dx), y = std::log(m->value);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    ++n;
  }
  if (n >= 2) rows.back().metrics.push_back({name, (n * sxy - sx * sy) / (n * sxx - sx * sx), min_order, false});
}

/// An inclined plane in map coordinates with cells of size ds along the slope (dx = ds cos zeta),
/// falling in +x; cell centre i lies at slope coordinate xs0 + (i + 1/2) ds.
inline Terrain2D plane(int nx, int ny, double ds, double dy, double zeta, double xs0, double y0) {
  Terrain2D t;
  t.nx = nx;
  t.ny = ny;
  t.dx = ds * std::cos(zeta);
  t.dy = dy;
  t.x0 = (xs0 + 0.5 * ds) * std::cos(zeta);
  t.y0 = y0 + 0.5 * dy;
  t.z.resize(t.cells());
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) t.z[std::size_t(j) * nx + i] = -std::tan(zeta) * (t.x0 + i * t.dx);
  return t;
}

inline Material coulomb(double delta_deg) {
  Material m;
  m.rheology = &friction::coulomb;
  m.delta = delta_deg * kDeg;
  m.phi = std::max(delta_deg, 30.0) * kDeg;
  return m;
}

std::vector<Row> case_a1(const Options& o);  // cases_exact.cpp
std::vector<Row> case_a2(const Options& o);
std::vector<Row> case_a3(const Options& o);
std::vector<Row> case_a4(const Options& o);  // cases_invariants.cpp
std::vector<Row> case_a5(const Options& o);
std::vector<Row> case_a6(const Options& o);
std::vector<Row> case_a7(const Options& o);
std::vector<Row> case_stress(const Options& o);  // cases_stress.cpp

}  // namespace runout::engine::verification::detail
