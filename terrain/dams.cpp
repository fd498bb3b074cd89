// Dams and walls on the grid (terrain.hpp rasterize_dam): the cells their crest lines or footprints
// touch, with their height; the crest lines' flux gauges.
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "terrain/gdal_support.hpp"
#include "terrain/terrain.hpp"

namespace runout::terrain {
namespace {

using namespace detail;

// The cells segment (x0, y0)-(x1, y1) passes through, each with the length of its piece there:
// the segment is cut where it crosses the grid's lines, and each piece belongs to the cell holding
// its midpoint. `add(k, length)` for each piece inside the grid.
template <class F>
void walk_segment(const Grid& g, double x0, double y0, double x1, double y1, F add) {
  const double dxs = x1 - x0, dys = y1 - y0, len = std::hypot(dxs, dys);
  if (!(len > 0)) return;
  std::vector<double> ts = {0.0, 1.0};
  auto cuts = [&](double a0, double da, double lo) {
    if (da == 0) return;
    const double u0 = (a0 - lo) / g.dx, u1 = (a0 + da - lo) / g.dx;
    for (double m = std::ceil(std::min(u0, u1)); m <= std::floor(std::max(u0, u1)); m += 1.0) {
      const double t = (lo + m * g.dx - a0) / da;
      if (t > 0 && t < 1) ts.push_back(t);
    }
  };
  cuts(x0, dxs, g.x_min);
  cuts(y0, dys, g.y_min);
  std::sort(ts.begin(), ts.end());
  for (std::size_t q = 0; q + 1 < ts.size(); ++q) {
    const double piece = (ts[q + 1] - ts[q]) * len;
    if (!(piece > 1e-12 * g.dx)) continue;
    const double tm = 0.5 * (ts[q] + ts[q + 1]);
    const int i = int(std::floor((x0 + tm * dxs - g.x_min) / g.dx)), j = int(std::floor((y0 + tm * dys - g.y_min) / g.dx));
    if (i >= 0 && j >= 0 && i < g.nx && j < g.ny) add(std::size_t(j) * g.nx + i, piece);
  }
}

// Every ring or line of a geometry as its vertices, in the grid's CRS.
void vertex_runs(const OGRGeometry* geom, std::vector<std::vector<std::pair<double, double>>>& out) {
  const auto flat = wkbFlatten(geom->getGeometryType());
  if (flat == wkbLineString || flat == wkbLinearRing) {
    const auto* l = geom->toSimpleCurve();
    std::vector<std::pair<double, double>> v;
    for (int k = 0; k < l->getNumPoints(); ++k) v.emplace_back(l->getX(k), l->getY(k));
    out.push_back(std::move(v));
  } else if (flat == wkbPolygon) {
    for (const auto* ring : *geom->toPolygon()) vertex_runs(ring, out);
  } else if (flat == wkbMultiLineString || flat == wkbMultiPolygon || flat == wkbGeometryCollection) {
    for (const auto* part : *geom->toGeometryCollection()) vertex_runs(part, out);
  }
}

bool is_line(OGRwkbGeometryType t) { return wkbFlatten(t) == wkbLineString || wkbFlatten(t) == wkbMultiLineString; }
bool is_polygon(OGRwkbGeometryType t) { return wkbFlatten(t) == wkbPolygon || wkbFlatten(t) == wkbMultiPolygon; }

// One feature of a dam file on the grid: its crest pieces (lines: gauge weights) or its footprint
// (polygons: centres inside, and the outline's cells), as the cells it touches.
void touch_feature(const Grid& g, OGRGeometry& geom, bool lines, bool centres_only, std::vector<std::uint8_t>& touched,
                   std::vector<double>& wx, std::vector<double>& wy, double& length) {
  std::vector<std::vector<std::pair<double, double>>> runs;
  if (!centres_only) vertex_runs(&geom, runs);
  for (const auto& v : runs)
    for (std::size_t q = 0; q + 1 < v.size(); ++q) {
      const double x0 = v[q].first, y0 = v[q].second, x1 = v[q + 1].first, y1 = v[q + 1].second;
      const double len = std::hypot(x1 - x0, y1 - y0);
      if (!(len > 0)) continue;
      const double nx = (y1 - y0) / len, ny = -(x1 - x0) / len;  // the right-hand normal
      walk_segment(g, x0, y0, x1, y1, [&](std::size_t k, double piece) {
        touched[k] = 1;
        if (!lines) return;
        wx[k] += piece * nx;
        wy[k] += piece * ny;
        length += piece;
      });
    }
  if (lines) return;
  OGREnvelope env;
  geom.getEnvelope(&env);
  const int i0 = std::max(0, int(std::floor((env.MinX - g.x_min) / g.dx))), i1 = std::min(g.nx - 1, int(std::floor((env.MaxX - g.x_min) / g.dx)));
  const int j0 = std::max(0, int(std::floor((env.MinY - g.y_min) / g.dx))), j1 = std::min(g.ny - 1, int(std::floor((env.MaxY - g.y_min) / g.dx)));
  bool any = false;
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      OGRPoint c(g.cx(i), g.cy(j));
      if (geom.Contains(&c)) touched[std::size_t(j) * g.nx + i] = 1, any = true;
    }
  if (any || !centres_only) return;
  OGRPoint centroid;  // a footprint smaller than a cell: the cell holding its centroid
  if (geom.Centroid(&centroid) != OGRERR_NONE) return;
  const int i = int(std::floor((centroid.getX() - g.x_min) / g.dx)), j = int(std::floor((centroid.getY() - g.y_min) / g.dx));
  if (i >= 0 && j >= 0 && i < g.nx && j < g.ny) touched[std::size_t(j) * g.nx + i] = 1;
}

// A surface model's heights over the ground on the grid: NaN where it has no value, is outside the
// domain or stands less than rq.min_height above the ground. A surface more than 100 m above the
// ground is refused, naming the place.
std::vector<double> surface_heights(const Grid& g, const DamRequest& rq) {
  const std::string file = rq.field + ".surface_path '" + rq.surface_path + "'";
  std::vector<double> h = read_raster_on(rq.surface_path, g, file);
  for (std::size_t k = 0; k < g.cells(); ++k) {
    const double v = h[k] - g.z[k];
    if (!std::isfinite(v) || v < rq.min_height || (!g.outside.empty() && g.outside[k])) {
      h[k] = NAN;
      continue;
    }
    if (v > 100)
      throw TerrainError(file + ": the surface lies " + fmt(v, 2) + " m above the ground at (" + fmt(g.cx(int(k % std::size_t(g.nx))), 1) +
                         ", " + fmt(g.cy(int(k / std::size_t(g.nx))), 1) + "): a structure is at most 100 m high");
    h[k] = v;
  }
  return h;
}

// A structure from a surface model alone: every cell where it stands min_height above the ground.
DamCells surface_structure(const Grid& g, const DamRequest& rq) {
  DamCells d;
  d.height.assign(g.cells(), 0.0);
  const auto h = surface_heights(g, rq);
  for (std::size_t k = 0; k < g.cells(); ++k)
    if (std::isfinite(h[k])) d.height[k] = h[k], ++d.cells;
  d.features = 1;
  if (d.cells == 0)
    throw TerrainError(rq.field + ".surface_path '" + rq.surface_path + "': stands nowhere in the domain " + fmt(rq.min_height, 2) +
                       " m or more above the ground (min_height_m)");
  return d;
}

}  // namespace

