// Rasters read back onto the computation grid (an ensemble's members' hazard rasters).
#include <gdal_alg.h>

#include <algorithm>
#include <cmath>

#include "terrain/gdal_support.hpp"

namespace runout::terrain {

using namespace detail;

std::vector<double> read_raster_on(const std::string& path, const Grid& g, const std::string& what) {
  init_gdal();
  GDALDatasetUniquePtr src(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY));
  if (!src) throw TerrainError(what + ": cannot read '" + path + "' as a raster" + gdal_message());
  double gt[6] = {0, 1, 0, 0, 0, -1};
  const bool has_gt = src->GetGeoTransform(gt) == CE_None;
  const double tol = 1e-6 * g.dx;
  const bool same = has_gt && src->GetRasterXSize() == g.nx && src->GetRasterYSize() == g.ny && std::abs(gt[0] - g.x_min) < tol &&
                    std::abs(gt[3] - (g.y_min + g.ny * g.dx)) < tol && std::abs(gt[1] - g.dx) < tol && std::abs(gt[5] + g.dx) < tol &&
                    gt[2] == 0 && gt[4] == 0;
  GDALDatasetUniquePtr warped;
  GDALDataset* ds = src.get();
  if (!same) {  // another grid (an ensemble member at another resolution): nearest neighbour onto this one
    auto opt = warp_options({"-of", "MEM", "-t_srs", g.crs_wkt, "-te", fmt(g.x_min, 9), fmt(g.y_min, 9), fmt(g.x_min + g.nx * g.dx, 9),
                             fmt(g.y_min + g.ny * g.dx, 9), "-ts", std::to_string(g.nx), std::to_string(g.ny), "-r", "near",
                             "-dstnodata", "nan", "-ot", "Float64"});
    GDALDatasetH h = GDALDataset::ToHandle(src.get());
    int usage_error = 0;
    warped.reset(GDALDataset::FromHandle(GDALWarp("", nullptr, 1, &h, opt.get(), &usage_error)));
    if (!warped) throw TerrainError(what + ": cannot resample '" + path + "' onto the grid" + gdal_message());
    ds = warped.get();
  }
  auto* band = ds->GetRasterBand(1);
  std::vector<double> rows(g.cells());
  if (band->RasterIO(GF_Read, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float64, 0, 0) != CE_None)
    throw TerrainError(what + ": cannot read '" + path + "'" + gdal_message());
  int has_nodata = 0;
  const double nodata = band->GetNoDataValue(&has_nodata);
  std::vector<double> v(g.cells());
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) {
      const double x = rows[std::size_t(r) * g.nx + i];
      v[std::size_t(g.ny - 1 - r) * g.nx + i] = (has_nodata && x == nodata) ? NAN : x;
    }
  return v;
}

Grid grid_of_raster(const std::string& path, const std::string& what) {
  init_gdal();
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY));
  if (!ds) throw TerrainError(what + ": cannot read '" + path + "' as a raster" + gdal_message());
  double gt[6];
  if (ds->GetGeoTransform(gt) != CE_None || gt[2] != 0 || gt[4] != 0 || gt[1] <= 0 || std::abs(gt[1] + gt[5]) > 1e-9 * gt[1])
    throw TerrainError(what + ": '" + path + "' is not a north-up raster of square cells");
  Grid g;
  g.nx = ds->GetRasterXSize();
  g.ny = ds->GetRasterYSize();
  g.dx = gt[1];
  g.x_min = gt[0];
  g.y_min = gt[3] + g.ny * gt[5];
  if (const auto* srs = ds->GetSpatialRef()) {
    char* wkt = nullptr;
    srs->exportToWkt(&wkt);
    g.crs_wkt = wkt ? wkt : "";
    CPLFree(wkt);
    const char* auth = srs->GetAuthorityName(nullptr);
    const char* code = srs->GetAuthorityCode(nullptr);
    g.crs_name = auth && code ? std::string(auth) + ":" + code : (srs->GetName() ? srs->GetName() : "local");
  }
  g.z = read_raster_on(path, g, what);
  g.outside.assign(g.cells(), 0);
  for (std::size_t k = 0; k < g.cells(); ++k) g.outside[k] = std::isnan(g.z[k]);
  // Outside the domain the ground is filled from the data around it (GDAL's inverse-distance fill,
  // as the prepared grid fills it from the nearest data), so that the hillshade has no cliff there.
  auto mem = mem_raster(g, GDT_Float64);
  auto* band = mem->GetRasterBand(1);
  band->SetNoDataValue(-1e30);
  auto rows = north_first<double>(g, [&](std::size_t k) { return g.outside[k] ? -1e30 : g.z[k]; });
  if (band->RasterIO(GF_Write, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float64, 0, 0) != CE_None ||
      GDALFillNodata(band, nullptr, std::max(g.nx, g.ny), 0, 0, nullptr, nullptr, nullptr) != CE_None ||
      band->RasterIO(GF_Read, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float64, 0, 0) != CE_None)
    throw TerrainError(what + ": filling the ground outside the domain failed" + gdal_message());
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) g.z[std::size_t(g.ny - 1 - r) * g.nx + i] = rows[std::size_t(r) * g.nx + i];
  return g;
}

}  // namespace runout::terrain
