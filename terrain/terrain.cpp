#include "terrain/terrain.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal_alg.h>
#include <gdal_priv.h>
#include <gdal_utils.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>

namespace runout::terrain {
namespace {

void init_gdal() {
  static std::once_flag once;
  std::call_once(once, [] {
    GDALAllRegister();
    CPLSetErrorHandler(CPLQuietErrorHandler);  // errors are read back and reported by us
  });
}

std::string gdal_message() {
  const char* m = CPLGetLastErrorMsg();
  return (m && *m) ? std::string(": ") + m : std::string();
}

std::string fmt(double v, int prec = 1) {
  std::ostringstream o;
  if (std::abs(v) >= 1e9) {  // no 300-digit numbers in messages
    o.precision(4);
    o << v;
    return o.str();
  }
  o.setf(std::ios::fixed);
  o.precision(prec);
  o << v;
  return o.str();
}

OGRSpatialReference srs_from(const std::string& text, const std::string& what) {
  OGRSpatialReference s;
  if (text == "local") {  // local Cartesian metres: synthetic terrain, surveys without georeference
    s.SetLocalCS("local metres");
    s.SetLinearUnits(SRS_UL_METER, 1.0);
    return s;
  }
  if (s.SetFromUserInput(text.c_str()) != OGRERR_NONE)
    throw TerrainError(what + ": unknown CRS '" + text + "' (use e.g. EPSG:2056 or a WKT/PROJ string)");
  s.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return s;
}

OGRSpatialReference wgs84() {
  OGRSpatialReference s;
  s.importFromEPSG(4326);
  s.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return s;
}

std::string wkt(const OGRSpatialReference& s) {
  char* w = nullptr;
  s.exportToWkt(&w);
  std::string out = w ? w : "";
  CPLFree(w);
  return out;
}

std::string crs_name(const OGRSpatialReference& s) {
  if (s.IsLocal()) return "local metres";
  const char* auth = s.GetAuthorityName(nullptr);
  const char* code = s.GetAuthorityCode(nullptr);
  if (auth && code) return std::string(auth) + ":" + code;
  const char* n = s.GetName();
  return n ? n : "unnamed CRS";
}

// A coordinate transformation; nullptr for two local CRSs (the identity: they have no datum to relate).
std::unique_ptr<OGRCoordinateTransformation> transform(const OGRSpatialReference& from, const OGRSpatialReference& to,
                                                       const std::string& what) {
  if (from.IsLocal() || to.IsLocal()) {
    if (from.IsLocal() && to.IsLocal()) return nullptr;
    throw TerrainError(what + ": a local CRS cannot be related to " + (from.IsLocal() ? crs_name(to) : crs_name(from)) +
                       "; give every input in the same local CRS");
  }
  std::unique_ptr<OGRCoordinateTransformation> t(OGRCreateCoordinateTransformation(&from, &to));
  if (!t) throw TerrainError(what + ": no coordinate transformation between the CRSs" + gdal_message());
  return t;
}

// Union of the polygons of every layer of a vector file, with its CRS.
std::unique_ptr<OGRGeometry> read_area(const std::string& path, OGRSpatialReference& srs) {
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  if (!ds) throw TerrainError("area of interest '" + path + "': cannot read it as a vector file" + gdal_message());
  auto out = std::make_unique<OGRMultiPolygon>();
  bool have_srs = false;
  for (auto* layer : ds->GetLayers()) {
    if (const auto* s = layer->GetSpatialRef()) {
      srs = *s;
      srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
      have_srs = true;
    }
    for (auto& f : layer) {
      const OGRGeometry* g = f->GetGeometryRef();
      if (!g) continue;
      const auto type = wkbFlatten(g->getGeometryType());
      if (type == wkbPolygon) out->addGeometry(g);
      else if (type == wkbMultiPolygon)
        for (const auto* p : g->toMultiPolygon()) out->addGeometry(p);
    }
  }
  if (out->IsEmpty()) throw TerrainError("area of interest '" + path + "': no polygon in the file");
  if (!have_srs) throw TerrainError("area of interest '" + path + "': the file has no CRS");
  return out;
}

struct Raster {
  GDALDatasetUniquePtr ds;
};

double source_resolution_m(GDALDataset* ds, const OGRSpatialReference& s) {
  double gt[6];
  if (ds->GetGeoTransform(gt) != CE_None) return 0;
  if (s.IsGeographic()) {
    const double lat = gt[3] + gt[5] * ds->GetRasterYSize() / 2.0;
    const double mx = std::abs(gt[1]) * 111320.0 * std::cos(lat * M_PI / 180), my = std::abs(gt[5]) * 110540.0;
    return std::sqrt(mx * my);
  }
  return std::sqrt(std::abs(gt[1] * gt[5])) * s.GetLinearUnits();
}

}  // namespace

Grid prepare_grid(const DemRequest& req, DemReport* report) {
  init_gdal();
  DemReport rep;
  GDALDatasetUniquePtr dem(GDALDataset::Open(req.dem_path.c_str(), GDAL_OF_RASTER));
  if (!dem) throw TerrainError("DEM '" + req.dem_path + "': cannot read it as a raster" + gdal_message());
  double gt[6];
  if (dem->GetGeoTransform(gt) != CE_None)
    throw TerrainError("DEM '" + req.dem_path + "': the raster has no georeferencing");
  OGRSpatialReference src;
  if (!req.dem_crs.empty()) {
    if (dem->GetSpatialRef() && !dem->GetSpatialRef()->IsEmpty()) {
      // The file's own CRS wins; an explicit one is only for files without.
      src = *dem->GetSpatialRef();
      src.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    } else {
      src = srs_from(req.dem_crs, "dem.crs");
    }
  } else if (dem->GetSpatialRef() && !dem->GetSpatialRef()->IsEmpty()) {
    src = *dem->GetSpatialRef();
    src.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  } else {
    throw TerrainError("DEM '" + req.dem_path + "' has no CRS and none is given: set dem.crs (e.g. \"EPSG:2056\")");
  }
  rep.source_crs = crs_name(src);
  rep.source_resolution_m = source_resolution_m(dem.get(), src);

  // Area of interest (optional) and the extent's centre in lon/lat.
  std::unique_ptr<OGRGeometry> aoi;
  OGRSpatialReference aoi_srs;
  if (!req.aoi_path.empty()) {
    aoi = read_area(req.aoi_path, aoi_srs);
    rep.used_aoi = true;
  }
  const auto ll = wgs84();
  double clon = 0, clat = 0;
  if (src.IsLocal()) {
    // No geographic position: the grid stays in the local CRS.
  } else if (aoi) {
    OGREnvelope e;
    aoi->getEnvelope(&e);
    clon = 0.5 * (e.MinX + e.MaxX);
    clat = 0.5 * (e.MinY + e.MaxY);
    auto ct = transform(aoi_srs, ll, "area of interest");
    if (ct) ct->Transform(1, &clon, &clat);
  } else {
    clon = gt[0] + gt[1] * dem->GetRasterXSize() / 2.0 + gt[2] * dem->GetRasterYSize() / 2.0;
    clat = gt[3] + gt[4] * dem->GetRasterXSize() / 2.0 + gt[5] * dem->GetRasterYSize() / 2.0;
    auto ct = transform(src, ll, "DEM");
    if (ct) ct->Transform(1, &clon, &clat);
  }

  // Computation CRS.
  OGRSpatialReference dst;
  if (src.IsLocal()) {
    if (!(req.target_crs.empty() || req.target_crs == "dem"))
      throw TerrainError("grid.crs: a DEM in a local CRS is computed in it (\"dem\"), not in " + req.target_crs);
    dst = src;
  } else if (req.target_crs.empty() || req.target_crs == "utm") {
    const int zone = std::clamp(int(std::floor((clon + 180.0) / 6.0)) + 1, 1, 60);
    dst.importFromEPSG((clat >= 0 ? 32600 : 32700) + zone);
  } else if (req.target_crs == "dem") {
    dst = src;
  } else {
    dst = srs_from(req.target_crs, "grid.crs");
  }
  dst.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  if (!dst.IsProjected() && !dst.IsLocal())
    throw TerrainError("grid.crs: the computation needs a projected CRS in metres, got " + crs_name(dst));

  // The DEM's own grid is used as it is (no resampling) when the computation CRS is the DEM's, its
  // raster is north-up with square cells and the resolution is the DEM's (or not given).
  const bool north_up = gt[2] == 0 && gt[4] == 0 && gt[5] < 0 && std::abs(gt[1] + gt[5]) <= 1e-9 * gt[1];
  const bool native = north_up && dst.IsSame(&src) &&
                      (req.resolution <= 0 || std::abs(req.resolution - gt[1]) <= 1e-6 * gt[1]);
  const double res = native ? gt[1]
                     : req.resolution > 0 ? req.resolution
                                          : std::max(1.0, std::round(rep.source_resolution_m));
  if (rep.source_resolution_m > 0 && res < rep.source_resolution_m / 10.0)
    throw TerrainError("grid.resolution_m = " + fmt(res, 2) + " m is finer than a tenth of the DEM's resolution (" +
                       fmt(rep.source_resolution_m, 1) + " m)");

  // Warp options.
  std::vector<std::string> args = {"-of", "MEM", "-tr", fmt(res, 6), fmt(res, 6),
                                   "-r", req.resampling.empty() ? "cubic" : req.resampling, "-dstnodata", "-99999",
                                   "-ot", "Float64"};
  if (src.IsLocal()) {
    // One local frame: resampling only, through the geotransforms (there is no CRS to transform).
    for (const char* o : {"-to", "SRC_METHOD=GEOTRANSFORM", "-to", "DST_METHOD=GEOTRANSFORM"}) args.push_back(o);
  } else {
    args.push_back("-t_srs");
    args.push_back(wkt(dst));
  }
  if (!src.IsLocal() && !req.dem_crs.empty() && !(dem->GetSpatialRef() && !dem->GetSpatialRef()->IsEmpty())) {
    args.push_back("-s_srs");
    args.push_back(wkt(src));
  }
  if (aoi) {
    // From here on the area is used in the computation CRS (bounding box here, mask below).
    auto ct = transform(aoi_srs, dst, "area of interest");
    if (ct && aoi->transform(ct.get()) != OGRERR_NONE)
      throw TerrainError("area of interest '" + req.aoi_path + "': cannot transform it to " + crs_name(dst));
    OGREnvelope e;
    aoi->getEnvelope(&e);
    const double x0 = std::floor(e.MinX / res) * res, y0 = std::floor(e.MinY / res) * res;
    const double x1 = std::ceil(e.MaxX / res) * res, y1 = std::ceil(e.MaxY / res) * res;
    args.push_back("-te");
    args.push_back(fmt(x0, 6));
    args.push_back(fmt(y0, 6));
    args.push_back(fmt(x1, 6));
    args.push_back(fmt(y1, 6));
  } else {
    args.push_back("-tap");
  }
  {
    // Size check before warping: an extent estimate from the AOI or the DEM.
    double w = 0, h = 0;
    if (aoi) {
      const auto& te = args;
      const std::size_t k = std::find(te.begin(), te.end(), "-te") - te.begin();
      w = std::stod(te[k + 3]) - std::stod(te[k + 1]);
      h = std::stod(te[k + 4]) - std::stod(te[k + 2]);
    } else {
      w = dem->GetRasterXSize() * rep.source_resolution_m;
      h = dem->GetRasterYSize() * rep.source_resolution_m;
    }
    const double cells = (w / res) * (h / res);
    if (cells * req.bytes_per_cell > req.memory_budget_bytes)
      throw TerrainError("grid of about " + fmt(cells / 1e6, 1) + " million cells at " + fmt(res, 2) +
                         " m exceeds the memory budget of " + fmt(req.memory_budget_bytes / (1u << 30), 1) +
                         " GiB: choose a coarser grid.resolution_m or a smaller area of interest");
  }
  Grid g;
  g.crs_wkt = wkt(dst);
  g.crs_name = crs_name(dst);
  std::vector<double> rows;
  if (native) {
    // A window of whole DEM cells covering the area (or the whole DEM), values as they are.
    int c0 = 0, r0 = 0, c1 = dem->GetRasterXSize(), r1 = dem->GetRasterYSize();
    if (aoi) {
      const std::size_t k = std::find(args.begin(), args.end(), "-te") - args.begin();
      const double ex0 = std::stod(args[k + 1]), ey0 = std::stod(args[k + 2]), ex1 = std::stod(args[k + 3]),
                   ey1 = std::stod(args[k + 4]);
      c0 = std::max(c0, int(std::floor((ex0 - gt[0]) / gt[1])));
      c1 = std::min(c1, int(std::ceil((ex1 - gt[0]) / gt[1])));
      r0 = std::max(r0, int(std::floor((ey1 - gt[3]) / gt[5])));
      r1 = std::min(r1, int(std::ceil((ey0 - gt[3]) / gt[5])));
    }
    g.nx = c1 - c0;
    g.ny = r1 - r0;
    g.dx = gt[1];
    g.x_min = gt[0] + c0 * gt[1];
    g.y_min = gt[3] + r1 * gt[5];
    if (g.nx < 3 || g.ny < 3) throw TerrainError("the area of interest covers fewer than 3 x 3 cells of the DEM");
    rows.resize(g.cells());
    auto* band = dem->GetRasterBand(1);
    if (band->RasterIO(GF_Read, c0, r0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float64, 0, 0) != CE_None)
      throw TerrainError("DEM '" + req.dem_path + "': reading the raster failed" + gdal_message());
    int has = 0;
    const double nd = band->GetNoDataValue(&has);
    if (has)
      for (double& v : rows)
        if (v == nd || std::isnan(nd) != std::isnan(v)) v = -99999.0;
  } else {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::unique_ptr<GDALWarpAppOptions, decltype(&GDALWarpAppOptionsFree)> wopt(
        GDALWarpAppOptionsNew(argv.data(), nullptr), GDALWarpAppOptionsFree);
    if (!wopt) throw TerrainError("internal: warp options rejected" + gdal_message());
    GDALDatasetH srch = GDALDataset::ToHandle(dem.get());
    int usage_error = 0;
    GDALDatasetUniquePtr warped(GDALDataset::FromHandle(GDALWarp("", nullptr, 1, &srch, wopt.get(), &usage_error)));
    if (!warped) throw TerrainError("DEM '" + req.dem_path + "': reprojection failed" + gdal_message());
    g.nx = warped->GetRasterXSize();
    g.ny = warped->GetRasterYSize();
    double wgt[6];
    warped->GetGeoTransform(wgt);
    g.dx = wgt[1];
    g.x_min = wgt[0];
    g.y_min = wgt[3] + wgt[5] * g.ny;
    if (g.nx < 3 || g.ny < 3) throw TerrainError("the area of interest covers fewer than 3 x 3 cells at " + fmt(res, 2) + " m");
    rows.resize(g.cells());
    if (warped->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float64, 0, 0) != CE_None)
      throw TerrainError("DEM '" + req.dem_path + "': reading the reprojected raster failed" + gdal_message());
  }
  g.z.resize(g.cells());
  g.outside.assign(g.cells(), 0);
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) {
      const double v = rows[std::size_t(r) * g.nx + i];
      const std::size_t k = std::size_t(g.ny - 1 - r) * g.nx + i;
      if (!(v > -99998) || !std::isfinite(v)) {
        g.outside[k] = 1;
        ++rep.cells_without_data;
      }
      g.z[k] = v;
    }
  // Cells outside the area-of-interest polygon are outside the domain too.
  if (aoi) {
    GDALDatasetUniquePtr mask(GetGDALDriverManager()->GetDriverByName("MEM")->Create("", g.nx, g.ny, 1, GDT_Byte, nullptr));
    double mgt[6] = {g.x_min, g.dx, 0, g.y_min + g.ny * g.dx, 0, -g.dx};
    mask->SetGeoTransform(mgt);
    int band = 1;
    double burn = 1;
    OGRGeometryH gh = OGRGeometry::ToHandle(aoi.get());
    std::vector<unsigned char> m(g.cells());
    if (GDALRasterizeGeometries(GDALDataset::ToHandle(mask.get()), 1, &band, 1, &gh, nullptr, nullptr, &burn, nullptr,
                                nullptr, nullptr) != CE_None ||
        mask->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, g.nx, g.ny, m.data(), g.nx, g.ny, GDT_Byte, 0, 0) != CE_None)
      throw TerrainError("area of interest '" + req.aoi_path + "': rasterisation failed" + gdal_message());
    for (int r = 0; r < g.ny; ++r)
      for (int i = 0; i < g.nx; ++i) {
        const std::size_t k = std::size_t(g.ny - 1 - r) * g.nx + i;
        if (!m[std::size_t(r) * g.nx + i] && !g.outside[k]) {
          g.outside[k] = 1;
          ++rep.cells_outside_area;
        }
      }
  }
  const long inside = long(g.cells()) - rep.cells_without_data - rep.cells_outside_area;
  if (inside < 9)
    throw TerrainError("DEM '" + req.dem_path + "' has data for only " + std::to_string(inside) + " cells of the area (" +
                       std::to_string(rep.cells_without_data) + " without data, " + std::to_string(rep.cells_outside_area) +
                       " outside the area of interest): the area of interest must lie inside the DEM");
  // Cells without data get the elevation of the nearest cells with data (breadth-first), so that
  // the gradients of the domain's edge cells stay finite; the engine keeps material out of them.
  {
    std::vector<std::size_t> front, next;
    std::vector<std::uint8_t> known(g.cells());
    for (std::size_t k = 0; k < g.cells(); ++k) {
      known[k] = std::isfinite(g.z[k]) && g.z[k] > -99998;
      if (known[k]) front.push_back(k);
    }
    while (!front.empty()) {
      next.clear();
      for (std::size_t k : front) {
        const int i = int(k % g.nx), j = int(k / g.nx);
        const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
        for (int d = 0; d < 4; ++d) {
          const int u = i + di[d], v = j + dj[d];
          if (u < 0 || v < 0 || u >= g.nx || v >= g.ny) continue;
          const std::size_t q = std::size_t(v) * g.nx + u;
          if (known[q]) continue;
          known[q] = 1;
          g.z[q] = g.z[k];
          next.push_back(q);
        }
      }
      front.swap(next);
    }
  }
  const auto sl = slope_deg(g);
  std::vector<double> sorted;
  double sum = 0;
  rep.z_min = 1e300;
  rep.z_max = -1e300;
  for (std::size_t k = 0; k < g.cells(); ++k) {
    if (g.outside[k]) continue;
    sorted.push_back(sl[k]);
    sum += sl[k];
    rep.z_min = std::min(rep.z_min, g.z[k]);
    rep.z_max = std::max(rep.z_max, g.z[k]);
  }
  std::sort(sorted.begin(), sorted.end());
  rep.slope_mean_deg = sum / double(sorted.size());
  rep.slope_max_deg = sorted.back();
  rep.slope_p90_deg = sorted[std::size_t(0.9 * double(sorted.size() - 1))];
  if (report) *report = rep;
  return g;
}

