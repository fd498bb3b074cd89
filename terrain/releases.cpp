// Releases onto the grid: polygons with a thickness per polygon (attribute or default) or a
// thickness raster (alone or inside the polygons), the slope window, and the released volume.
#include <gdal_alg.h>
#include <gdal_priv.h>
#include <ogr_api.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "terrain/gdal_support.hpp"
#include "terrain/terrain.hpp"

namespace runout::terrain {
namespace {

using namespace detail;


// The release is evaluated on a lattice of samples finer than the grid: each cell divided into
// n x n squares. A square counts with the fraction of it that the polygon covers (the exact area of
// their intersection, OGR), the thickness there (the release's, or the thickness raster resampled
// at the square's centre) and the slope at its centre. The slope window is decided on the DEM's
// continuous surface as the scenario's resampling reconstructs it (grid.resampling, the interpolant
// the grids are made with), sampled at a fixed spacing s that depends on the DEM alone
// (slope_spacing: its pixel size / 8, not below 1 m) on cells at multiples of s in the grid's CRS,
// so that every grid sees the same surface; slopes by centred differences there (what a grid of
// spacing s made from this DEM sees), interpolated bilinearly at each square's centre. A square
// inside the slope window releases fraction x area x thickness (vertical thickness) or
// fraction x area x thickness / cos(slope) (normal thickness); the cell's normal depth is the one
// that carries exactly the sum of its squares: volume x cos(the grid's slope) / dx^2, since the
// engines hold h dx^2 / cos(the grid's slope). n is the smallest number that makes the squares no
// larger than s (at most 16). docs/user/scenarios.md, Releases on the grid.
struct Lattice {
  const Grid& g;
  const DemRequest& dem;
  double res = 0;  // the slope surface's spacing s [m] (slope_spacing)
  int n = 1;       // samples per cell side
  Lattice(const Grid& grid, const DemRequest& d) : g(grid), dem(d), res(slope_spacing(d, grid)) {
    n = std::clamp(int(std::ceil(g.dx / res - 1e-9)), 1, 16);
  }
  // The samples of the cells [i0, i1) x [j0, j1) as a grid (row 0 south).
  Grid of(int i0, int j0, int i1, int j1) const {
    Grid l;
    l.nx = (i1 - i0) * n;
    l.ny = (j1 - j0) * n;
    l.dx = g.dx / n;
    l.x_min = g.x_min + i0 * g.dx;
    l.y_min = g.y_min + j0 * g.dx;
    l.crs_wkt = g.crs_wkt;
    l.crs_name = g.crs_name;
    return l;
  }
};

// The slope [deg] at the samples' centres of `l`: the DEM's surface at the spacing s around them
// (two of its cells beyond, so it covers only the release's cells), its slopes by centred
// differences, interpolated bilinearly.
std::vector<double> sample_slopes(const Lattice& lat, const Grid& l) {
  // Its cells on multiples of s in the grid's CRS, whatever the grid: every grid samples the same
  // surface.
  const double r = lat.res, x0 = std::floor(l.x_min / r - 2) * r, y0 = std::floor(l.y_min / r - 2) * r;
  const Grid s = dem_surface(lat.dem, lat.g, r, x0, y0, std::ceil((l.x_min + l.nx * l.dx) / r + 2) * r, std::ceil((l.y_min + l.ny * l.dx) / r + 2) * r);
  const auto slope = slope_deg(s);
  std::vector<double> out(l.cells());
  for (int v = 0; v < l.ny; ++v) {
    const double fy = (l.y_min + (v + 0.5) * l.dx - s.y_min) / s.dx - 0.5;
    const int j = std::clamp(int(std::floor(fy)), 0, s.ny - 2);
    const double ty = std::clamp(fy - j, 0.0, 1.0);
    for (int u = 0; u < l.nx; ++u) {
      const double fx = (l.x_min + (u + 0.5) * l.dx - s.x_min) / s.dx - 0.5;
      const int i = std::clamp(int(std::floor(fx)), 0, s.nx - 2);
      const double tx = std::clamp(fx - i, 0.0, 1.0);
      const auto at = [&](int di, int dj) { return slope[std::size_t(j + dj) * s.nx + std::size_t(i + di)]; };
      out[std::size_t(v) * l.nx + u] = (1 - ty) * ((1 - tx) * at(0, 0) + tx * at(1, 0)) + ty * ((1 - tx) * at(0, 1) + tx * at(1, 1));
    }
  }
  return out;
}

// The fraction of each sample square of `l` that the polygon covers (row 0 south): the squares it
// touches (GDAL's rasteriser, ALL_TOUCHED), 1 for those inside it, else the area of the
// intersection (OGR) over the square's.
std::vector<double> coverage(const Grid& l, const OGRGeometry& geom, const std::string& what) {
  auto mask_ds = mem_raster(l, GDT_Byte);
  int band = 1;
  double burn = 1;
  OGRGeometryH gh = OGRGeometry::ToHandle(const_cast<OGRGeometry*>(&geom));
  char* opts[] = {const_cast<char*>("ALL_TOUCHED=TRUE"), nullptr};
  if (GDALRasterizeGeometries(GDALDataset::ToHandle(mask_ds.get()), 1, &band, 1, &gh, nullptr, nullptr, &burn, opts, nullptr, nullptr) !=
      CE_None)
    throw TerrainError(what + ": rasterisation failed" + gdal_message());
  std::vector<unsigned char> rows(l.cells());
  if (mask_ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, l.nx, l.ny, rows.data(), l.nx, l.ny, GDT_Byte, 0, 0) != CE_None)
    throw TerrainError(what + ": reading the rasterised polygon failed" + gdal_message());
  std::unique_ptr<std::remove_pointer_t<OGRPreparedGeometryH>, decltype(&OGRDestroyPreparedGeometry)> prepared(
      OGRCreatePreparedGeometry(gh), &OGRDestroyPreparedGeometry);
  std::vector<double> f(l.cells(), 0.0);
  const double a = l.dx * l.dx;
  for (int r = 0; r < l.ny; ++r)
    for (int i = 0; i < l.nx; ++i) {
      if (!rows[std::size_t(r) * l.nx + i]) continue;
      const int j = l.ny - 1 - r;
      const double x0 = l.x_min + i * l.dx, y0 = l.y_min + j * l.dx;
      OGRLinearRing ring;
      ring.addPoint(x0, y0);
      ring.addPoint(x0 + l.dx, y0);
      ring.addPoint(x0 + l.dx, y0 + l.dx);
      ring.addPoint(x0, y0 + l.dx);
      ring.addPoint(x0, y0);
      OGRPolygon sq;
      sq.addRing(&ring);
      double frac = 0;
      if (prepared && OGRPreparedGeometryContains(prepared.get(), OGRGeometry::ToHandle(&sq))) {
        frac = 1;
      } else {
        const std::unique_ptr<OGRGeometry> x(geom.Intersection(&sq));
        if (x) frac = std::min(1.0, OGR_G_Area(OGRGeometry::ToHandle(x.get())) / a);
      }
      f[std::size_t(j) * l.nx + i] = frac;
    }
  return f;
}

// The cells one release fills, from its samples (Lattice): those where the domain has terrain,
// with a positive thickness and a slope within [smin, smax]; the depth carrying the volume times
// `factor` (the release's thickness_factor) goes into h where it exceeds what is there (area: the
// plan area released in the cell). Errors name `what`.
struct CellFill {
  const Lattice& lat;
  const std::vector<double>& slope;  // the grid's
  const std::string& extent;
  std::vector<double>& h;
  std::vector<double>& area;
  // `geom` (null: all of each cell) and the thickness per sample: `raster` (a thickness raster's
  // request, resampled at the samples) or `t`, over the cells [i0, i1) x [j0, j1). Returns the plan
  // area of `geom` inside the domain (the grid, the area of interest, the DEM's data) [m2].
  double operator()(const std::string& what, bool vertical, double smin, double smax, const OGRGeometry* geom, const ReleaseRequest* raster,
                  const OGRSpatialReference& dst, double t, double factor, int i0, int j0, int i1, int j1) const;
};

std::vector<double> raster_thickness(const Grid& g, const ReleaseRequest& rq, const OGRSpatialReference& dst);

double CellFill::operator()(const std::string& what, bool vertical, double smin, double smax, const OGRGeometry* geom,
                          const ReleaseRequest* raster, const OGRSpatialReference& dst, double t, double factor, int i0, int j0, int i1,
                          int j1) const {
  const Grid& g = lat.g;
  const int n = lat.n;
  i0 = std::max(i0, 0);
  j0 = std::max(j0, 0);
  i1 = std::min(i1, g.nx);
  j1 = std::min(j1, g.ny);
  long inside = 0, kept = 0;
  double smin_seen = 90, smax_seen = 0, covered_m2 = 0;
  std::vector<double> vol(g.cells(), 0.0), plan(g.cells(), 0.0);
  std::vector<std::size_t> touched;
  // Bands of rows of at most about 4 million samples and 4 million cells of the slope surface.
  const double per_cell = std::max(double(n) * n, (g.dx / lat.res) * (g.dx / lat.res));
  const int band_rows = i1 > i0 ? std::max(1, int(double(1 << 22) / ((i1 - i0) * per_cell))) : 1;
  for (int b0 = j0; b0 < j1 && i0 < i1; b0 += band_rows) {
    const int b1 = std::min(j1, b0 + band_rows);
    const Grid l = lat.of(i0, b0, i1, b1);
    const auto cov = geom ? coverage(l, *geom, what) : std::vector<double>(l.cells(), 1.0);
    const auto thick = raster ? raster_thickness(l, *raster, dst) : std::vector<double>(l.cells(), t);
    bool any = false;
    for (std::size_t q = 0; q < l.cells() && !any; ++q) any = cov[q] > 0 && thick[q] > 0;
    if (!any) continue;
    const auto sl = sample_slopes(lat, l);
    const double a = l.dx * l.dx;
    for (int v = 0; v < l.ny; ++v)
      for (int u = 0; u < l.nx; ++u) {
        const std::size_t q = std::size_t(v) * l.nx + u;
        const std::size_t k = std::size_t(b0 + v / n) * g.nx + std::size_t(i0 + u / n);
        if (!(cov[q] > 0) || !(thick[q] > 0) || (!g.outside.empty() && g.outside[k])) continue;  // no release where the domain has no terrain
        ++inside;
        covered_m2 += cov[q] * a;
        smin_seen = std::min(smin_seen, sl[q]);
        smax_seen = std::max(smax_seen, sl[q]);
        if (sl[q] < smin || sl[q] > smax) continue;
        ++kept;
        if (vol[k] == 0) touched.push_back(k);
        vol[k] += cov[q] * a * factor * (vertical ? thick[q] : thick[q] / std::cos(sl[q] * M_PI / 180));
        plan[k] += cov[q] * a;
      }
  }
  if (inside == 0)
    throw TerrainError(what + " lies outside the grid, outside the area of interest or where the DEM has no data, or is thinner than a cell (" + extent + ")");
  if (kept == 0)
    throw TerrainError(what + ": no cell has a slope within [" + fmt(smin) + ", " + fmt(smax) + "] deg (slopes inside: " + fmt(smin_seen) +
                       " to " + fmt(smax_seen) + " deg)");
  for (std::size_t k : touched) {
    const double d = vol[k] * std::cos(slope[k] * M_PI / 180) / (g.dx * g.dx);
    if (d > h[k]) {
      h[k] = d;
      area[k] = plan[k];
    }
  }
  return covered_m2;
}

// A note when part of a polygon lies outside the domain (more than 1 % of its area, beyond the
// sampling's resolution): that part is not released, and the user should know.
void note_clipped(const std::string& what, const OGRGeometry& geom, double inside_m2, ReleaseReport& rep) {
  const double all = OGR_G_Area(OGRGeometry::ToHandle(const_cast<OGRGeometry*>(&geom)));
  if (!(all > 0) || inside_m2 >= 0.99 * all) return;
  char b[200];
  std::snprintf(b, sizeof b, ": %.1f %% of its area (%.0f of %.0f m2) lies outside the grid, the area of interest or the DEM's data and is not released",
                100 * (1 - inside_m2 / all), all - inside_m2, all);
  rep.notes.push_back(what + b);
}

// The cells [i0, i1) x [j0, j1) that the envelope of `geom` meets.
std::array<int, 4> cells_of(const Grid& g, const OGRGeometry& geom) {
  OGREnvelope e;
  geom.getEnvelope(&e);
  const auto clampi = [](double v, int hi) { return int(std::clamp(v, 0.0, double(hi))); };
  return {clampi(std::floor((e.MinX - g.x_min) / g.dx), g.nx), clampi(std::floor((e.MinY - g.y_min) / g.dx), g.ny),
          clampi(std::ceil((e.MaxX - g.x_min) / g.dx), g.nx), clampi(std::ceil((e.MaxY - g.y_min) / g.dx), g.ny)};
}

// The cells of a thickness raster alone: those where it is positive at their centres and one cell
// around them, as [i0, i1) x [j0, j1).
std::array<int, 4> cells_of(const Grid& g, const std::vector<double>& t) {
  int i0 = g.nx, j0 = g.ny, i1 = 0, j1 = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i)
      if (t[std::size_t(j) * g.nx + i] > 0) {
        i0 = std::min(i0, i - 1);
        j0 = std::min(j0, j - 1);
        i1 = std::max(i1, i + 2);
        j1 = std::max(j1, j + 2);
      }
  return {i0, j0, i1, j1};
}

