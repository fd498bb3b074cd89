#include "jobs/products/path.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <queue>

namespace runout::jobs::products {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool inside(const terrain::Grid& g, int i, int j) {
  return i >= 0 && j >= 0 && i < g.nx && j < g.ny && (g.outside.empty() || !g.outside[std::size_t(j) * g.nx + i]);
}

// The value of the cell holding (x, y); NaN outside the domain.
double cell_value(const terrain::Grid& g, const std::vector<double>& v, double x, double y) {
  const int i = int(std::floor((x - g.x_min) / g.dx)), j = int(std::floor((y - g.y_min) / g.dx));
  return inside(g, i, j) ? v[std::size_t(j) * g.nx + i] : kNaN;
}

// The ground at (x, y), bilinear between the cell centres (clamped at the grid's edges).
double ground(const terrain::Grid& g, double x, double y) {
  const double fi = std::clamp((x - g.x_min) / g.dx - 0.5, 0.0, g.nx - 1.0), fj = std::clamp((y - g.y_min) / g.dx - 0.5, 0.0, g.ny - 1.0);
  const int i0 = std::min(int(fi), std::max(g.nx - 2, 0)), j0 = std::min(int(fj), std::max(g.ny - 2, 0));
  const int i1 = std::min(i0 + 1, g.nx - 1), j1 = std::min(j0 + 1, g.ny - 1);
  const double a = fi - i0, b = fj - j0;
  auto z = [&](int i, int j) { return g.z[std::size_t(j) * g.nx + i]; };
  return (1 - a) * (1 - b) * z(i0, j0) + a * (1 - b) * z(i1, j0) + (1 - a) * b * z(i0, j1) + a * b * z(i1, j1);
}

// The line resampled every `ds` of its horizontal length (the last vertex included).
Line resample(const Line& line, double ds, double& length) {
  Line out;
  length = 0;
  double carry = 0;  // distance from the last sample to the current segment's start
  out.push_back(line.front());
  for (std::size_t k = 1; k < line.size(); ++k) {
    const double dx = line[k].first - line[k - 1].first, dy = line[k].second - line[k - 1].second, seg = std::hypot(dx, dy);
    double at = ds - carry;
    for (; at <= seg; at += ds) out.emplace_back(line[k - 1].first + dx * at / seg, line[k - 1].second + dy * at / seg);
    carry = seg - (at - ds);
    length += seg;
  }
  return out;
}

void extend_to_edge(const terrain::Grid& g, Line& line);

}  // namespace

Line steepest_descent(const terrain::Grid& g, double x, double y) {
  int i = int(std::floor((x - g.x_min) / g.dx)), j = int(std::floor((y - g.y_min) / g.dx));
  Line line;
  if (!inside(g, i, j)) return line;
  line.emplace_back(g.cx(i), g.cy(j));
  for (std::size_t step = 0; step < g.cells(); ++step) {
    int bi = -1, bj = -1;
    double best = 0;
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        if ((di == 0 && dj == 0) || !inside(g, i + di, j + dj)) continue;
        const double drop = (g.z[std::size_t(j) * g.nx + i] - g.z[std::size_t(j + dj) * g.nx + i + di]) / std::hypot(di, dj);
        if (drop > best) {
          best = drop;
          bi = i + di;
          bj = j + dj;
        }
      }
    if (bi < 0) break;  // a pit or the flat: no lower neighbour
    i = bi;
    j = bj;
    line.emplace_back(g.cx(i), g.cy(j));
  }
  extend_to_edge(g, line);
  return line;
}

namespace {

void extend_to_edge(const terrain::Grid& g, Line& line) {
  // On straight in the last 200 m's direction, to the domain's edge.
  if (line.size() < 2) return;
  const std::size_t back = std::min(line.size() - 1, std::size_t(std::ceil(200 / g.dx)));
  double dx = line.back().first - line[line.size() - 1 - back].first, dy = line.back().second - line[line.size() - 1 - back].second;
  const double n = std::hypot(dx, dy);
  dx /= n;
  dy /= n;
  double px = line.back().first, py = line.back().second;
  while (true) {
    const double nx = px + dx * g.dx, ny = py + dy * g.dx;
    if (!inside(g, int(std::floor((nx - g.x_min) / g.dx)), int(std::floor((ny - g.y_min) / g.dx)))) break;
    px = nx;
    py = ny;
  }
  if (std::hypot(px - line.back().first, py - line.back().second) > 0) line.emplace_back(px, py);
}

}  // namespace