std::vector<double> slope_deg(const Grid& g) {
  std::vector<double> s(g.cells());
  auto z = [&](int i, int j) { return g.z[std::size_t(std::clamp(j, 0, g.ny - 1)) * g.nx + std::clamp(i, 0, g.nx - 1)]; };
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const int il = std::max(i - 1, 0), ir = std::min(i + 1, g.nx - 1), jl = std::max(j - 1, 0), jr = std::min(j + 1, g.ny - 1);
      const double bx = (z(ir, j) - z(il, j)) / ((ir - il) * g.dx), by = (z(i, jr) - z(i, jl)) / ((jr - jl) * g.dx);
      s[std::size_t(j) * g.nx + i] = std::atan(std::hypot(bx, by)) * 180.0 / M_PI;
    }
  return s;
}

namespace {

GDALDatasetUniquePtr mem_raster(const Grid& g, GDALDataType type) {
  auto* drv = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDatasetUniquePtr ds(drv->Create("", g.nx, g.ny, 1, type, nullptr));
  double gt[6] = {g.x_min, g.dx, 0, g.y_min + g.ny * g.dx, 0, -g.dx};
  ds->SetGeoTransform(gt);
  ds->SetProjection(g.crs_wkt.c_str());
  return ds;
}

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
        // The same bound as the scenario's releases[].thickness_m (README, Valid ranges).
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

void write_cog(const std::string& path, const Grid& g, const std::vector<double>& values, const std::string& description) {
  init_gdal();
  auto ds = mem_raster(g, GDT_Float32);
  auto* band = ds->GetRasterBand(1);
  const float nodata = -9999.0f;
  band->SetNoDataValue(nodata);
  band->SetDescription(description.c_str());
  std::vector<float> rows(g.cells());
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) {
      const double v = values[std::size_t(g.ny - 1 - r) * g.nx + i];
      rows[std::size_t(r) * g.nx + i] = std::isfinite(v) ? float(v) : nodata;
    }
  if (band->RasterIO(GF_Write, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float32, 0, 0) != CE_None)
    throw TerrainError("writing '" + path + "' failed" + gdal_message());
  auto* cog = GetGDALDriverManager()->GetDriverByName("COG");
  const char* opts[] = {"COMPRESS=DEFLATE", "PREDICTOR=YES", nullptr};
  GDALDatasetUniquePtr out(cog->CreateCopy(path.c_str(), ds.get(), FALSE, const_cast<char**>(opts), nullptr, nullptr));
  if (!out) throw TerrainError("writing '" + path + "' failed" + gdal_message());
}

