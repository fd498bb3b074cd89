// What a run writes on its grid: COG rasters, the runout outline (GeoJSON in WGS84, GeoPackage in
// the grid's CRS) and ESRI ASCII grids on another raster's grid.
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
