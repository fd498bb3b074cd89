#pragma once
// Test support for the run-driver tests (tests/integration/test_*.cpp): synthetic DEMs and
// polygons made with GDAL, scenarios over them, and checks of a run's outputs.
#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "jobs/drivers/run.hpp"
#include "jobs/scenario/scenario.hpp"
#include "tests/support/run_record.hpp"
#include "tests/support/temp_dir.hpp"
#include "terrain/terrain.hpp"

namespace fs = std::filesystem;
using namespace runout;

namespace runout::test_support::run {

namespace fs = std::filesystem;
using namespace runout;
using test_support::read_text;
using test_support::TempDir;

using test_support::record_figure;
using test_support::run_record;
using test_support::station_at;
using test_support::as_vector;

// A DEM of nx x ny cells in `epsg` with its south-west corner at (x0, y0), the elevation z(i, r) of
// each cell's centre (column i, row r from the north); no data (-9999) where z returns NaN. An
// ".asc" path is written as an ESRI ASCII grid, any other as GeoTIFF.
template <class F>
void make_dem_box(const std::string& path, int nx, int ny, double cell, double x0, double y0, F z, const char* epsg = "EPSG:32632",
                  bool with_crs = true) {
  GDALAllRegister();
  auto* drv = GetGDALDriverManager()->GetDriverByName(path.size() > 4 && path.substr(path.size() - 4) == ".asc" ? "AAIGrid" : "GTiff");
  auto* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDatasetUniquePtr ds(mem->Create("", nx, ny, 1, GDT_Float32, nullptr));
  double gt[6] = {x0, cell, 0, y0 + ny * cell, 0, -cell};
  ds->SetGeoTransform(gt);
  if (with_crs) {
    OGRSpatialReference s;
    s.SetFromUserInput(epsg);
    ds->SetSpatialRef(&s);
  }
  std::vector<float> v(std::size_t(nx) * ny);
  for (int r = 0; r < ny; ++r)
    for (int i = 0; i < nx; ++i) {
      const double e = z(i, r);
      v[std::size_t(r) * nx + i] = std::isnan(e) ? -9999.0f : float(e);
    }
  ds->GetRasterBand(1)->SetNoDataValue(-9999.0);
  EXPECT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, nx, ny, v.data(), nx, ny, GDT_Float32, 0, 0), CE_None);
  GDALDatasetUniquePtr out(drv->CreateCopy(path.c_str(), ds.get(), FALSE, nullptr, nullptr, nullptr));
  ASSERT_TRUE(out);
}

// A DEM of n x n cells in `epsg` from x = 500000, y = 5200000 (south-west corner), the elevation
// z(x, y) of each cell's centre relative to that corner, row r from the north; no data (-9999) where
// z returns NaN.
template <class F>
void make_dem_of(const std::string& path, int n, double cell, F z, const char* epsg = "EPSG:32632", bool with_crs = true) {
  make_dem_box(path, n, n, cell, 500000, 5200000, z, epsg, with_crs);
}

// A DEM in UTM 32N (EPSG:32632): a slope of `deg` falling to the east, flattening into a valley.
inline void make_dem(const std::string& path, int n, double cell, double deg, const char* epsg = "EPSG:32632", bool with_crs = true,
              int hole_i0 = -1, int hole_i1 = -1) {
  make_dem_of(
      path, n, cell,
      [&](int i, int r) {
        if (i >= hole_i0 && i < hole_i1 && r >= n / 3 && r < 2 * n / 3) return double(NAN);
        return std::max(0.0, (0.6 * n * cell - i * cell)) * std::tan(deg * M_PI / 180) + 0.02 * r * cell;
      },
      epsg, with_crs);
}