OutlineReport write_outline(const std::string& geojson_path, const std::string& gpkg_path, const Grid& g,
                            const std::vector<double>& values, double threshold) {
  init_gdal();
  OutlineReport rep;
  auto mask = mem_raster(g, GDT_Byte);
  std::vector<unsigned char> m(g.cells());
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) m[std::size_t(r) * g.nx + i] = values[std::size_t(g.ny - 1 - r) * g.nx + i] > threshold;
  if (mask->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, g.nx, g.ny, m.data(), g.nx, g.ny, GDT_Byte, 0, 0) != CE_None)
    throw TerrainError("outline: writing the mask failed" + gdal_message());
  OGRSpatialReference srs;
  srs.importFromWkt(g.crs_wkt.c_str());
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  auto* gpkg = GetGDALDriverManager()->GetDriverByName("GPKG");
  GDALDatasetUniquePtr vds(gpkg->Create(gpkg_path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  if (!vds) throw TerrainError("writing '" + gpkg_path + "' failed" + gdal_message());
  OGRLayer* layer = vds->CreateLayer("runout_outline", &srs, wkbPolygon, nullptr);
  OGRFieldDefn fd("inside", OFTInteger);
  layer->CreateField(&fd);
  if (GDALPolygonize(mask->GetRasterBand(1), mask->GetRasterBand(1), layer, 0, nullptr, nullptr, nullptr) != CE_None)
    throw TerrainError("outline: polygonising failed" + gdal_message());
  layer->ResetReading();
  for (auto& f : layer) {
    if (const OGRGeometry* geom = f->GetGeometryRef()) {
      rep.area_m2 += geom->toPolygon()->get_Area();
      ++rep.polygons;
    }
  }
  if (srs.IsLocal()) return rep;  // no geographic coordinates: no GeoJSON (RFC 7946 is WGS84)
  // GeoJSON in WGS84 (RFC 7946) from the same polygons.
  auto* gj = GetGDALDriverManager()->GetDriverByName("GeoJSON");
  const char* gjopts[] = {"RFC7946=YES", nullptr};
  GDALDatasetUniquePtr jds(gj->Create(geojson_path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  if (!jds) throw TerrainError("writing '" + geojson_path + "' failed" + gdal_message());
  auto ll = wgs84();
  OGRLayer* jl = jds->CreateLayer("runout_outline", &ll, wkbPolygon, const_cast<char**>(gjopts));
  OGRFieldDefn area("area_m2", OFTReal);
  jl->CreateField(&area);
  auto ct = transform(srs, ll, "outline");
  layer->ResetReading();
  for (auto& f : layer) {
    const OGRGeometry* geom = f->GetGeometryRef();
    if (!geom) continue;
    std::unique_ptr<OGRGeometry> w(geom->clone());
    w->transform(ct.get());
    OGRFeature out(jl->GetLayerDefn());
    out.SetField("area_m2", geom->toPolygon()->get_Area());
    out.SetGeometry(w.get());
    if (jl->CreateFeature(&out) != OGRERR_NONE) throw TerrainError("writing '" + geojson_path + "' failed" + gdal_message());
  }
  rep.geojson = true;
  return rep;
}

void write_ascii_on(const std::string& path, const std::string& template_path, const Grid& g,
                    const std::vector<double>& values) {
  init_gdal();
  GDALDatasetUniquePtr tpl(GDALDataset::Open(template_path.c_str(), GDAL_OF_RASTER));
  if (!tpl) throw TerrainError("'" + template_path + "': cannot read it as a raster" + gdal_message());
  auto src = mem_raster(g, GDT_Float32);
  const float nodata = -9999.0f;
  src->GetRasterBand(1)->SetNoDataValue(nodata);
  std::vector<float> rows(g.cells());
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) {
      const double v = values[std::size_t(g.ny - 1 - r) * g.nx + i];
      rows[std::size_t(r) * g.nx + i] = std::isfinite(v) ? float(v) : nodata;
    }
  if (src->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float32, 0, 0) != CE_None)
    throw TerrainError("writing '" + path + "' failed");
  auto* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDatasetUniquePtr dst(mem->Create("", tpl->GetRasterXSize(), tpl->GetRasterYSize(), 1, GDT_Float32, nullptr));
  double gt[6];
  tpl->GetGeoTransform(gt);
  dst->SetGeoTransform(gt);
  // The template's CRS, or the grid's when the template has none (a DEM whose CRS the scenario gave).
  const OGRSpatialReference* ts = tpl->GetSpatialRef();
  dst->SetProjection(ts && !ts->IsEmpty() ? wkt(*ts).c_str() : g.crs_wkt.c_str());
  dst->GetRasterBand(1)->SetNoDataValue(nodata);
  dst->GetRasterBand(1)->Fill(nodata);
  std::vector<std::string> args = {"-r", "bilinear", "-srcnodata", "-9999", "-dstnodata", "-9999"};
  OGRSpatialReference gs;
  gs.importFromWkt(g.crs_wkt.c_str());
  if (gs.IsLocal()) {  // identical local frames: no CRS to transform between
    args.push_back("-to");
    args.push_back("SRC_METHOD=GEOTRANSFORM");
    args.push_back("-to");
    args.push_back("DST_METHOD=GEOTRANSFORM");
  }
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::unique_ptr<GDALWarpAppOptions, decltype(&GDALWarpAppOptionsFree)> wopt(GDALWarpAppOptionsNew(argv.data(), nullptr),
                                                                               GDALWarpAppOptionsFree);
  GDALDatasetH s = GDALDataset::ToHandle(src.get());
  int usage = 0;
  if (!GDALWarp(nullptr, GDALDataset::ToHandle(dst.get()), 1, &s, wopt.get(), &usage))
    throw TerrainError("writing '" + path + "': resampling to the DEM's grid failed" + gdal_message());
  auto* asc = GetGDALDriverManager()->GetDriverByName("AAIGrid");
  const char* opts[] = {"DECIMAL_PRECISION=4", nullptr};
  GDALDatasetUniquePtr out(asc->CreateCopy(path.c_str(), dst.get(), FALSE, const_cast<char**>(opts), nullptr, nullptr));
  if (!out) throw TerrainError("writing '" + path + "' failed" + gdal_message());
}

}  // namespace runout::terrain