// The polygon rasterised onto the grid: 1 for the cells whose centre it covers, row 0 south.
std::vector<unsigned char> polygon_cells(const Grid& g, OGRGeometry& geom, const std::string& what) {
  auto mask_ds = mem_raster(g, GDT_Byte);
  int band = 1;
  double burn = 1;
  OGRGeometryH gh = OGRGeometry::ToHandle(&geom);
  if (GDALRasterizeGeometries(GDALDataset::ToHandle(mask_ds.get()), 1, &band, 1, &gh, nullptr, nullptr, &burn, nullptr, nullptr, nullptr) !=
      CE_None)
    throw TerrainError(what + ": rasterisation failed" + gdal_message());
  std::vector<unsigned char> rows(g.cells()), m(g.cells());
  if (mask_ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Byte, 0, 0) != CE_None)
    throw TerrainError(what + ": reading the rasterised polygon failed" + gdal_message());
  for (int r = 0; r < g.ny; ++r)
    std::copy_n(rows.begin() + std::ptrdiff_t(r) * g.nx, g.nx, m.begin() + std::ptrdiff_t(g.ny - 1 - r) * g.nx);
  return m;
}

// "the grid covers x .. , y .. in CRS", for errors.
std::string grid_extent(const Grid& g) {
  return "the grid covers x " + fmt(g.x_min, 0) + ".." + fmt(g.x_min + g.nx * g.dx, 0) + ", y " + fmt(g.y_min, 0) + ".." +
         fmt(g.y_min + g.ny * g.dx, 0) + " in " + g.crs_name;
}

