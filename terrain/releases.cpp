// Release polygons rasterised onto the grid: thickness per polygon (attribute or default), slope
// window, and the released volume.
#include <gdal_alg.h>
#include <gdal_priv.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
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

}  // namespace

std::vector<double> rasterize_releases(const Grid& g, const std::vector<ReleaseRequest>& releases, ReleaseReport* report) {
  init_gdal();
  ReleaseReport rep;
  std::vector<double> h(g.cells(), 0.0);
  const auto slope = slope_deg(g);
  OGRSpatialReference dst;
  dst.importFromWkt(g.crs_wkt.c_str());
  dst.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  const std::string extent = "the grid covers x " + fmt(g.x_min, 0) + ".." + fmt(g.x_min + g.nx * g.dx, 0) + ", y " +
                             fmt(g.y_min, 0) + ".." + fmt(g.y_min + g.ny * g.dx, 0) + " in " + g.crs_name;
  for (const auto& rq : releases) {
    GDALDatasetUniquePtr ds(GDALDataset::Open(rq.path.c_str(), GDAL_OF_VECTOR));
    if (!ds) throw TerrainError("release '" + rq.path + "': cannot read it as a vector file" + gdal_message());
    int n = 0;
    for (auto* layer : ds->GetLayers()) {
      const OGRSpatialReference* ls = layer->GetSpatialRef();
      OGRSpatialReference src;
      if (ls && !ls->IsEmpty()) {
        src = *ls;
        src.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
      } else if (!rq.crs.empty()) {
        src = srs_from(rq.crs, "release '" + rq.path + "'");
      } else {
        throw TerrainError("release '" + rq.path + "' has no CRS and none is given: set the release's crs (e.g. \"EPSG:2056\")");
      }
      auto ct = transform(src, dst, "release '" + rq.path + "'");
      for (auto& f : layer) {
        ++n;
        const std::string what = "release polygon " + std::to_string(n) + " of '" + rq.path + "'";
        const OGRGeometry* g0 = f->GetGeometryRef();
        if (!g0 || g0->IsEmpty()) throw TerrainError(what + ": no geometry");
        const auto type = wkbFlatten(g0->getGeometryType());
        if (type != wkbPolygon && type != wkbMultiPolygon) throw TerrainError(what + ": not a polygon");
        double t = rq.has_thickness ? rq.thickness : 0.0;
        if (!rq.has_thickness) {
          if (rq.thickness_attribute.empty()) throw TerrainError(what + ": no thickness (set thickness_m or thickness_attribute)");
          t = field_value(*f, rq.thickness_attribute, what);
        }
        // The same bound as the scenario's releases[].thickness_m (docs/user/scenarios.md, Valid ranges).
        if (!(t > 0 && t <= 500)) throw TerrainError(what + ": thickness must be > 0 m and at most 500 m, got " + fmt(t, 3));
        double smin = rq.has_min_slope ? rq.min_slope : 0.0, smax = rq.has_max_slope ? rq.max_slope : 90.0;
        if (!rq.has_min_slope && !rq.min_slope_attribute.empty()) smin = field_value(*f, rq.min_slope_attribute, what);
        if (!rq.has_max_slope && !rq.max_slope_attribute.empty()) smax = field_value(*f, rq.max_slope_attribute, what);
        if (!(smin >= 0 && smax <= 90 && smin < smax))
          throw TerrainError(what + ": slope window [" + fmt(smin) + ", " + fmt(smax) + "] deg must satisfy 0 <= min < max <= 90");
        std::unique_ptr<OGRGeometry> geom(g0->clone());
        if (!geom->IsValid()) {
          std::unique_ptr<OGRGeometry> fixed(geom->MakeValid());
          if (!fixed || fixed->IsEmpty()) throw TerrainError(what + ": invalid geometry that GEOS cannot repair");
          geom = std::move(fixed);
          rep.notes.push_back(what + ": invalid geometry (e.g. self-intersecting) repaired with GEOS MakeValid");
        }
        if (ct && geom->transform(ct.get()) != OGRERR_NONE) throw TerrainError(what + ": cannot transform it to " + g.crs_name);
        auto mask_ds = mem_raster(g, GDT_Byte);
        int band = 1;
        double burn = 1;
        OGRGeometryH gh = OGRGeometry::ToHandle(geom.get());
        if (GDALRasterizeGeometries(GDALDataset::ToHandle(mask_ds.get()), 1, &band, 1, &gh, nullptr, nullptr, &burn,
                                    nullptr, nullptr, nullptr) != CE_None)
          throw TerrainError(what + ": rasterisation failed" + gdal_message());
        std::vector<unsigned char> m(g.cells());
        if (mask_ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, g.nx, g.ny, m.data(), g.nx, g.ny, GDT_Byte, 0, 0) != CE_None)
          throw TerrainError(what + ": reading the rasterised polygon failed" + gdal_message());
        long inside = 0, kept = 0;
        double smin_seen = 90, smax_seen = 0;
        for (int r = 0; r < g.ny; ++r)
          for (int i = 0; i < g.nx; ++i) {
            if (!m[std::size_t(r) * g.nx + i]) continue;
            const std::size_t k = std::size_t(g.ny - 1 - r) * g.nx + i;
            if (!g.outside.empty() && g.outside[k]) continue;  // no release where the domain has no terrain
            ++inside;
            smin_seen = std::min(smin_seen, slope[k]);
            smax_seen = std::max(smax_seen, slope[k]);
            if (slope[k] < smin || slope[k] > smax) continue;
            ++kept;
            const double hn = rq.vertical ? t * std::cos(slope[k] * M_PI / 180) : t;
            h[k] = std::max(h[k], hn);
          }
        if (inside == 0)
          throw TerrainError(what + " lies outside the grid, outside the area of interest or where the DEM has no data, or is thinner than a cell (" + extent + ")");
        if (kept == 0)
          throw TerrainError(what + ": no cell has a slope within [" + fmt(smin) + ", " + fmt(smax) +
                             "] deg (slopes inside the polygon: " + fmt(smin_seen) + " to " + fmt(smax_seen) + " deg)");
        ++rep.polygons;
      }
    }
    if (n == 0) throw TerrainError("release '" + rq.path + "': no polygon in the file");
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