Line flow_path(const terrain::Grid& g, const std::vector<TrackPoint>& track, const std::vector<double>& release) {
  Line line;
  for (const auto& p : track)
    if (line.empty() || std::hypot(p.x - line.back().first, p.y - line.back().second) >= 0.5 * g.dx) line.emplace_back(p.x, p.y);
  if (line.size() < 2) return {};
  // Up to the release's upper edge: back against the first direction while the line stays on the
  // domain, to the last released cell met.
  double dx = line[0].first - line[1].first, dy = line[0].second - line[1].second;
  const double n = std::hypot(dx, dy);
  dx /= n;
  dy /= n;
  std::pair<double, double> top = line.front();
  for (double d = g.dx;; d += 0.5 * g.dx) {
    const double x = line[0].first + dx * d, y = line[0].second + dy * d;
    const double v = cell_value(g, release, x, y);
    if (std::isnan(v)) break;
    if (v > 0) top = {x, y};
    else if (top != line.front()) break;  // the release's edge: a release beyond a gap is another one
  }
  if (top != line.front()) line.insert(line.begin(), top);
  extend_to_edge(g, line);
  return line;
}

PathProfile analyse_path(const terrain::Grid& g, const Line& line, const PathFields& f, const PathSettings& set) {
  PathProfile p;
  p.spacing = g.dx;
  const Line pts = line.size() >= 2 ? resample(line, g.dx, p.length) : Line{};
  if (pts.size() < 2 || !(p.length > 0)) throw terrain::TerrainError("path: the line has no length on the grid");
  const std::vector<double>& marker = set.field == "pft" ? f.depth : set.field == "pfv" ? f.speed : f.pressure_kpa;
  const char* name = set.field == "pft" ? "max depth" : set.field == "pfv" ? "max speed" : "max pressure";
  const char* unit = set.field == "pft" ? "m" : set.field == "pfv" ? "m/s" : "kPa";
  char crit[96];
  std::snprintf(crit, sizeof crit, "%s >= %g %s", name, set.threshold, unit);
  p.criterion = crit;
  const int half = int(std::floor(0.5 * set.width_m / g.dx));
  std::vector<std::vector<double>> reach(pts.size());  // per station: the marker across the section
  double s = 0;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    if (k > 0) s += std::hypot(pts[k].first - pts[k - 1].first, pts[k].second - pts[k - 1].second);
    const std::size_t a = k > 0 ? k - 1 : 0, b = std::min(k + 1, pts.size() - 1);
    double tx = pts[b].first - pts[a].first, ty = pts[b].second - pts[a].second;
    const double tn = std::hypot(tx, ty);
    tx /= tn;
    ty /= tn;
    double d = kNaN, v = kNaN, pr = kNaN;
    for (int l = -half; l <= half; ++l) {
      const double x = pts[k].first - ty * l * g.dx, y = pts[k].second + tx * l * g.dx;
      auto take = [&](double& into, const std::vector<double>& field) {
        const double c = cell_value(g, field, x, y);
        if (std::isfinite(c) && !(into >= c)) into = c;
      };
      take(d, f.depth);
      take(v, f.speed);
      take(pr, f.pressure_kpa);
      reach[k].push_back(cell_value(g, marker, x, y));
    }
    p.s.push_back(s);
    p.x.push_back(pts[k].first);
    p.y.push_back(pts[k].second);
    p.z.push_back(ground(g, pts[k].first, pts[k].second));
    p.depth.push_back(d);
    p.speed.push_back(v);
    p.pressure_kpa.push_back(pr);
  }
  const std::vector<double>& m = set.field == "pft" ? p.depth : set.field == "pfv" ? p.speed : p.pressure_kpa;
  for (std::size_t k = 0; k < m.size(); ++k)
    if (m[k] >= set.threshold) p.runout = k;
  if (p.runout && p.s[*p.runout] > 0) p.alpha_deg = std::atan((p.z.front() - p.z[*p.runout]) / p.s[*p.runout]) * 180 / M_PI;
  // The beta point: the first station below the released cells where the path's slope (over two
  // stations either way) falls below beta_deg.
  std::size_t from = 0;
  for (std::size_t k = 0; k < p.s.size(); ++k)
    if (cell_value(g, f.release, p.x[k], p.y[k]) > 0) from = k;
  const double tb = std::tan(set.beta_deg * M_PI / 180);
  for (std::size_t k = std::max<std::size_t>(from, 2); k + 2 < p.s.size(); ++k)
    if ((p.z[k - 2] - p.z[k + 2]) / (p.s[k + 2] - p.s[k - 2]) < tb) {
      p.beta = k;
      break;
    }
  if (p.beta)
    for (std::size_t k = *p.beta; k < reach.size(); ++k)
      for (double c : reach[k]) p.runout_zone_area_m2 += c >= set.threshold ? g.dx * g.dx : 0.0;
  return p;
}

