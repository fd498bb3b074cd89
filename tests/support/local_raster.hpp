#pragma once
// Synthetic inputs for runs on a DEM in tests: a one-band Float64 GeoTIFF in local metres.
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

}  // namespace runout::test_support
