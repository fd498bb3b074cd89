// Releases onto the grid: polygons with a thickness per polygon (attribute or default) or a
// thickness raster (alone or inside the polygons), the slope window, and the released volume.
#include <gdal_alg.h>
#include <gdal_priv.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "terrain/gdal_support.hpp"
#include "terrain/terrain.hpp"

namespace runout::terrain {
namespace {

using namespace detail;

double field_value(OGRFeature& f, const std::string& attr, const std::string& what) {
  const int idx = f.GetFieldIndex(attr.c_str());
  if (idx < 0) {
    std::string names;
    for (int k = 0; k < f.GetFieldCount(); ++k) names += (k ? ", " : "") + std::string(f.GetFieldDefnRef(k)->GetNameRef());
    throw TerrainError(what + ": no attribute '" + attr + "' (attributes: " + (names.empty() ? "none" : names) + ")");
  }
  if (!f.IsFieldSetAndNotNull(idx)) throw TerrainError(what + ": attribute '" + attr + "' is empty");
  const OGRFieldType type = f.GetFieldDefnRef(idx)->GetType();
  if (type == OFTString) {  // GDAL reads a text that is not a number as 0
    const std::string text = f.GetFieldAsString(idx);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    while (end && *end && std::isspace(static_cast<unsigned char>(*end))) ++end;
    if (text.empty() || end == text.c_str() || *end) throw TerrainError(what + ": attribute '" + attr + "' is not a number: '" + text + "'");
    return v;
  }
  if (type != OFTInteger && type != OFTInteger64 && type != OFTReal)
    throw TerrainError(what + ": attribute '" + attr + "' is not a number (" + OGRFieldDefn::GetFieldTypeName(type) + ")");
  return f.GetFieldAsDouble(idx);
}

// The cells one release fills: those where `in` holds and the domain has terrain, with a positive
// thickness `thick` and a slope within [smin, smax]; the normal thickness times `factor` (the
// release's thickness_factor) goes into h (the maximum of what is there). Errors name `what`.
struct CellFill {
  const Grid& g;
  const std::vector<double>& slope;
  const std::string& extent;
  std::vector<double>& h;
  void operator()(const std::string& what, bool vertical, double smin, double smax, const std::function<bool(std::size_t)>& in,
                  const std::function<double(std::size_t)>& thick, double factor) const {
    long inside = 0, kept = 0;
    double smin_seen = 90, smax_seen = 0;
    for (std::size_t k = 0; k < g.cells(); ++k) {
      if (!in(k) || (!g.outside.empty() && g.outside[k])) continue;  // no release where the domain has no terrain
      const double t = thick(k);
      if (!(t > 0)) continue;
      ++inside;
      smin_seen = std::min(smin_seen, slope[k]);
      smax_seen = std::max(smax_seen, slope[k]);
      if (slope[k] < smin || slope[k] > smax) continue;
      ++kept;
      h[k] = std::max(h[k], factor * (vertical ? t * std::cos(slope[k] * M_PI / 180) : t));
    }
    if (inside == 0)
      throw TerrainError(what + " lies outside the grid, outside the area of interest or where the DEM has no data, or is thinner than a cell (" + extent + ")");
    if (kept == 0)
      throw TerrainError(what + ": no cell has a slope within [" + fmt(smin) + ", " + fmt(smax) + "] deg (slopes inside: " + fmt(smin_seen) +
                         " to " + fmt(smax_seen) + " deg)");
  }
};

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
  const std::string what = "release thickness raster '" + rq.thickness_raster + "'";
  GDALDatasetUniquePtr src(GDALDataset::Open(rq.thickness_raster.c_str(), GDAL_OF_RASTER));
  if (!src) throw TerrainError(what + ": cannot read it as a raster" + gdal_message());
  const OGRSpatialReference* own = src->GetSpatialRef();
  const OGRSpatialReference s =
      input_crs(own, rq.crs, what, what + " has no CRS and none is given: set the release's crs (e.g. \"EPSG:2056\")");
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
// the raster's `raster_t`) and its slope window.
void release_polygons(const ReleaseRequest& rq, const OGRSpatialReference& dst, const std::vector<double>* raster_t, const CellFill& fill,
                      ReleaseReport& rep, std::vector<ReleaseArea>* areas = nullptr) {
  GDALDatasetUniquePtr ds(GDALDataset::Open(rq.path.c_str(), GDAL_OF_VECTOR));
  if (!ds) throw TerrainError("release '" + rq.path + "': cannot read it as a vector file" + gdal_message());
  int n = 0;
  for (auto* layer : ds->GetLayers()) {
    const std::string file = "release '" + rq.path + "'";
    const auto src = input_crs(layer->GetSpatialRef(), rq.crs, file, file + " has no CRS and none is given: set the release's crs (e.g. \"EPSG:2056\")");
    auto ct = transform(src, dst, file);
    for (auto& f : layer) {
      ++n;
      const std::string what = "release polygon " + std::to_string(n) + " of '" + rq.path + "'";
      bool repaired = false;
      const auto geom = polygon_on_grid(f->GetGeometryRef(), ct.get(), fill.g, what, repaired);
      if (repaired) rep.notes.push_back(what + ": invalid geometry (e.g. self-intersecting) repaired with GEOS MakeValid");
      double t = rq.has_thickness ? rq.thickness : 0.0;
      if (!rq.has_thickness && !raster_t) {
        if (rq.thickness_attribute.empty()) throw TerrainError(what + ": no thickness (set thickness_m or thickness_attribute)");
        t = field_value(*f, rq.thickness_attribute, what);
      }
      // The same bound as the scenario's releases[].thickness_m (docs/user/scenarios.md, Valid ranges).
      if (!raster_t && !(t > 0 && t <= 500)) throw TerrainError(what + ": thickness must be > 0 m and at most 500 m, got " + fmt(t, 3));
      double smin = rq.has_min_slope ? rq.min_slope : 0.0, smax = rq.has_max_slope ? rq.max_slope : 90.0;
      if (!rq.has_min_slope && !rq.min_slope_attribute.empty()) smin = field_value(*f, rq.min_slope_attribute, what);
      if (!rq.has_max_slope && !rq.max_slope_attribute.empty()) smax = field_value(*f, rq.max_slope_attribute, what);
      if (!(smin >= 0 && smax <= 90 && smin < smax))
        throw TerrainError(what + ": slope window [" + fmt(smin) + ", " + fmt(smax) + "] deg must satisfy 0 <= min < max <= 90");
      const auto m = polygon_cells(fill.g, *geom, what);
      const std::string named = what + (raster_t ? " with the thickness raster '" + rq.thickness_raster + "'" : "");
      auto in = [&](std::size_t k) { return m[k] != 0; };
      auto thick = [&](std::size_t k) { return raster_t ? (*raster_t)[k] : t; };
      if (areas) {  // a secondary release: each polygon an area of its own
        areas->push_back({what, std::vector<double>(fill.g.cells(), 0.0), 0});
        CellFill{fill.g, fill.slope, fill.extent, areas->back().h}(named, rq.vertical, smin, smax, in, thick, rq.thickness_factor);
      } else {
        fill(named, rq.vertical, smin, smax, in, thick, rq.thickness_factor);
      }
      ++rep.polygons;
    }
  }
  if (n == 0) throw TerrainError("release '" + rq.path + "': no polygon in the file");
}

}  // namespace

std::vector<std::uint8_t> rasterize_polygons(const Grid& g, const std::string& path, const std::string& crs, const std::string& what) {
  init_gdal();
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  if (!ds) throw TerrainError(what + ": cannot read '" + path + "' as a vector file" + gdal_message());
  OGRSpatialReference dst;
  dst.importFromWkt(g.crs_wkt.c_str());
  dst.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
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

std::vector<ReleaseArea> secondary_release_areas(const Grid& g, const std::vector<ReleaseRequest>& releases) {
  init_gdal();
  std::vector<ReleaseArea> areas;
  const auto slope = slope_deg(g);
  OGRSpatialReference dst;
  dst.importFromWkt(g.crs_wkt.c_str());
  dst.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  const std::string extent = grid_extent(g);
  std::vector<double> unused(g.cells(), 0.0);
  ReleaseReport rep;
  for (const auto& rq : releases) {
    if (!rq.secondary) continue;
    std::vector<double> raster_t;
    if (!rq.thickness_raster.empty()) raster_t = raster_thickness(g, rq, dst);
    if (!rq.path.empty()) {
      release_polygons(rq, dst, rq.thickness_raster.empty() ? nullptr : &raster_t, CellFill{g, slope, extent, unused}, rep, &areas);
      continue;
    }
    const std::string what = "secondary release thickness raster '" + rq.thickness_raster + "'";
    areas.push_back({what, std::vector<double>(g.cells(), 0.0), 0});
    const double smin = rq.has_min_slope ? rq.min_slope : 0.0, smax = rq.has_max_slope ? rq.max_slope : 90.0;
    CellFill{g, slope, extent, areas.back().h}(what, rq.vertical, smin, smax, [](std::size_t) { return true; },
                                               [&](std::size_t k) { return raster_t[k]; }, rq.thickness_factor);
  }
  for (auto& a : areas)
    for (std::size_t k = 0; k < a.h.size(); ++k)
      if (a.h[k] > 0) a.volume_m3 += a.h[k] * g.dx * g.dx / std::cos(slope[k] * M_PI / 180);
  return areas;
}

std::vector<double> rasterize_releases(const Grid& g, const std::vector<ReleaseRequest>& releases, ReleaseReport* report) {
  init_gdal();
  ReleaseReport rep;
  std::vector<double> h(g.cells(), 0.0);
  const auto slope = slope_deg(g);
  OGRSpatialReference dst;
  dst.importFromWkt(g.crs_wkt.c_str());
  dst.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  const std::string extent = grid_extent(g);
  const CellFill fill{g, slope, extent, h};
  for (const auto& rq : releases) {
    if (rq.secondary) continue;
    std::vector<double> raster_t;
    if (!rq.thickness_raster.empty()) raster_t = raster_thickness(g, rq, dst);
    if (!rq.path.empty()) {
      release_polygons(rq, dst, rq.thickness_raster.empty() ? nullptr : &raster_t, fill, rep);
      continue;
    }
    const double smin = rq.has_min_slope ? rq.min_slope : 0.0, smax = rq.has_max_slope ? rq.max_slope : 90.0;
    fill("release thickness raster '" + rq.thickness_raster + "'", rq.vertical, smin, smax, [](std::size_t) { return true; },
         [&](std::size_t k) { return raster_t[k]; }, rq.thickness_factor);
  }
  for (std::size_t k = 0; k < h.size(); ++k)
    if (h[k] > 0) {
      ++rep.cells;
      rep.area_m2 += g.dx * g.dx;
      rep.volume_m3 += h[k] * g.dx * g.dx / std::cos(slope[k] * M_PI / 180);
    }
  if (report) *report = rep;
  return h;
}

}  // namespace runout::terrain