// A feature's polygon in the grid's CRS: refused when empty or not a polygon, repaired with GEOS
// when invalid (`repaired` set), transformed with `ct` (null: as it is). Errors name `what`.
std::unique_ptr<OGRGeometry> polygon_on_grid(const OGRGeometry* g0, OGRCoordinateTransformation* ct, const Grid& g, const std::string& what,
                                             bool& repaired) {
  if (!g0 || g0->IsEmpty()) throw TerrainError(what + ": no geometry");
  const auto type = wkbFlatten(g0->getGeometryType());
  if (type != wkbPolygon && type != wkbMultiPolygon) throw TerrainError(what + ": not a polygon");
  std::unique_ptr<OGRGeometry> geom(g0->clone());
  repaired = false;
  if (!geom->IsValid()) {
    std::unique_ptr<OGRGeometry> fixed(geom->MakeValid());
    if (!fixed || fixed->IsEmpty()) throw TerrainError(what + ": invalid geometry that GEOS cannot repair");
    geom = std::move(fixed);
    repaired = true;
  }
  if (ct && geom->transform(ct) != OGRERR_NONE) throw TerrainError(what + ": cannot transform it to " + g.crs_name);
  return geom;
}

// The thickness raster at the cells' centres, resampled bilinearly by GDAL's warper (PROJ for the
// CRS), row 0 south; 0 where it has no data. Values below 0 or above 500 m are refused.
std::vector<double> raster_thickness(const Grid& g, const ReleaseRequest& rq, const OGRSpatialReference& dst) {
  const std::string what = rq.kind + " thickness raster '" + rq.thickness_raster + "'";
  GDALDatasetUniquePtr src(GDALDataset::Open(rq.thickness_raster.c_str(), GDAL_OF_RASTER));
  if (!src) throw TerrainError(what + ": cannot read it as a raster" + gdal_message());
  const OGRSpatialReference* own = src->GetSpatialRef();
  const OGRSpatialReference s =
      input_crs(own, rq.crs, what, what + " has no CRS and none is given: set the " + rq.kind + "'s crs (e.g. \"EPSG:2056\")");
  transform(s, dst, what);  // refuses a local CRS against a georeferenced one
  std::vector<std::string> args = {"-r", "bilinear", "-dstnodata", "-99999", "-wo", "INIT_DEST=NO_DATA"};
  if (s.IsLocal()) {
    for (const char* o : {"-to", "SRC_METHOD=GEOTRANSFORM", "-to", "DST_METHOD=GEOTRANSFORM"}) args.push_back(o);
  } else if (!(own && !own->IsEmpty())) {
    args.push_back("-s_srs");
    args.push_back(wkt(s));
  }
  const auto wopt = warp_options(args);
  auto out = mem_raster(g, GDT_Float64);
  out->GetRasterBand(1)->SetNoDataValue(-99999);
  GDALDatasetH srch = GDALDataset::ToHandle(src.get());
  int usage_error = 0;
  if (!GDALWarp(nullptr, GDALDataset::ToHandle(out.get()), 1, &srch, wopt.get(), &usage_error))
    throw TerrainError(what + ": resampling it onto the grid failed" + gdal_message());
  std::vector<double> rows(g.cells()), t(g.cells(), 0.0);
  if (out->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float64, 0, 0) != CE_None)
    throw TerrainError(what + ": reading the resampled raster failed" + gdal_message());
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) {
      const double v = rows[std::size_t(r) * std::size_t(g.nx) + std::size_t(i)];
      if (v == -99999 || std::isnan(v)) continue;
      const int j = g.ny - 1 - r;
      // The same bound as the scenario's releases[].thickness_m (docs/user/scenarios.md, Valid ranges).
      if (v < -1e-9 || v > 500)
        throw TerrainError(what + ": thickness must lie in [0, 500] m, got " + fmt(v, 3) + " m at x " + fmt(g.cx(i), 1) + ", y " +
                           fmt(g.cy(j), 1) + " (" + crs_name(dst) + ")");
      t[std::size_t(j) * std::size_t(g.nx) + std::size_t(i)] = std::max(0.0, v);
    }
  return t;
}

