// What a run writes on its grid as rasters: COG rasters of values and of classes, and ESRI ASCII
// grids on another raster's grid.
#include <gdal_alg.h>
#include <gdal_utils.h>
#include <gdal_priv.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "terrain/gdal_support.hpp"
#include "terrain/terrain.hpp"

namespace runout::terrain {

using namespace detail;

namespace {

void describe(GDALRasterBand* band, const BandInfo& info) {
  band->SetDescription(info.description.c_str());
  if (!info.unit.empty()) {
    band->SetUnitType(info.unit.c_str());
    band->SetMetadataItem("UNITS", info.unit.c_str());
  }
  for (const auto& [k, v] : info.metadata) band->SetMetadataItem(k.c_str(), v.c_str());
}

// The in-memory raster as a cloud-optimised GeoTIFF (DEFLATE; the COG driver adds overviews when the
// raster is larger than one 512-pixel tile).
void save_cog(GDALDataset& ds, const std::string& path, const char* predictor) {
  auto* cog = GetGDALDriverManager()->GetDriverByName("COG");
  const char* opts[] = {"COMPRESS=DEFLATE", predictor, nullptr};
  GDALDatasetUniquePtr out(cog->CreateCopy(path.c_str(), &ds, FALSE, const_cast<char**>(opts), nullptr, nullptr));
  if (!out) throw TerrainError("writing '" + path + "' failed" + gdal_message());
}

}  // namespace

void write_cog(const std::string& path, const Grid& g, const std::vector<double>& values, const BandInfo& info) {
  init_gdal();
  auto ds = mem_raster(g, GDT_Float32);
  auto* band = ds->GetRasterBand(1);
  const float nodata = -9999.0f;
  band->SetNoDataValue(nodata);
  describe(band, info);
  auto rows = north_first<float>(g, [&](std::size_t k) { return std::isfinite(values[k]) ? float(values[k]) : nodata; });
  if (band->RasterIO(GF_Write, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float32, 0, 0) != CE_None)
    throw TerrainError("writing '" + path + "' failed" + gdal_message());
  save_cog(*ds, path, "PREDICTOR=YES");
}

void write_band_stack(const std::string& path, const Grid& g, const std::vector<BandInfo>& bands,
                      const std::function<std::vector<double>(std::size_t)>& values,
                      const std::vector<std::pair<std::string, std::string>>& dataset_metadata) {
  init_gdal();
  CPLErrorReset();
  if (bands.empty()) throw TerrainError("writing '" + path + "': no bands");
  // The bands go one at a time into a tiled GeoTIFF beside the file (a frame's band need not be in
  // memory with the others), which then becomes the Cloud Optimized GeoTIFF.
  auto* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
  const std::string part = path + ".part.tif";
  const char* opts[] = {"TILED=YES", "COMPRESS=DEFLATE", "PREDICTOR=3", "BIGTIFF=IF_SAFER", "INTERLEAVE=BAND", nullptr};
  GDALDatasetUniquePtr ds(gtiff->Create(part.c_str(), g.nx, g.ny, int(bands.size()), GDT_Float32, const_cast<char**>(opts)));
  if (!ds) throw TerrainError("writing '" + path + "' failed" + gdal_message());
  double gt[6] = {g.x_min, g.dx, 0, g.y_min + g.ny * g.dx, 0, -g.dx};
  ds->SetGeoTransform(gt);
  ds->SetProjection(g.crs_wkt.c_str());
  for (const auto& [k, v] : dataset_metadata) ds->SetMetadataItem(k.c_str(), v.c_str());
  const float nodata = -9999.0f;
  for (std::size_t b = 0; b < bands.size(); ++b) {
    auto* band = ds->GetRasterBand(int(b) + 1);
    band->SetNoDataValue(nodata);
    describe(band, bands[b]);
    const auto v = values(b);
    auto rows = north_first<float>(g, [&](std::size_t k) {
      return std::isfinite(v[k]) && (g.outside.empty() || !g.outside[k]) ? float(v[k]) : nodata;
    });
    if (band->RasterIO(GF_Write, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float32, 0, 0) != CE_None)
      throw TerrainError("writing '" + path + "' failed" + gdal_message());
  }
  try {
    save_cog(*ds, path, "PREDICTOR=YES");
  } catch (...) {
    ds.reset();
    VSIUnlink(part.c_str());
    throw;
  }
  ds.reset();
  VSIUnlink(part.c_str());
  if (CPLGetLastErrorType() == CE_Failure) throw TerrainError("writing '" + path + "' failed" + gdal_message());
}

void write_class_cog(const std::string& path, const Grid& g, const std::vector<std::uint8_t>& cls, const std::vector<ValueClass>& classes,
                     const BandInfo& info) {
  init_gdal();
  if (classes.size() > 254) throw TerrainError("writing '" + path + "': more than 254 classes");
  auto ds = mem_raster(g, GDT_Byte);
  auto* band = ds->GetRasterBand(1);
  band->SetNoDataValue(255);
  describe(band, info);
  GDALColorTable colours;
  GDALColorEntry none = {255, 255, 255, 0};
  colours.SetColorEntry(0, &none);
  std::vector<std::string> names = {"none"};
  for (std::size_t k = 0; k < classes.size(); ++k) {
    const GDALColorEntry e = {classes[k].rgb[0], classes[k].rgb[1], classes[k].rgb[2], 255};
    colours.SetColorEntry(int(k) + 1, &e);
    names.push_back(classes[k].name);
  }
  band->SetColorTable(&colours);
  std::vector<char*> cat;
  for (auto& n : names) cat.push_back(n.data());
  cat.push_back(nullptr);
  band->SetCategoryNames(cat.data());
  auto rows = north_first<std::uint8_t>(g, [&](std::size_t k) { return !g.outside.empty() && g.outside[k] ? std::uint8_t(255) : cls[k]; });
  if (band->RasterIO(GF_Write, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Byte, 0, 0) != CE_None)
    throw TerrainError("writing '" + path + "' failed" + gdal_message());
  save_cog(*ds, path, "PREDICTOR=NO");
}

std::vector<double> masked_outside(const Grid& g, const std::vector<double>& values) {
  std::vector<double> m = values;
  for (std::size_t k = 0; k < m.size(); ++k)
    if (g.outside[k]) m[k] = std::numeric_limits<double>::quiet_NaN();
  return m;
}

void write_ascii_on(const std::string& path, const std::string& template_path, const Grid& g,
                    const std::vector<double>& values) {
  init_gdal();
  GDALDatasetUniquePtr tpl(GDALDataset::Open(template_path.c_str(), GDAL_OF_RASTER));
  if (!tpl) throw TerrainError("'" + template_path + "': cannot read it as a raster" + gdal_message());
  auto src = mem_raster(g, GDT_Float32);
  const float nodata = -9999.0f;
  src->GetRasterBand(1)->SetNoDataValue(nodata);
  auto rows = north_first<float>(g, [&](std::size_t k) { return std::isfinite(values[k]) ? float(values[k]) : nodata; });
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