DamCells rasterize_dam(const Grid& g, const DamRequest& rq) {
  init_gdal();
  if (rq.path.empty() && !rq.surface_path.empty()) return surface_structure(g, rq);
  const std::vector<double> surface = rq.surface_path.empty() ? std::vector<double>{} : surface_heights(g, rq);
  const std::string file = rq.field + ".path '" + rq.path + "'";
  GDALDatasetUniquePtr ds(GDALDataset::Open(rq.path.c_str(), GDAL_OF_VECTOR));
  if (!ds) throw TerrainError(file + ": cannot read it as a vector file" + gdal_message());
  const OGRSpatialReference dst = grid_crs(g);
  DamCells d;
  d.height.assign(g.cells(), 0.0);
  std::vector<double> wx(g.cells(), 0.0), wy(g.cells(), 0.0);
  int polygons = 0;
  for (auto* layer : ds->GetLayers()) {
    const auto src = input_crs(layer->GetSpatialRef(), rq.crs, file, file + " has no CRS and none is given: set " + rq.field + ".crs");
    auto ct = transform(src, dst, file);
    for (auto& f : layer) {
      ++d.features;
      const std::string what = rq.field + ": feature " + std::to_string(d.features) + " of '" + rq.path + "'";
      const OGRGeometry* g0 = f->GetGeometryRef();
      if (!g0 || g0->IsEmpty()) throw TerrainError(what + ": no geometry");
      const bool line = is_line(g0->getGeometryType());
      if (!line && !is_polygon(g0->getGeometryType())) throw TerrainError(what + ": neither a line (crest) nor a polygon (footprint)");
      d.lines = d.lines || line;
      polygons += !line;
      if (d.lines && polygons > 0) throw TerrainError(what + ": crest lines and footprints (polygons) in one dam: give them as two dams");
      const bool top = !rq.top_attribute.empty(), from_surface = !surface.empty();
      const double v = rq.has_height ? rq.height
                       : top         ? field_value(*f, rq.top_attribute, what)
                       : from_surface ? 0.0
                       : rq.height_attribute.empty() ? -1
                                                     : field_value(*f, rq.height_attribute, what);
      if (v < 0 && !rq.has_height && !top && !from_surface && rq.height_attribute.empty())
        throw TerrainError(what + ": no height (set height_m or height_attribute)");
      if (!top && !from_surface && !(v > 0 && v <= 100)) throw TerrainError(what + ": height must be > 0 m and at most 100 m, got " + fmt(v, 2));
      std::unique_ptr<OGRGeometry> geom(g0->clone());
      if (ct && geom->transform(ct.get()) != OGRERR_NONE) throw TerrainError(what + ": cannot transform it to " + g.crs_name);
      std::vector<std::uint8_t> touched(g.cells(), 0);
      touch_feature(g, *geom, line, rq.centres_only && !line, touched, wx, wy, d.length_m);
      for (std::size_t k = 0; k < g.cells(); ++k) {
        if (!touched[k] || (!g.outside.empty() && g.outside[k])) continue;
        if (from_surface) {  // the surface model's height here; where it is lower than min_height, not the structure
          if (std::isfinite(surface[k])) d.height[k] = std::max(d.height[k], surface[k]);
          continue;
        }
        const double h = top ? v - g.z[k] : v;  // a top elevation: its height over this cell's ground
        if (top && !(h > 0 && h <= 100))
          throw TerrainError(what + ": its top (" + rq.top_attribute + " = " + fmt(v, 2) + " m) lies " + fmt(h, 2) +
                             " m above the ground at (" + fmt(g.cx(int(k % std::size_t(g.nx))), 1) + ", " +
                             fmt(g.cy(int(k / std::size_t(g.nx))), 1) + "): it must lie between 0 and 100 m above it");
        d.height[k] = std::max(d.height[k], h);
      }
    }
  }
  if (d.features == 0) throw TerrainError(file + ": no feature in the file");
  auto inside = [&](std::size_t k) { return g.outside.empty() || !g.outside[k]; };
  auto on_crest = [&](std::size_t k) { return (wx[k] != 0 || wy[k] != 0) && inside(k); };
  for (std::size_t k = 0; k < g.cells(); ++k) {
    d.cells += d.height[k] > 0;
    if (!d.lines || !on_crest(k)) continue;
    const int i = int(k % std::size_t(g.nx)), j = int(k / std::size_t(g.nx));
    const int di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};  // W, E, S, N
    std::array<std::int8_t, 4> side{};
    for (int f = 0; f < 4; ++f) {
      const int u = i + di[f], v = j + dj[f];
      if (u < 0 || v < 0 || u >= g.nx || v >= g.ny) continue;
      const std::size_t m = std::size_t(v) * g.nx + u;
      const double along = wx[k] * di[f] + wy[k] * dj[f];  // the neighbour's side of the line
      if (on_crest(m) || !inside(m) || std::abs(along) <= 1e-9 * std::hypot(wx[k], wy[k])) continue;
      side[f] = along > 0 ? 1 : -1;
    }
    d.crest.push_back(k);
    d.sides.push_back(side);
  }
  if (d.cells == 0 && !surface.empty())
    throw TerrainError(file + ": the surface model (" + rq.surface_path + ") stands " + fmt(rq.min_height, 2) +
                       " m or more above the ground on none of its cells (min_height_m)");
  if (d.cells == 0) throw TerrainError(file + ": lies on no cell of the domain");
  return d;
}

}  // namespace runout::terrain