// A GeoJSON file of lines; coordinates in `epsg`.
inline void make_lines(const std::string& path, const std::vector<std::vector<std::pair<double, double>>>& lines, const char* epsg,
                       const char* extra_props = "") {
  std::ofstream f(path);
  f << R"({"type":"FeatureCollection","crs":{"type":"name","properties":{"name":"urn:ogc:def:crs:EPSG::)" << (epsg + 5)
    << R"("}},"features":[)";
  for (std::size_t k = 0; k < lines.size(); ++k) {
    f << (k ? "," : "") << R"({"type":"Feature","properties":{"id":)" << k << extra_props << R"(},"geometry":{"type":"LineString","coordinates":[)";
    for (std::size_t v = 0; v < lines[k].size(); ++v) f << (v ? "," : "") << "[" << std::setprecision(12) << lines[k][v].first << "," << lines[k][v].second << "]";
    f << "]}}";
  }
  f << "]}";
}

// A GeoJSON polygon file; coordinates in `epsg` (axis order x/lon first).
inline void make_polygons(const std::string& path, const std::vector<std::vector<std::pair<double, double>>>& rings,
                   const char* epsg, const char* extra_props = "") {
  std::ofstream f(path);
  f << R"({"type":"FeatureCollection","crs":{"type":"name","properties":{"name":")"
    << (std::string(epsg) == "EPSG:4326" ? "urn:ogc:def:crs:OGC:1.3:CRS84" : std::string("urn:ogc:def:crs:EPSG::") + (epsg + 5))
    << R"("}},"features":[)";
  for (std::size_t k = 0; k < rings.size(); ++k) {
    f << (k ? "," : "") << R"({"type":"Feature","properties":{"id":)" << k << extra_props << R"(},"geometry":{"type":"Polygon","coordinates":[[)";
    for (std::size_t v = 0; v < rings[k].size(); ++v) f << (v ? "," : "") << "[" << std::setprecision(12) << rings[k][v].first << "," << rings[k][v].second << "]";
    f << "]]}}";
  }
  f << "]}";
}
// A grid of n x n cells of `cell` m from (500000, 5200000), flat at elevation z, in UTM 32N.
inline terrain::Grid flat_grid(int n, double cell, double z = 0) {
  terrain::Grid g;
  g.nx = g.ny = n;
  g.dx = cell;
  g.x_min = 500000;
  g.y_min = 5200000;
  OGRSpatialReference s;
  s.importFromEPSG(32632);
  char* w = nullptr;
  s.exportToWkt(&w);
  g.crs_wkt = w;
  CPLFree(w);
  g.crs_name = "EPSG:32632";
  g.z.assign(g.cells(), z);
  return g;
}

inline std::vector<std::pair<double, double>> square(double x0, double y0, double a) {
  return {{x0, y0}, {x0 + a, y0}, {x0 + a, y0 + a}, {x0, y0 + a}, {x0, y0}};
}

// mu(I) for glass beads in a scenario's material (a flow-dependent friction law).
inline void set_mu_i(v1::Material* m) {
  m->set_rheology("mu_i");
  m->set_mu_s(0.38);
  m->set_mu_2(0.64);
  m->set_mu_i0(0.28);
  m->set_grain_diameter_m(0.0005);
  m->set_grain_density_kg_m3(2450);
}