namespace {

// Dijkstra over the open cells from `top` (moves to the eight neighbours, `cost(m)` times their
// length into cell m); returns each cell's distance and predecessor (n: none).
template <class Open, class Cost>
std::pair<std::vector<double>, std::vector<std::size_t>> spread(const terrain::Grid& g, std::size_t top, Open open, Cost cost) {
  const std::size_t n = g.cells();
  std::vector<double> dist(n, HUGE_VAL);
  std::vector<std::size_t> from(n, n);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  dist[top] = 0;
  queue.push({0, top});
  while (!queue.empty()) {
    const auto [d, k] = queue.top();
    queue.pop();
    if (d > dist[k]) continue;
    const int i = int(k % std::size_t(g.nx)), j = int(k / std::size_t(g.nx));
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        if ((di == 0 && dj == 0) || !open(i + di, j + dj)) continue;
        const std::size_t m = std::size_t(j + dj) * g.nx + std::size_t(i + di);
        const double nd = d + (di != 0 && dj != 0 ? M_SQRT2 : 1.0) * cost(m);
        if (nd < dist[m]) {
          dist[m] = nd;
          from[m] = k;
          queue.push({nd, m});
        }
      }
  }
  return {std::move(dist), std::move(from)};
}

// Each open cell's distance (in cells, chamfer 1 / √2) to the nearest cell that is not open.
template <class Open>
std::vector<double> distance_to_edge(const terrain::Grid& g, Open open) {
  std::vector<double> d(g.cells(), 0);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) d[std::size_t(j) * g.nx + i] = open(i, j) ? HUGE_VAL : 0;
  auto relax = [&](int i, int j, int di, int dj) {
    const int a = i + di, b = j + dj;
    const double via = (a < 0 || b < 0 || a >= g.nx || b >= g.ny ? 0 : d[std::size_t(b) * g.nx + a]) + (di && dj ? M_SQRT2 : 1.0);
    double& here = d[std::size_t(j) * g.nx + i];
    here = std::min(here, via);
  };
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i)
      for (const auto& [di, dj] : {std::pair{-1, 0}, {-1, -1}, {0, -1}, {1, -1}}) relax(i, j, di, dj);
  for (int j = g.ny - 1; j >= 0; --j)
    for (int i = g.nx - 1; i >= 0; --i)
      for (const auto& [di, dj] : {std::pair{1, 0}, {1, 1}, {0, 1}, {-1, 1}}) relax(i, j, di, dj);
  return d;
}

}  // namespace

