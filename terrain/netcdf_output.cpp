// A time series on the grid as one NetCDF-4 file with the CF conventions (GDAL's multidimensional
// netCDF writer): dimensions time, y, x with their coordinate variables, a grid mapping for the CRS,
// one Float32 variable per field. QGIS opens it as a mesh layer whose datasets step with its temporal
// controller, and GDAL, xarray and Panoply read it as they read any CF file.
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "terrain/gdal_support.hpp"
#include "terrain/terrain.hpp"

namespace runout::terrain {

using namespace detail;

namespace {

void text_attribute(GDALMDArray& a, const char* name, const std::string& value) {
  auto attr = a.CreateAttribute(name, {}, GDALExtendedDataType::CreateString());
  if (!attr || !attr->Write(value.c_str())) throw TerrainError(std::string("netCDF: cannot write attribute ") + name + gdal_message());
}

// A coordinate variable of `dim` holding `values`.
std::shared_ptr<GDALMDArray> coordinate(GDALGroup& root, const std::shared_ptr<GDALDimension>& dim, const std::vector<double>& values) {
  auto var = root.CreateMDArray(dim->GetName(), {dim}, GDALExtendedDataType::Create(GDT_Float64));
  if (!var) throw TerrainError("netCDF: cannot create " + dim->GetName() + gdal_message());
  const GUInt64 start = 0;
  const size_t count = values.size();
  if (!var->Write(&start, &count, nullptr, nullptr, GDALExtendedDataType::Create(GDT_Float64), values.data()))
    throw TerrainError("netCDF: cannot write " + dim->GetName() + gdal_message());
  // (netCDF: a variable named as its dimension is that dimension's coordinate variable.)
  return var;
}

}  // namespace

void write_time_cube(const std::string& path, const Grid& g, const std::vector<double>& times_s, const std::vector<CubeField>& fields) {
  init_gdal();
  CPLErrorReset();
  if (times_s.empty()) throw TerrainError("writing '" + path + "': no frames");
  auto* drv = GetGDALDriverManager()->GetDriverByName("netCDF");
  if (!drv) throw TerrainError("writing '" + path + "': GDAL has no netCDF driver");
  const char* opts[] = {"FORMAT=NC4", "CONVENTIONS=CF-1.8", nullptr};
  const std::string part = path + ".part";  // moved into place once whole
  VSIUnlink(part.c_str());
  std::unique_ptr<GDALDataset> ds(drv->CreateMultiDimensional(part.c_str(), nullptr, const_cast<char**>(opts)));
  if (!ds) throw TerrainError("writing '" + path + "' failed" + gdal_message());
  auto root = ds->GetRootGroup();
  auto dim_t = root->CreateDimension("time", GDAL_DIM_TYPE_TEMPORAL, "", times_s.size());
  auto dim_y = root->CreateDimension("y", GDAL_DIM_TYPE_HORIZONTAL_Y, "NORTH", std::size_t(g.ny));
  auto dim_x = root->CreateDimension("x", GDAL_DIM_TYPE_HORIZONTAL_X, "EAST", std::size_t(g.nx));
  if (!dim_t || !dim_y || !dim_x) throw TerrainError("writing '" + path + "': cannot create the dimensions" + gdal_message());
  // Time counts from the release; CF wants a reference date, so the release is put at the epoch.
  auto t = coordinate(*root, dim_t, times_s);
  text_attribute(*t, "units", "seconds since 1970-01-01 00:00:00");
  text_attribute(*t, "calendar", "standard");
  text_attribute(*t, "standard_name", "time");
  text_attribute(*t, "long_name", "time since the release (the release at the epoch)");
  text_attribute(*t, "axis", "T");
  std::vector<double> xs(std::size_t(g.nx)), ys(std::size_t(g.ny));
  for (int i = 0; i < g.nx; ++i) xs[std::size_t(i)] = g.cx(i);
  for (int j = 0; j < g.ny; ++j) ys[std::size_t(j)] = g.cy(j);  // row 0 south: y ascending
  for (const auto& [dim, values, axis] : {std::tuple{dim_x, &xs, "x"}, std::tuple{dim_y, &ys, "y"}}) {
    auto c = coordinate(*root, dim, *values);
    text_attribute(*c, "standard_name", std::string("projection_") + axis + "_coordinate");
    text_attribute(*c, "units", "m");
    text_attribute(*c, "axis", axis == std::string("x") ? "X" : "Y");
  }
  OGRSpatialReference srs;
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  if (!g.crs_wkt.empty() && srs.importFromWkt(g.crs_wkt.c_str()) != OGRERR_NONE)
    throw TerrainError("writing '" + path + "': the grid's CRS cannot be read back");
  const float nodata = -9999.0f;
  for (const auto& f : fields) {
    // One chunk per frame: the library's default chunks span many frames, so that writing frame by
    // frame inflated and deflated each chunk again for every frame (minutes for 600 frames).
    const std::string block = "BLOCKSIZE=1," + std::to_string(g.ny) + "," + std::to_string(g.nx);
    const char* var_opts[] = {"COMPRESS=DEFLATE", "ZLEVEL=4", block.c_str(), nullptr};
    auto var = root->CreateMDArray(f.name, {dim_t, dim_y, dim_x}, GDALExtendedDataType::Create(GDT_Float32), const_cast<char**>(var_opts));
    if (!var) throw TerrainError("writing '" + path + "': cannot create " + f.name + gdal_message());
    if (!g.crs_wkt.empty()) var->SetSpatialRef(&srs);
    var->SetNoDataValue(double(nodata));
    var->SetUnit(f.unit);
    text_attribute(*var, "long_name", f.long_name);
    std::vector<float> frame(g.cells());
    for (std::size_t b = 0; b < times_s.size(); ++b) {
      const auto v = f.values(b);
      for (std::size_t k = 0; k < frame.size(); ++k)
        frame[k] = std::isfinite(v[k]) && (g.outside.empty() || !g.outside[k]) ? float(v[k]) : nodata;
      const GUInt64 start[3] = {b, 0, 0};
      const size_t count[3] = {1, std::size_t(g.ny), std::size_t(g.nx)};
      if (!var->Write(start, count, nullptr, nullptr, GDALExtendedDataType::Create(GDT_Float32), frame.data()))
        throw TerrainError("writing '" + path + "': frame " + std::to_string(b) + " of " + f.name + gdal_message());
    }
  }
  ds.reset();
  if (CPLGetLastErrorType() == CE_Failure || VSIRename(part.c_str(), path.c_str()) != 0) {
    VSIUnlink(part.c_str());
    throw TerrainError("writing '" + path + "' failed" + gdal_message());
  }
}

}  // namespace runout::terrain