inline v1::Scenario base_scenario(const std::string& dem, const std::string& release, double res = 20) {
  v1::Scenario s;
  s.mutable_dem()->set_path(dem);
  s.mutable_grid()->set_resolution_m(res);
  auto* r = s.add_releases();
  r->set_path(release);
  r->set_thickness_m(2.0);
  s.mutable_material()->set_bed_friction_deg(20);
  s.mutable_numerics()->set_end_time_s(400);
  return s;
}
inline void expect_error(const v1::Scenario& s, const TempDir& d, const std::string& needle) {
  try {
    auto r = jobs::resolve_scenario(s, d.p.string());
    fs::create_directories(d.p / "err");
    jobs::run_scenario(r, (d.p / "err").string());
    ADD_FAILURE() << "no error, expected one containing: " << needle;
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

// Resolving `s` fails with a ScenarioError whose message holds every one of `needles`.
inline void expect_resolve_error(const v1::Scenario& s, std::initializer_list<std::string> needles) {
  try {
    jobs::resolve_scenario(s, ".");
    ADD_FAILURE() << "no error, expected one naming " << *needles.begin();
  } catch (const jobs::ScenarioError& e) {
    for (const auto& n : needles) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
  }
}

// What every bundled scenario's output directory must hold: the rasters as Float32 COGs on the
// computation grid with its CRS and nodata, and a valid runout outline whose area is the affected area.
inline void check_outputs(const TempDir& d, const jobs::RunSummary& sum, const std::string& crs_name) {
  for (const char* f : {"max_depth.tif", "max_speed.tif", "max_pressure.tif", "deposit.tif", "arrival_time.tif"}) {
    GDALDatasetUniquePtr t(GDALDataset::Open((d / f).c_str(), GDAL_OF_RASTER));
    ASSERT_TRUE(t) << f;
    EXPECT_EQ(t->GetRasterXSize(), sum.nx) << f;
    EXPECT_EQ(t->GetRasterYSize(), sum.ny) << f;
    double gt[6];
    t->GetGeoTransform(gt);
    EXPECT_NEAR(gt[1], sum.dx, 1e-9 * sum.dx) << f;
    EXPECT_NEAR(gt[5], -sum.dx, 1e-9 * sum.dx) << f;
    EXPECT_EQ(t->GetRasterBand(1)->GetRasterDataType(), GDT_Float32) << f;
    int has = 0;
    EXPECT_EQ(t->GetRasterBand(1)->GetNoDataValue(&has), -9999.0) << f;
    EXPECT_TRUE(has) << f;
    ASSERT_TRUE(t->GetSpatialRef()) << f;
    if (crs_name == "local metres")  // GeoTIFF keeps a local frame as an unnamed engineering CRS in metres
      EXPECT_TRUE(t->GetSpatialRef()->IsLocal()) << f;
    else
      EXPECT_EQ(std::string(t->GetSpatialRef()->GetName()), crs_name) << f;
    EXPECT_STREQ(t->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE"), "COG") << f;
  }
  GDALDatasetUniquePtr ol(GDALDataset::Open((d / "outline.gpkg").c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(ol);
  double area = 0;
  int n = 0;
  for (auto& f : ol->GetLayer(0)) {
    ASSERT_TRUE(f->GetGeometryRef()->IsValid());
    EXPECT_EQ(wkbFlatten(f->GetGeometryRef()->getGeometryType()), wkbPolygon);
    area += OGR_G_Area(OGRGeometry::ToHandle(f->GetGeometryRef()));
    ++n;
  }
  EXPECT_GE(n, 1);
  EXPECT_NEAR(area, sum.affected_area_m2, 1e-6 * area);
  EXPECT_TRUE(fs::exists(d / "run.json"));
  EXPECT_TRUE(fs::exists(d / "map_max_depth.png"));
  EXPECT_TRUE(fs::exists(d / "map_max_depth.pdf"));
}

// The first lines of an ESRI ASCII grid as key -> value.
// A raster's first band as numbers (row 0 north, GDAL's order; no data as NaN) with the centre of
// each cell: cx(i), cy(r) in the raster's CRS.
struct RasterValues {
  int w = 0, h = 0;
  double gt[6] = {0, 1, 0, 0, 0, -1};
  std::vector<double> v;
  double cx(int i) const { return gt[0] + (i + 0.5) * gt[1]; }
  double cy(int r) const { return gt[3] + (r + 0.5) * gt[5]; }
  /// The largest finite value over the cells whose centres `keep(x, y)` accepts (0 where none).
  template <class Keep>
  double max_where(Keep keep) const {
    double m = 0;
    for (int r = 0; r < h; ++r)
      for (int i = 0; i < w; ++i) {
        const double z = v[std::size_t(r) * w + i];
        if (std::isfinite(z) && keep(cx(i), cy(r))) m = std::max(m, z);
      }
    return m;
  }
};
inline RasterValues read_raster_values(const std::string& path) {
  RasterValues r;
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
  EXPECT_TRUE(ds) << path;
  if (!ds) return r;
  ds->GetGeoTransform(r.gt);
  r.w = ds->GetRasterXSize();
  r.h = ds->GetRasterYSize();
  r.v.resize(std::size_t(r.w) * r.h);
  EXPECT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, r.w, r.h, r.v.data(), r.w, r.h, GDT_Float64, 0, 0), CE_None);
  int has = 0;
  const double nodata = ds->GetRasterBand(1)->GetNoDataValue(&has);
  for (double& x : r.v)
    if (has && x == nodata) x = NAN;
  return r;
}

inline std::map<std::string, double> ascii_header(const std::string& path) {
  std::ifstream in(path);
  std::map<std::string, double> h;
  std::string k;
  double v;
  for (int i = 0; i < 6 && (in >> k >> v); ++i) {
    for (auto& c : k) c = char(std::tolower(static_cast<unsigned char>(c)));
    h[k] = v;
  }
  return h;
}

// An ISeeSnow export: both peak fields with the benchmark's names on the DEM's grid, the
// configuration file and the result-table row.
inline void check_iseesnow(const TempDir& d, const std::string& release, const std::string& id, const std::string& dem,
                    double volume) {
  const std::string stem = release + "_" + id + "_null_runout";
  GDALDatasetUniquePtr z(GDALDataset::Open(dem.c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(z);
  double gz[6];
  z->GetGeoTransform(gz);
  for (const char* suffix : {"_pft.asc", "_pfv.asc"}) {
    const auto h = ascii_header(d / (stem + suffix));
    ASSERT_EQ(h.size(), 6u) << stem << suffix;
    EXPECT_EQ(h.at("ncols"), z->GetRasterXSize());
    EXPECT_EQ(h.at("nrows"), z->GetRasterYSize());
    EXPECT_NEAR(h.at("cellsize"), gz[1], 1e-9);
    EXPECT_NEAR(h.at("xllcorner"), gz[0], 1e-6);
    EXPECT_NEAR(h.at("yllcorner"), gz[3] + gz[5] * z->GetRasterYSize(), 1e-6);
    EXPECT_EQ(h.at("nodata_value"), -9999.0);
    // No NaN anywhere, and a flow somewhere.
    std::ifstream in(d / (stem + suffix));
    std::string line;
    for (int i = 0; i < 6; ++i) std::getline(in, line);
    double mx = 0, v;
    std::size_t count = 0;
    while (in >> v) {
      EXPECT_TRUE(std::isfinite(v));
      mx = std::max(mx, v);
      ++count;
    }
    EXPECT_EQ(count, std::size_t(z->GetRasterXSize()) * z->GetRasterYSize());
    EXPECT_GT(mx, 0.5) << stem << suffix;
  }
  EXPECT_TRUE(fs::exists(d / (stem + ".txt")));
  std::ifstream csv(d / ("iseesnow_" + id + ".csv"));
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_EQ(header.rfind(",testCase,computation duration (CPU) [s],", 0), 0u) << header;
  std::stringstream rs(row);
  std::vector<std::string> cells;
  for (std::string c; std::getline(rs, c, ',');) cells.push_back(c);
  ASSERT_GE(cells.size(), 6u) << row;
  EXPECT_EQ(cells[0], std::to_string(std::stoi(id.substr(0, 2))));  // "03CoulombOnly": row 3,
  EXPECT_EQ(cells[1], id.substr(2));                                 // test case CoulombOnly
  EXPECT_NEAR(std::stod(cells[4]), volume, 1e-6 * volume);  // volume at t0
  EXPECT_NEAR(std::stod(cells[5]), volume, 1e-6 * volume);  // closed: nothing left the grid
}

// B2 at 0 deg (scenarios/lab/b2-collapse-0deg.json) on 1 cm cells (50 x 15 instead of the file's
// 2.5 mm) to end_time: the coarse VOF run that several tests start from.
inline jobs::ResolvedScenario coarse_b2(double end_time) {
  auto r = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/lab/b2-collapse-0deg.json");
  auto* lab = r.scenario.mutable_lab();
  lab->set_nx(50);
  lab->set_ny(15);
  lab->set_end_time_s(end_time);
  return r;
}


}  // namespace runout::test_support::run