// One polygon file's releases, each polygon with its thickness (the release's, its attribute's or
// the thickness raster's) and its slope window.
void release_polygons(const ReleaseRequest& rq, const OGRSpatialReference& dst, const CellFill& fill, ReleaseReport& rep,
                      std::vector<ReleaseArea>* areas = nullptr) {
  GDALDatasetUniquePtr ds(GDALDataset::Open(rq.path.c_str(), GDAL_OF_VECTOR));
  if (!ds) throw TerrainError(rq.kind + " '" + rq.path + "': cannot read it as a vector file" + gdal_message());
  const bool raster = !rq.thickness_raster.empty();
  const Grid& g = fill.lat.g;
  int n = 0;
  for (auto* layer : ds->GetLayers()) {
    const std::string file = rq.kind + " '" + rq.path + "'";
    const auto src = input_crs(layer->GetSpatialRef(), rq.crs, file, file + " has no CRS and none is given: set the " + rq.kind + "'s crs (e.g. \"EPSG:2056\")");
    auto ct = transform(src, dst, file);
    for (auto& f : layer) {
      ++n;
      const std::string what = rq.kind + " polygon " + std::to_string(n) + " of '" + rq.path + "'";
      bool repaired = false;
      const auto geom = polygon_on_grid(f->GetGeometryRef(), ct.get(), g, what, repaired);
      if (repaired) rep.notes.push_back(what + ": invalid geometry (e.g. self-intersecting) repaired with GEOS MakeValid");
      double t = rq.has_thickness ? rq.thickness : 0.0;
      if (!rq.has_thickness && !raster) {
        if (rq.thickness_attribute.empty()) throw TerrainError(what + ": no thickness (set thickness_m or thickness_attribute)");
        t = field_value(*f, rq.thickness_attribute, what);
      }
      // The same bound as the scenario's releases[].thickness_m (docs/user/scenarios.md, Valid ranges).
      if (!raster && !(t > 0 && t <= 500)) throw TerrainError(what + ": thickness must be > 0 m and at most 500 m, got " + fmt(t, 3));
      double smin = rq.has_min_slope ? rq.min_slope : 0.0, smax = rq.has_max_slope ? rq.max_slope : 90.0;
      if (!rq.has_min_slope && !rq.min_slope_attribute.empty()) smin = field_value(*f, rq.min_slope_attribute, what);
      if (!rq.has_max_slope && !rq.max_slope_attribute.empty()) smax = field_value(*f, rq.max_slope_attribute, what);
      if (!(smin >= 0 && smax <= 90 && smin < smax))
        throw TerrainError(what + ": slope window [" + fmt(smin) + ", " + fmt(smax) + "] deg must satisfy 0 <= min < max <= 90");
      const std::string named = what + (raster ? " with the thickness raster '" + rq.thickness_raster + "'" : "");
      const auto c = cells_of(g, *geom);
      if (areas) {  // a secondary release: each polygon an area of its own
        areas->push_back({what, std::vector<double>(g.cells(), 0.0), 0});
        std::vector<double> area(g.cells(), 0.0);
        const double in = CellFill{fill.lat, fill.slope, fill.extent, areas->back().h, area}(
            named, rq.vertical, smin, smax, geom.get(), raster ? &rq : nullptr, dst, t, rq.thickness_factor, c[0], c[1], c[2], c[3]);
        if (!raster) note_clipped(what, *geom, in, rep);
      } else {
        const double in = fill(named, rq.vertical, smin, smax, geom.get(), raster ? &rq : nullptr, dst, t, rq.thickness_factor, c[0], c[1], c[2], c[3]);
        if (!raster) note_clipped(what, *geom, in, rep);
      }
      ++rep.polygons;
    }
  }
  if (n == 0) throw TerrainError(rq.kind + " '" + rq.path + "': no polygon in the file");
}

