#pragma once
// Rasters in tests: a synthetic one-band Float64 GeoTIFF in local metres as a run's input, and a
// run's output raster read back.
#include <gdal_priv.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace runout::test_support {

/// A one-band Float64 GeoTIFF without a CRS (the scenario says "local"): nx x ny cells of size c,
/// the upper-left corner at (x0, y_top), `rows` from the north.
inline void write_local_raster(const std::string& path, int nx, int ny, double x0, double y_top, double c, const std::vector<double>& rows) {
  GDALAllRegister();
  GDALDatasetUniquePtr ds(GetGDALDriverManager()->GetDriverByName("GTiff")->Create(path.c_str(), nx, ny, 1, GDT_Float64, nullptr));
  ASSERT_TRUE(ds);
  double gt[6] = {x0, c, 0, y_top, 0, -c};
  ds->SetGeoTransform(gt);
  ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, nx, ny, const_cast<double*>(rows.data()), nx, ny, GDT_Float64, 0, 0), CE_None);
}

/// A raster's first band as doubles (rows from the north) with its size and geotransform; empty
/// values (and a failed expectation) when it cannot be read.
struct RasterBand {
  int nx = 0, ny = 0;
  double gt[6] = {0, 1, 0, 0, 0, -1};
  std::vector<double> values;
  double at(int row, int col) const { return values[std::size_t(row) * std::size_t(nx) + std::size_t(col)]; }
  double x_centre(int col) const { return gt[0] + (col + 0.5) * gt[1]; }
  double y_centre(int row) const { return gt[3] + (row + 0.5) * gt[5]; }
};

inline RasterBand read_raster_band(const std::string& path) {
  GDALAllRegister();
  RasterBand b;
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
  EXPECT_TRUE(ds) << path;
  if (!ds) return b;
  ds->GetGeoTransform(b.gt);
  b.nx = ds->GetRasterXSize();
  b.ny = ds->GetRasterYSize();
  b.values.resize(std::size_t(b.nx) * std::size_t(b.ny));
  EXPECT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, b.nx, b.ny, b.values.data(), b.nx, b.ny, GDT_Float64, 0, 0), CE_None) << path;
  return b;
}

}  // namespace runout::test_support