Line longest_flow_line(const terrain::Grid& g, const std::vector<double>& release, const std::vector<double>& max_depth, double threshold,
                       std::pair<double, double>* far_end) {
  const std::size_t n = g.cells();
  auto open = [&](int i, int j) {
    if (!inside(g, i, j)) return false;
    const std::size_t k = std::size_t(j) * g.nx + i;
    return release[k] > 0 || max_depth[k] > threshold;
  };
  std::size_t top = n;
  for (std::size_t k = 0; k < n; ++k)
    if (release[k] > 0 && (g.outside.empty() || !g.outside[k]) && (top == n || g.z[k] > g.z[top])) top = k;
  if (top == n) return {};
  // The farthest outlined cell beyond the release, by the length of moves through the flow ...
  const auto [dist, unused] = spread(g, top, open, [](std::size_t) { return 1.0; });
  std::size_t far = top;
  for (std::size_t k = 0; k < n; ++k)
    if (std::isfinite(dist[k]) && max_depth[k] > threshold && !(release[k] > 0) && dist[k] > dist[far]) far = k;
  if (far == top) return {};
  if (far_end) *far_end = {g.cx(int(far % std::size_t(g.nx))), g.cy(int(far / std::size_t(g.nx)))};
  // ... reached along the flow's middle: each move costs its length over the square of one plus the
  // cell's distance to the flow's edge, so the line keeps off the outline where the flow is wide.
  const auto edge = distance_to_edge(g, open);
  const auto [cost, from] = spread(g, top, open, [&](std::size_t m) { return 1.0 / ((1 + edge[m]) * (1 + edge[m])); });
  std::vector<std::size_t> cells;
  for (std::size_t k = far; k != n; k = from[k]) cells.push_back(k);
  std::reverse(cells.begin(), cells.end());
  // The staircase of cells smoothed by a running mean over five cells (the ends kept).
  Line line;
  const std::ptrdiff_t last = std::ptrdiff_t(cells.size()) - 1;
  for (std::ptrdiff_t a = 0; a <= last; ++a) {
    const std::ptrdiff_t lo = std::max<std::ptrdiff_t>(0, a - 2), hi = std::min(last, a + 2), w = std::min(a - lo, hi - a);
    double x = 0, y = 0;
    for (std::ptrdiff_t b = a - w; b <= a + w; ++b) {
      x += g.cx(int(cells[std::size_t(b)] % std::size_t(g.nx)));
      y += g.cy(int(cells[std::size_t(b)] / std::size_t(g.nx)));
    }
    line.emplace_back(x / double(2 * w + 1), y / double(2 * w + 1));
  }
  extend_to_edge(g, line);
  return line;
}

double distance_to_line(const Line& line, double x, double y) {
  double best = HUGE_VAL;
  for (std::size_t k = 0; k + 1 < line.size(); ++k) {
    const double ax = line[k].first, ay = line[k].second, dx = line[k + 1].first - ax, dy = line[k + 1].second - ay;
    const double len2 = dx * dx + dy * dy;
    const double t = len2 > 0 ? std::clamp(((x - ax) * dx + (y - ay) * dy) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, std::hypot(x - ax - t * dx, y - ay - t * dy));
  }
  if (line.size() == 1) best = std::hypot(x - line[0].first, y - line[0].second);
  return best;
}

bool track_inside_outline(const terrain::Grid& g, const std::vector<TrackPoint>& track, const std::vector<double>& max_depth, double threshold) {
  for (std::size_t k = 1; k < track.size(); ++k)
    if (!(cell_value(g, max_depth, track[k].x, track[k].y) > threshold)) return false;
  return true;
}

void write_profile_csv(const std::string& path, const PathProfile& p) {
  std::ofstream f(path);
  f << "s_m,x,y,z_m,max_depth_m,max_speed_m_s,max_pressure_kpa\n";
  char row[256];
  auto num = [](double v) {
    char b[32];
    if (std::isfinite(v)) std::snprintf(b, sizeof b, "%.10g", v);
    else b[0] = '\0';
    return std::string(b);
  };
  for (std::size_t k = 0; k < p.s.size(); ++k) {
    std::snprintf(row, sizeof row, "%s,%s,%s,%s,%s,%s,%s\n", num(p.s[k]).c_str(), num(p.x[k]).c_str(), num(p.y[k]).c_str(),
                  num(p.z[k]).c_str(), num(p.depth[k]).c_str(), num(p.speed[k]).c_str(), num(p.pressure_kpa[k]).c_str());
    f << row;
  }
  if (!f) throw std::runtime_error("writing '" + path + "' failed");
}

}  // namespace runout::jobs::products