// A release given by its thickness raster alone (no polygons).
void release_raster(const ReleaseRequest& rq, const OGRSpatialReference& dst, const CellFill& fill, const std::string& what) {
  const auto c = cells_of(fill.lat.g, raster_thickness(fill.lat.g, rq, dst));
  const double smin = rq.has_min_slope ? rq.min_slope : 0.0, smax = rq.has_max_slope ? rq.max_slope : 90.0;
  fill(what, rq.vertical, smin, smax, nullptr, &rq, dst, 0, rq.thickness_factor, c[0], c[1], c[2], c[3]);
}

}  // namespace

std::vector<std::uint8_t> rasterize_polygons(const Grid& g, const std::string& path, const std::string& crs, const std::string& what) {
  init_gdal();
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  if (!ds) throw TerrainError(what + ": cannot read '" + path + "' as a vector file" + gdal_message());
  const OGRSpatialReference dst = grid_crs(g);
  std::vector<std::uint8_t> in(g.cells(), 0);
  int n = 0;
  for (auto* layer : ds->GetLayers()) {
    const std::string file = what + " '" + path + "'";
    const auto src = input_crs(layer->GetSpatialRef(), crs, file, file + " has no CRS and none is given");
    auto ct = transform(src, dst, file);
    for (auto& f : layer) {
      ++n;
      const std::string at = "polygon " + std::to_string(n) + " of " + file;
      bool repaired = false;
      const auto geom = polygon_on_grid(f->GetGeometryRef(), ct.get(), g, at, repaired);
      const auto m = polygon_cells(g, *geom, at);
      for (std::size_t k = 0; k < in.size(); ++k) in[k] |= m[k] && (g.outside.empty() || !g.outside[k]);
    }
  }
  if (n == 0) throw TerrainError(what + " '" + path + "': no polygon in the file");
  return in;
}

