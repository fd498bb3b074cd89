// The computation grid from a DEM: its CRS, the computation CRS (UTM by default), the grid's
// resolution and extent (the area of interest's bounding box, or the whole DEM), the elevations
// (the DEM's own cells when nothing needs resampling, else gdalwarp), the cells outside the domain,
// and the slope summary.
#include <gdal_alg.h>
#include <gdal_priv.h>
#include <gdal_utils.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "terrain/gdal_support.hpp"
#include "terrain/terrain.hpp"

namespace runout::terrain {
namespace {

using namespace detail;

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

// The DEM's CRS: the file's own; dem.crs only for a file without one.
OGRSpatialReference dem_crs(GDALDataset& dem, const DemRequest& req) {
  return input_crs(dem.GetSpatialRef(), req.dem_crs, "dem.crs",
                   "DEM '" + req.dem_path + "' has no CRS and none is given: set dem.crs (e.g. \"EPSG:2056\")");
}

// The centre of the area of interest (else of the DEM) in lon/lat: it picks the UTM zone. Zero for
// a local CRS (no geographic position).
void centre_lonlat(GDALDataset& dem, const double* gt, const OGRSpatialReference& src, const OGRGeometry* aoi,
                   const OGRSpatialReference& aoi_srs, double& clon, double& clat) {
  const auto ll = wgs84();
  clon = 0;
  clat = 0;
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
    clon = gt[0] + gt[1] * dem.GetRasterXSize() / 2.0 + gt[2] * dem.GetRasterYSize() / 2.0;
    clat = gt[3] + gt[4] * dem.GetRasterXSize() / 2.0 + gt[5] * dem.GetRasterYSize() / 2.0;
    auto ct = transform(src, ll, "DEM");
    if (ct) ct->Transform(1, &clon, &clat);
  }
}

// The computation CRS: grid.crs ("utm" by default, "dem", or any projected CRS in metres).
OGRSpatialReference computation_crs(const DemRequest& req, const OGRSpatialReference& src, double clon, double clat) {
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
  return dst;
}

// gdalwarp's arguments for the DEM in the computation CRS at `res` (without the extent).
std::vector<std::string> resample_args(const DemRequest& req, GDALDataset& dem, const OGRSpatialReference& src,
                                       const OGRSpatialReference& dst, double res) {
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
  if (!src.IsLocal() && !req.dem_crs.empty() && !(dem.GetSpatialRef() && !dem.GetSpatialRef()->IsEmpty())) {
    args.push_back("-s_srs");
    args.push_back(wkt(src));
  }
  return args;
}

// gdalwarp's arguments for the grid. With an area of interest, the area is transformed into the
// computation CRS here (bounding box here, mask later) and the extent is its box on whole cells.
std::vector<std::string> warp_args(const DemRequest& req, GDALDataset& dem, const OGRSpatialReference& src,
                                   const OGRSpatialReference& dst, double res, OGRGeometry* aoi, const OGRSpatialReference& aoi_srs) {
  std::vector<std::string> args = resample_args(req, dem, src, dst, res);
  if (aoi) {
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
  return args;
}

// The extent (-te) in the warp arguments: x0, y0, x1, y1.
std::array<double, 4> target_extent(const std::vector<std::string>& args) {
  const std::size_t k = std::find(args.begin(), args.end(), "-te") - args.begin();
  return {std::stod(args[k + 1]), std::stod(args[k + 2]), std::stod(args[k + 3]), std::stod(args[k + 4])};
}

// Refuses a grid that would not fit the memory budget, before warping: an extent estimate from the
// area of interest or the DEM.
void check_memory(const DemRequest& req, const std::vector<std::string>& args, GDALDataset& dem, const DemReport& rep,
                  double res, bool aoi) {
  double w = 0, h = 0;
  if (aoi) {
    const auto te = target_extent(args);
    w = te[2] - te[0];
    h = te[3] - te[1];
  } else {
    w = dem.GetRasterXSize() * rep.source_resolution_m;
    h = dem.GetRasterYSize() * rep.source_resolution_m;
  }
  const double cells = (w / res) * (h / res);
  if (cells * req.bytes_per_cell > req.memory_budget_bytes)
    throw TerrainError("grid of about " + fmt(cells / 1e6, 1) + " million cells at " + fmt(res, 2) +
                       " m exceeds the memory budget of " + fmt(req.memory_budget_bytes / (1u << 30), 1) +
                       " GiB: choose a coarser grid.resolution_m or a smaller area of interest");
}

// A window of whole DEM cells covering the area (or the whole DEM), values as they are; rows from
// the north, nodata as -99999.
std::vector<double> read_native(const DemRequest& req, GDALDataset& dem, const double* gt, const std::vector<std::string>& args,
                                bool aoi, Grid& g) {
  int c0 = 0, r0 = 0, c1 = dem.GetRasterXSize(), r1 = dem.GetRasterYSize();
  if (aoi) {
    const auto te = target_extent(args);
    const double ex0 = te[0], ey0 = te[1], ex1 = te[2], ey1 = te[3];
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
  std::vector<double> rows(g.cells());
  auto* band = dem.GetRasterBand(1);
  if (band->RasterIO(GF_Read, c0, r0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float64, 0, 0) != CE_None)
    throw TerrainError("DEM '" + req.dem_path + "': reading the raster failed" + gdal_message());
  int has = 0;
  const double nd = band->GetNoDataValue(&has);
  if (has)
    for (double& v : rows)
      if (v == nd || std::isnan(nd) != std::isnan(v)) v = -99999.0;
  return rows;
}

// The DEM warped onto the grid by gdalwarp; rows from the north, nodata as -99999.
// The DEM warped by gdalwarp's `args`: the warped raster's geometry into g (nx, ny, dx, x_min, y_min)
// and its rows (row 0 north). Errors name the DEM and the step (`warp_failed`, `read_failed`).
std::vector<double> warp_rows(const std::string& dem_path, GDALDataset& dem, std::vector<std::string>& args, Grid& g,
                              const std::string& warp_failed, const std::string& read_failed) {
  const auto wopt = warp_options(args);
  GDALDatasetH srch = GDALDataset::ToHandle(&dem);
  int usage_error = 0;
  GDALDatasetUniquePtr warped(GDALDataset::FromHandle(GDALWarp("", nullptr, 1, &srch, wopt.get(), &usage_error)));
  if (!warped) throw TerrainError("DEM '" + dem_path + "': " + warp_failed + gdal_message());
  g.nx = warped->GetRasterXSize();
  g.ny = warped->GetRasterYSize();
  double wgt[6];
  warped->GetGeoTransform(wgt);
  g.dx = wgt[1];
  g.x_min = wgt[0];
  g.y_min = wgt[3] + wgt[5] * g.ny;
  std::vector<double> rows(g.cells());
  if (warped->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float64, 0, 0) != CE_None)
    throw TerrainError("DEM '" + dem_path + "': " + read_failed + gdal_message());
  return rows;
}

std::vector<double> read_warped(const DemRequest& req, GDALDataset& dem, std::vector<std::string>& args, double res, Grid& g) {
  auto rows = warp_rows(req.dem_path, dem, args, g, "reprojection failed", "reading the reprojected raster failed");
  if (g.nx < 3 || g.ny < 3) throw TerrainError("the area of interest covers fewer than 3 x 3 cells at " + fmt(res, 2) + " m");
  return rows;
}

// The elevations into the grid (row 0 south); cells without data are outside the domain.
void take_rows(Grid& g, const std::vector<double>& rows, DemReport& rep) {
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
}

// Cells outside the area-of-interest polygon are outside the domain too.
void mask_outside_area(Grid& g, const OGRGeometry& area, const DemRequest& req, DemReport& rep) {
  GDALDatasetUniquePtr mask(GetGDALDriverManager()->GetDriverByName("MEM")->Create("", g.nx, g.ny, 1, GDT_Byte, nullptr));
  double mgt[6] = {g.x_min, g.dx, 0, g.y_min + g.ny * g.dx, 0, -g.dx};
  mask->SetGeoTransform(mgt);
  int band = 1;
  double burn = 1;
  OGRGeometryH gh = OGRGeometry::ToHandle(const_cast<OGRGeometry*>(&area));
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

// Cells without data get the elevation of the nearest cells with data (breadth-first), so that
// the gradients of the domain's edge cells stay finite; the engine keeps material out of them.
void fill_without_data(Grid& g) {
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

// Elevation range and slope statistics of the cells inside the domain.
void summarise(const Grid& g, DemReport& rep) {
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
  const OGRSpatialReference src = dem_crs(*dem, req);
  rep.source_crs = crs_name(src);
  rep.source_resolution_m = source_resolution_m(dem.get(), src);

  // Area of interest (optional) and the computation CRS.
  std::unique_ptr<OGRGeometry> aoi;
  OGRSpatialReference aoi_srs;
  if (!req.aoi_path.empty()) {
    aoi = read_area(req.aoi_path, aoi_srs);
    rep.used_aoi = true;
  }
  double clon = 0, clat = 0;
  centre_lonlat(*dem, gt, src, aoi.get(), aoi_srs, clon, clat);
  const OGRSpatialReference dst = computation_crs(req, src, clon, clat);

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

  std::vector<std::string> args = warp_args(req, *dem, src, dst, res, aoi.get(), aoi_srs);
  check_memory(req, args, *dem, rep, res, bool(aoi));
  Grid g;
  g.crs_wkt = wkt(dst);
  g.crs_name = crs_name(dst);
  const std::vector<double> rows = native ? read_native(req, *dem, gt, args, bool(aoi), g) : read_warped(req, *dem, args, res, g);
  take_rows(g, rows, rep);
  if (aoi) mask_outside_area(g, *aoi, req, rep);
  const long inside = long(g.cells()) - rep.cells_without_data - rep.cells_outside_area;
  if (inside < 9)
    throw TerrainError("DEM '" + req.dem_path + "' has data for only " + std::to_string(inside) + " cells of the area (" +
                       std::to_string(rep.cells_without_data) + " without data, " + std::to_string(rep.cells_outside_area) +
                       " outside the area of interest): the area of interest must lie inside the DEM");
  fill_without_data(g);
  summarise(g, rep);
  if (report) *report = rep;
  return g;
}

namespace detail {

double slope_spacing(const DemRequest& req, const Grid& g) {
  init_gdal();
  GDALDatasetUniquePtr dem(GDALDataset::Open(req.dem_path.c_str(), GDAL_OF_RASTER));
  if (!dem) throw TerrainError("DEM '" + req.dem_path + "': cannot read it as a raster" + gdal_message());
  const double r = source_resolution_m(dem.get(), dem_crs(*dem, req));
  if (!(r > 0)) return g.dx;  // no georeferenced pixel size: the grid's own
  return std::min(r, std::max(r / 8, 1.0));
}

Grid dem_surface(const DemRequest& req, const Grid& g, double res, double x0, double y0, double x1, double y1) {
  init_gdal();
  GDALDatasetUniquePtr dem(GDALDataset::Open(req.dem_path.c_str(), GDAL_OF_RASTER));
  if (!dem) throw TerrainError("DEM '" + req.dem_path + "': cannot read it as a raster" + gdal_message());
  const OGRSpatialReference src = dem_crs(*dem, req);
  OGRSpatialReference dst;
  dst.importFromWkt(g.crs_wkt.c_str());
  dst.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  auto args = resample_args(req, *dem, src, dst, res);
  const int nx = std::max(3, int(std::ceil((x1 - x0) / res))), ny = std::max(3, int(std::ceil((y1 - y0) / res)));
  for (const std::string& a : {std::string("-te"), fmt(x0, 6), fmt(y0, 6), fmt(x0 + nx * res, 6), fmt(y0 + ny * res, 6)}) args.push_back(a);
  Grid s;
  s.crs_wkt = g.crs_wkt;
  s.crs_name = g.crs_name;
  const auto rows = warp_rows(req.dem_path, *dem, args, s, "resampling it at the slope window's spacing failed",
                              "reading the resampled raster failed");
  DemReport unused;
  take_rows(s, rows, unused);
  fill_without_data(s);
  return s;
}

}  // namespace detail

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

}  // namespace runout::terrain