std::vector<ReleaseArea> secondary_release_areas(const Grid& g, const DemRequest& dem, const std::vector<ReleaseRequest>& releases) {
  init_gdal();
  std::vector<ReleaseArea> areas;
  if (std::none_of(releases.begin(), releases.end(), [](const ReleaseRequest& r) { return r.secondary; })) return areas;
  const auto slope = slope_deg(g);
  const OGRSpatialReference dst = grid_crs(g);
  const std::string extent = grid_extent(g);
  const Lattice lat(g, dem);
  std::vector<double> unused(g.cells(), 0.0), unused_area(g.cells(), 0.0);
  ReleaseReport rep;
  for (const auto& rq : releases) {
    if (!rq.secondary) continue;
    if (!rq.path.empty()) {
      release_polygons(rq, dst, CellFill{lat, slope, extent, unused, unused_area}, rep, &areas);
      continue;
    }
    const std::string what = "secondary release thickness raster '" + rq.thickness_raster + "'";
    areas.push_back({what, std::vector<double>(g.cells(), 0.0), 0});
    std::vector<double> area(g.cells(), 0.0);
    release_raster(rq, dst, CellFill{lat, slope, extent, areas.back().h, area}, what);
  }
  for (auto& a : areas)
    for (std::size_t k = 0; k < a.h.size(); ++k)
      if (a.h[k] > 0) a.volume_m3 += a.h[k] * g.dx * g.dx / std::cos(slope[k] * M_PI / 180);
  return areas;
}

std::vector<double> rasterize_releases(const Grid& g, const DemRequest& dem, const std::vector<ReleaseRequest>& releases,
                                       ReleaseReport* report) {
  init_gdal();
  ReleaseReport rep;
  std::vector<double> h(g.cells(), 0.0), area(g.cells(), 0.0);
  const auto slope = slope_deg(g);
  const OGRSpatialReference dst = grid_crs(g);
  const std::string extent = grid_extent(g);
  const Lattice lat(g, dem);
  const CellFill fill{lat, slope, extent, h, area};
  for (const auto& rq : releases) {
    if (rq.secondary) continue;
    if (!rq.path.empty()) release_polygons(rq, dst, fill, rep);
    else release_raster(rq, dst, fill, rq.kind + " thickness raster '" + rq.thickness_raster + "'");
  }
  for (std::size_t k = 0; k < h.size(); ++k)
    if (h[k] > 0) {
      ++rep.cells;
      rep.area_m2 += area[k];
      rep.volume_m3 += h[k] * g.dx * g.dx / std::cos(slope[k] * M_PI / 180);
    }
  if (report) *report = rep;
  return h;
}

}  // namespace runout::terrain
