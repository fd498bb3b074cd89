// Terrain: the terrain pipeline (DEM preparation, reprojection, releases, the area of interest) and
// the depth-averaged run driver on synthetic inputs made here with GDAL.
#include <tuple>

#include "jobs/drivers/hazard_maps.hpp"
#include "jobs/drivers/hazard_outputs.hpp"
#include "tests/support/run_helpers.hpp"

using namespace runout::test_support::run;

TEST(Terrain, SyntheticSlopeRunsAndWritesEveryOutput) {
  TempDir d;
  make_dem(d / "dem.tif", 120, 20.0, 30);
  make_polygons(d / "rel.geojson", {square(500200, 5201000, 300)}, "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson");
  sc.mutable_outputs()->set_timeseries_interval_s(10);
  auto r = jobs::resolve_scenario(sc, d.p.string());
  fs::create_directories(d / "out");
  const auto sum = jobs::run_scenario(r, d / "out");
  EXPECT_EQ(sum.crs, "EPSG:32632");
  EXPECT_NEAR(sum.release_area_m2, 300.0 * 300.0, 4 * 20 * 300.0);
  EXPECT_LT(sum.volume_error, 1e-12);
  EXPECT_GT(sum.runout_m, 500.0);
  for (const char* f : {"max_depth.tif", "max_speed.tif", "max_pressure.tif", "deposit.tif", "arrival_time.tif",
                        "outline.geojson", "outline.gpkg", "run.json", "timeseries.h5", "timeseries.xmf", "pressure_zones.tif", "pressure_zones.gpkg",
                        "pressure_zones.qml", "max_depth.qml"})
    EXPECT_TRUE(fs::exists(fs::path(d / "out") / f)) << f;
  for (const char* q : {"max_depth", "max_speed", "max_pressure", "pressure_zones", "deposit", "arrival_time"}) {
    GDALDatasetUniquePtr png(GDALDataset::Open((fs::path(d / "out") / (std::string("map_") + q + ".png")).c_str(), GDAL_OF_RASTER));
    ASSERT_TRUE(png) << q;
    EXPECT_GE(png->GetRasterCount(), 3);
    EXPECT_GE(png->GetRasterXSize(), 120 * 7);  // the grid (2400 m / 20 m) at 7.5 pixels per cell, plus the legend
    EXPECT_TRUE(fs::exists(fs::path(d / "out") / (std::string("map_") + q + ".pdf"))) << q;
  }
  GDALDatasetUniquePtr md(GDALDataset::Open((d / "out/max_depth.tif").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(md);
  EXPECT_EQ(md->GetRasterBand(1)->GetRasterDataType(), GDT_Float32);
  int has = 0;
  EXPECT_EQ(md->GetRasterBand(1)->GetNoDataValue(&has), -9999.0);
  EXPECT_TRUE(has);
  EXPECT_STREQ(md->GetSpatialRef()->GetAuthorityCode(nullptr), "32632");
  EXPECT_STREQ(md->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE"), "COG");
  // The outline is a valid polygon in WGS84 whose area matches the affected area.
  GDALDatasetUniquePtr ol(GDALDataset::Open((d / "out/outline.geojson").c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(ol);
  double area = 0;
  for (auto& f : ol->GetLayer(0)) {
    ASSERT_TRUE(f->GetGeometryRef()->IsValid());
    area += f->GetFieldAsDouble("area_m2");
    OGREnvelope e;
    f->GetGeometryRef()->getEnvelope(&e);
    EXPECT_GT(e.MinX, 8.9);  // lon/lat around 9 E, 47 N
    EXPECT_LT(e.MaxX, 9.2);
    EXPECT_GT(e.MinY, 46.8);
  }
  EXPECT_NEAR(area, sum.affected_area_m2, 1e-6 * area);
  const auto rec = run_record(d / "out/run.json");
  ASSERT_GT(rec.inputs_size(), 0);
  EXPECT_EQ(rec.inputs(0).sha256().size(), 64u);
  EXPECT_TRUE(rec.has_mass_balance());
  // One XDMF frame per 10 s of simulated time, plus the first and the last; HDF5 readable by GDAL.
  std::ifstream xmf(d / "out/timeseries.xmf");
  std::stringstream xs;
  xs << xmf.rdbuf();
  int frames = 0;
  for (std::size_t p = xs.str().find("<Time "); p != std::string::npos; p = xs.str().find("<Time ", p + 1)) ++frames;
  EXPECT_GE(frames, int(sum.t / 10) + 1);
  EXPECT_LE(frames, int(sum.t / 10) + 2);
  GDALDatasetUniquePtr f0(GDALDataset::Open(("HDF5:\"" + d / "out/timeseries.h5" + "\"://frames/00000/depth").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(f0);
  EXPECT_EQ(f0->GetRasterXSize(), 120);  // 2400 m of DEM at 20 m
  // ParaView: the frames on the terrain surface, x, y, z in the grid's CRS.
  EXPECT_NE(xs.str().find("TopologyType=\"2DSMesh\""), std::string::npos);
  EXPECT_NE(xs.str().find("timeseries.h5:/surface"), std::string::npos);
  // QGIS and GDAL: multi-band GeoTIFFs on the rasters' grid, one band per frame with its time; the
  // last depth band is the deposit; speeds only where the depth exceeds the flow threshold.
  EXPECT_TRUE(fs::exists(d / "out/timeseries_depth.qml"));
  EXPECT_TRUE(fs::exists(d / "out/timeseries_speed.qml"));
  GDALDatasetUniquePtr td(GDALDataset::Open((d / "out/timeseries_depth.tif").c_str(), GDAL_OF_RASTER));
  GDALDatasetUniquePtr tv(GDALDataset::Open((d / "out/timeseries_speed.tif").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(td && tv);
  EXPECT_EQ(td->GetRasterCount(), frames);
  EXPECT_EQ(tv->GetRasterCount(), frames);
  double gt_ts[6], gt_md[6];
  ASSERT_EQ(td->GetGeoTransform(gt_ts), CE_None);
  md->GetGeoTransform(gt_md);
  for (int q = 0; q < 6; ++q) EXPECT_EQ(gt_ts[q], gt_md[q]) << q;
  ASSERT_TRUE(td->GetSpatialRef());
  EXPECT_STREQ(td->GetSpatialRef()->GetAuthorityCode(nullptr), "32632");
  EXPECT_STREQ(td->GetRasterBand(1)->GetMetadataItem("TIME_S"), "0");
  EXPECT_STREQ(td->GetRasterBand(1)->GetUnitType(), "m");
  EXPECT_NEAR(std::atof(td->GetRasterBand(frames)->GetMetadataItem("TIME_S")), sum.t, 1e-6 * sum.t);
  const int n = td->GetRasterXSize() * td->GetRasterYSize();
  std::vector<float> last(n), deposit(n), depth(n), speed(n);
  ASSERT_EQ(td->GetRasterBand(frames)->RasterIO(GF_Read, 0, 0, 120, 120, last.data(), 120, 120, GDT_Float32, 0, 0), CE_None);
  GDALDatasetUniquePtr dep(GDALDataset::Open((d / "out/deposit.tif").c_str(), GDAL_OF_RASTER));
  ASSERT_EQ(dep->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 120, 120, deposit.data(), 120, 120, GDT_Float32, 0, 0), CE_None);
  EXPECT_EQ(last, deposit);
  ASSERT_EQ(td->GetRasterBand(frames / 2)->RasterIO(GF_Read, 0, 0, 120, 120, depth.data(), 120, 120, GDT_Float32, 0, 0), CE_None);
  ASSERT_EQ(tv->GetRasterBand(frames / 2)->RasterIO(GF_Read, 0, 0, 120, 120, speed.data(), 120, 120, GDT_Float32, 0, 0), CE_None);
  int flowing = 0;
  for (int k = 0; k < n; ++k) {
    if (std::fabs(depth[k] - 0.01f) < 1e-6f) continue;  // at the threshold Float32 rounding decides
    EXPECT_EQ(speed[k] == -9999.0f, !(depth[k] > 0.01f)) << k << ": depth " << depth[k] << ", speed " << speed[k];
    flowing += depth[k] > 0.01f;
  }
  EXPECT_GT(flowing, 10);
  // Both are Cloud Optimized GeoTIFFs.
  EXPECT_STREQ(td->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE"), "COG");
  EXPECT_STREQ(tv->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE"), "COG");
  EXPECT_FALSE(fs::exists(d / "out/timeseries_depth.tif.part.tif"));
  // The same frames in one CF NetCDF file: a time axis of the frames' times (seconds since the
  // release, put at the epoch), y ascending, depth and speed as in the GeoTIFFs' bands.
  GDALDatasetUniquePtr nc(GDALDataset::Open((d / "out/timeseries.nc").c_str(), GDAL_OF_MULTIDIM_RASTER));
  ASSERT_TRUE(nc);
  auto root = nc->GetRootGroup();
  auto time = root->OpenMDArray("time");
  ASSERT_TRUE(time);
  ASSERT_EQ(time->GetDimensionCount(), 1u);
  EXPECT_EQ(time->GetDimensions()[0]->GetSize(), std::uint64_t(frames));
  EXPECT_EQ(time->GetAttribute("units")->ReadAsString(), std::string("seconds since 1970-01-01 00:00:00"));
  std::vector<double> times(std::size_t(frames), 0);
  const GUInt64 t0 = 0;
  const size_t tn = std::size_t(frames);
  ASSERT_TRUE(time->Read(&t0, &tn, nullptr, nullptr, GDALExtendedDataType::Create(GDT_Float64), times.data()));
  EXPECT_EQ(times.front(), 0.0);
  EXPECT_NEAR(times.back(), sum.t, 1e-9 * sum.t);
  auto ncd = root->OpenMDArray("depth");
  ASSERT_TRUE(ncd);
  ASSERT_EQ(ncd->GetDimensionCount(), 3u);
  EXPECT_EQ(ncd->GetUnit(), "m");
  // One chunk per frame: chunks across frames are inflated and deflated again for each frame written.
  EXPECT_EQ(ncd->GetBlockSize(), (std::vector<GUInt64>{1, 120, 120}));
  std::vector<float> cube_frame(static_cast<std::size_t>(n));
  const GUInt64 start[3] = {GUInt64(frames / 2 - 1), 0, 0};
  const size_t count[3] = {1, 120, 120};
  ASSERT_TRUE(ncd->Read(start, count, nullptr, nullptr, GDALExtendedDataType::Create(GDT_Float32), cube_frame.data()));
  for (int r = 0; r < 120; ++r)  // the NetCDF's row r is the GeoTIFF's row 119 - r (y ascending)
    for (int i = 0; i < 120; ++i) ASSERT_EQ(cube_frame[std::size_t(r) * 120 + i], depth[std::size_t(119 - r) * 120 + i]) << r << ", " << i;
  // The vector outputs carry their QGIS style: the GeoPackage's default in layer_styles, and a .qml
  // of their own (not the raster's pressure_zones.qml).
  for (const auto& [file, layer, renderer] : {std::tuple<std::string, std::string, std::string>{"outline", "runout_outline", "singleSymbol"},
                                              {"pressure_zones", "pressure_zones", "categorizedSymbol"}}) {
    GDALDatasetUniquePtr g(GDALDataset::Open((d / ("out/" + file + ".gpkg")).c_str(), GDAL_OF_VECTOR));
    ASSERT_TRUE(g) << file;
    OGRLayer* styles = g->GetLayerByName("layer_styles");
    ASSERT_TRUE(styles) << file;
    int rows = 0;
    for (auto& f : styles) {
      ++rows;
      EXPECT_STREQ(f->GetFieldAsString("f_table_name"), layer.c_str());
      EXPECT_EQ(f->GetFieldAsInteger("useAsDefault"), 1);
      EXPECT_NE(std::string(f->GetFieldAsString("styleQML")).find("type=\"" + renderer + "\""), std::string::npos) << file;
    }
    EXPECT_EQ(rows, 1) << file;
  }
  EXPECT_TRUE(fs::exists(d / "out/outline.qml"));
  std::ifstream zq(d / "out/pressure_zones_polygons.qml");
  std::stringstream zs;
  zs << zq.rdbuf();
  EXPECT_NE(zs.str().find("categorizedSymbol"), std::string::npos);
}

TEST(Terrain, ReleaseInWgs84AndInUtmGiveTheSameGrid) {
  TempDir d;
  make_dem(d / "dem.tif", 80, 25.0, 30);
  const std::vector<std::pair<double, double>> utm = {{500300, 5200500}, {500700, 5200520}, {500650, 5200900}, {500280, 5200850}, {500300, 5200500}};
  OGRSpatialReference u, ll;
  u.importFromEPSG(32632);
  ll.importFromEPSG(4326);
  u.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  ll.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> ct(OGRCreateCoordinateTransformation(&u, &ll));
  auto geo = utm;
  for (auto& p : geo) ct->Transform(1, &p.first, &p.second);
  make_polygons(d / "utm.geojson", {utm}, "EPSG:32632");
  make_polygons(d / "ll.geojson", {geo}, "EPSG:4326");
  terrain::DemRequest rq;
  rq.dem_path = d / "dem.tif";
  rq.resolution = 10;
  const auto g = terrain::prepare_grid(rq);
  terrain::ReleaseRequest a, b;
  a.path = d / "utm.geojson";
  b.path = d / "ll.geojson";
  a.has_thickness = b.has_thickness = true;
  a.thickness = b.thickness = 1.5;
  const auto ha = terrain::rasterize_releases(g, rq, {a}), hb = terrain::rasterize_releases(g, rq, {b});
  for (std::size_t k = 0; k < ha.size(); ++k) EXPECT_NEAR(ha[k], hb[k], 1e-6) << k;  // the polygon's corners through PROJ and back
  long cells = 0;
  for (double v : ha) cells += v > 0;
  EXPECT_GT(cells, 1000);
}

TEST(Terrain, SlopeWindowAndVerticalThickness) {
  TempDir d;
  make_dem(d / "dem.tif", 100, 20.0, 35);
  // Half on the 35 degree slope, half on the flat valley floor (x > 0.6 * 2000 m).
  make_polygons(d / "rel.geojson", {square(501000, 5200800, 400)}, "EPSG:32632");
  terrain::DemRequest rq;
  rq.dem_path = d / "dem.tif";
  rq.resolution = 20;
  const auto g = terrain::prepare_grid(rq);
  const auto slope = terrain::slope_deg(g);
  terrain::ReleaseRequest r;
  r.path = d / "rel.geojson";
  r.has_thickness = true;
  r.thickness = 2.0;
  r.vertical = true;
  r.has_min_slope = true;
  r.min_slope = 28;
  r.has_max_slope = true;
  r.max_slope = 50;
  terrain::ReleaseReport rep;
  const auto h = terrain::rasterize_releases(g, rq, {r}, &rep);
  // The window is decided on the DEM's surface at 20 / 8 m: the cells on the slope release all of
  // themselves; the column the foot of the slope (x = 501200 m) crosses, flatter on the grid, only
  // its part that is steep on the fine surface.
  long kept = 0, partial = 0;
  for (std::size_t k = 0; k < h.size(); ++k)
    if (h[k] > 0) {
      ++kept;
      if (slope[k] >= 28.0) {
        EXPECT_NEAR(h[k], 2.0 * std::cos(slope[k] * M_PI / 180), 1e-12);
      } else {
        ++partial;
        EXPECT_LT(h[k], 2.0 * std::cos(slope[k] * M_PI / 180));
      }
    }
  EXPECT_GT(kept, 50);
  EXPECT_LT(kept, 400 / 20 * 400 / 20);
  EXPECT_LE(partial, 400 / 20);  // one column
  EXPECT_EQ(rep.cells, kept);
  // Vertical thickness: the volume is the plan area released x 2 m; the area the polygon's part
  // west of the slope's foot, to within a grid column.
  EXPECT_NEAR(rep.volume_m3, 2.0 * rep.area_m2, 1e-9 * rep.volume_m3);
  EXPECT_NEAR(rep.area_m2, 200.0 * 400, 20.0 * 400);
  std::printf("slope window on the fine surface: %ld cells (%ld partial), %.0f m2, %.0f m3\n", kept, partial, rep.area_m2, rep.volume_m3);
}

// A one-band Float32 GeoTIFF in `epsg`: nx x ny cells of `cell` (its CRS's units) from (x0, y0) at
// the south-west corner, value v(x, y) at the cells' centres.
void make_raster(const std::string& path, const char* epsg, double x0, double y0, double cell, int nx, int ny,
                 const std::function<double(double, double)>& v) {
  GDALAllRegister();
  auto* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDatasetUniquePtr ds(mem->Create("", nx, ny, 1, GDT_Float32, nullptr));
  double gt[6] = {x0, cell, 0, y0 + ny * cell, 0, -cell};
  ds->SetGeoTransform(gt);
  OGRSpatialReference s;
  s.SetFromUserInput(epsg);
  ds->SetSpatialRef(&s);
  std::vector<float> z(std::size_t(nx) * std::size_t(ny));
  for (int r = 0; r < ny; ++r)
    for (int i = 0; i < nx; ++i) z[std::size_t(r) * std::size_t(nx) + std::size_t(i)] = float(v(x0 + (i + 0.5) * cell, y0 + (ny - r - 0.5) * cell));
  ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, nx, ny, z.data(), nx, ny, GDT_Float32, 0, 0), CE_None);
  GDALDatasetUniquePtr out(GetGDALDriverManager()->GetDriverByName("GTiff")->CreateCopy(path.c_str(), ds.get(), FALSE, nullptr, nullptr, nullptr));
  ASSERT_TRUE(out);
}

// A thickness raster at twice the grid's resolution, linear across the slope's fall line: the grid's
// cells take its value at their centres (bilinear resampling of a linear field), only where the
// raster lies, and the volume is the sum over them.
TEST(Terrain, ReleaseThicknessFromARasterIsResampledOntoTheGrid) {
  TempDir d;
  make_dem(d / "dem.tif", 100, 20.0, 30);
  auto t_at = [](double x, double) { return 1.0 + (x - 500200) / 400; };
  make_raster(d / "t.tif", "EPSG:32632", 500200, 5200600, 10, 40, 40, t_at);
  terrain::DemRequest rq;
  rq.dem_path = d / "dem.tif";
  rq.resolution = 20;
  const auto g = terrain::prepare_grid(rq);
  terrain::ReleaseRequest r;
  r.thickness_raster = d / "t.tif";
  terrain::ReleaseReport rep;
  const auto h = terrain::rasterize_releases(g, rq, {r}, &rep);
  const auto slope = terrain::slope_deg(g);
  long cells = 0;
  double volume = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const std::size_t k = std::size_t(j) * std::size_t(g.nx) + std::size_t(i);
      const bool in = g.cx(i) > 500200 && g.cx(i) < 500600 && g.cy(j) > 5200600 && g.cy(j) < 5201000;
      if (!in) {
        EXPECT_EQ(h[k], 0.0) << i << " " << j;
        continue;
      }
      ++cells;
      volume += h[k] * g.dx * g.dx / std::cos(slope[k] * M_PI / 180);
      const bool edge = g.cx(i) < 500220 || g.cx(i) > 500580 || g.cy(j) < 5200620 || g.cy(j) > 5200980;
      if (!edge) EXPECT_NEAR(h[k], t_at(g.cx(i), g.cy(j)), 1e-6) << i << " " << j;
      EXPECT_GE(h[k], 1.0);
      EXPECT_LE(h[k], 2.0);
    }
  EXPECT_EQ(cells, 20 * 20);
  EXPECT_EQ(rep.cells, cells);
  EXPECT_EQ(rep.polygons, 0);
  EXPECT_NEAR(rep.volume_m3, volume, 1e-9 * volume);
}

// A thickness raster in WGS84 of 2 m everywhere, cut by a polygon in UTM: the same release as the
// polygon with thickness_m 2.
TEST(Terrain, ReleaseThicknessRasterInsideAPolygonEqualsThePolygonsThickness) {
  TempDir d;
  make_dem(d / "dem.tif", 80, 25.0, 30);
  make_raster(d / "t_ll.tif", "EPSG:4326", 8.99, 46.94, 0.0005, 60, 60, [](double, double) { return 2.0; });
  make_polygons(d / "rel.geojson", {square(500300, 5200500, 300)}, "EPSG:32632");
  terrain::DemRequest rq;
  rq.dem_path = d / "dem.tif";
  rq.resolution = 25;
  const auto g = terrain::prepare_grid(rq);
  terrain::ReleaseRequest a, b;
  a.path = b.path = d / "rel.geojson";
  a.has_thickness = true;
  a.thickness = 2;
  b.thickness_raster = d / "t_ll.tif";
  terrain::ReleaseReport ra, rb;
  const auto ha = terrain::rasterize_releases(g, rq, {a}, &ra), hb = terrain::rasterize_releases(g, rq, {b}, &rb);
  ASSERT_GT(ra.cells, 100);
  EXPECT_EQ(rb.cells, ra.cells);
  for (std::size_t k = 0; k < ha.size(); ++k) EXPECT_NEAR(hb[k], ha[k], 1e-6) << k;
  EXPECT_NEAR(rb.volume_m3, ra.volume_m3, 1e-6 * ra.volume_m3);
}

// The volume the engines hold for a release h (normal depth): the depth-averaged engine's
// vertical thickness H = h / cos(slope) on the grid's cells, the one the 3D driver fills too.
double engine_volume(const terrain::Grid& g, const std::vector<double>& h) {
  const auto H = engine::state_from_normal_depth(jobs::engine_terrain(g), h).H;
  double v = 0;
  for (double x : H) v += x * g.dx * g.dx;
  return v;
}

// A plane of 30 deg (a DEM of 20 m cells) and a polygon whose edges cut the cells at every grid:
// the release carries the polygon's area x thickness / cos(30 deg) (normal thickness) or area x
// thickness (vertical), to round-off, at grids coarser and finer than the DEM and off its cells;
// the engines hold what the report states. A slope window the plane is outside of is refused.
TEST(Terrain, ReleaseFilledByCellFractionCarriesThePolygonsVolume) {
  TempDir d;
  const double tan30 = std::tan(30 * M_PI / 180);
  make_raster(d / "plane.tif", "EPSG:32632", 500000, 5200000, 20, 100, 100, [&](double x, double) { return 2000 - (x - 500000) * tan30; });
  const std::vector<std::pair<double, double>> ring = {{500613.7, 5200587.1}, {501262.3, 5200701.9}, {501188.8, 5201333.3},
                                                       {500877.1, 5201102.6}, {500590.4, 5201290.2}, {500613.7, 5200587.1}};
  make_polygons(d / "rel.geojson", {ring}, "EPSG:32632");
  OGRLinearRing lr;
  for (const auto& [x, y] : ring) lr.addPoint(x, y);
  OGRPolygon poly;
  poly.addRing(&lr);
  const double area = poly.get_Area();
  ASSERT_GT(area, 2.5e5);
  for (const double res : {7.0, 20.0, 33.0, 90.0}) {
    terrain::DemRequest rq;
    rq.dem_path = d / "plane.tif";
    rq.resolution = res;
    const auto g = terrain::prepare_grid(rq);
    terrain::ReleaseRequest r;
    r.path = d / "rel.geojson";
    r.has_thickness = true;
    r.thickness = 1.5;
    r.has_min_slope = r.has_max_slope = true;
    r.min_slope = 28;
    r.max_slope = 50;
    terrain::ReleaseReport rep;
    const auto h = terrain::rasterize_releases(g, rq, {r}, &rep);
    EXPECT_NEAR(rep.volume_m3, area * 1.5 / std::cos(30 * M_PI / 180), 1e-5 * rep.volume_m3) << res << " m";
    EXPECT_NEAR(rep.area_m2, area, 1e-6 * area) << res << " m";
    EXPECT_NEAR(engine_volume(g, h), rep.volume_m3, 1e-12 * rep.volume_m3) << res << " m";
    // No cell deeper than the thickness over the whole cell (the grid's own slope converts it).
    const auto sl = terrain::slope_deg(g);
    for (std::size_t k = 0; k < h.size(); ++k)
      EXPECT_LE(h[k], 1.5 * std::cos(sl[k] * M_PI / 180) / std::cos(30 * M_PI / 180) * (1 + 1e-5)) << res << " m, cell " << k;
    r.vertical = true;
    const auto hv = terrain::rasterize_releases(g, rq, {r}, &rep);
    EXPECT_NEAR(rep.volume_m3, area * 1.5, 1e-5 * rep.volume_m3) << res << " m";
    EXPECT_NEAR(engine_volume(g, hv), rep.volume_m3, 1e-12 * rep.volume_m3) << res << " m";
    r.min_slope = 35;
    try {
      terrain::rasterize_releases(g, rq, {r});
      ADD_FAILURE() << res << " m";
    } catch (const terrain::TerrainError& e) {
      EXPECT_NE(std::string(e.what()).find("release polygon 1 of '" + (d / "rel.geojson") +
                                           "': no cell has a slope within [35.0, 50.0] deg (slopes inside: 30.0 to 30.0 deg)"),
                std::string::npos)
          << e.what();
    }
  }
}

// The bundled In den Arelen release (an SRTM DEM of about 76 m, the 28-50 deg window from the
// polygon's attributes, 1.5 m normal to the slope) releases the same volume at 10, 30, 60 and 90 m:
// within 2 %; the engines hold what the report states.
TEST(Terrain, InDenArelenReleasesTheSameVolumeOnEveryGrid) {
  auto s = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/scenarios/in-den-arelen.json");
  std::vector<double> volumes;
  for (const double res : {10.0, 30.0, 60.0, 90.0}) {
    s.dem.resolution = res;
    const auto g = terrain::prepare_grid(s.dem);
    terrain::ReleaseReport rep;
    const auto h = terrain::rasterize_releases(g, s.dem, s.releases, &rep);
    EXPECT_NEAR(engine_volume(g, h), rep.volume_m3, 1e-12 * rep.volume_m3) << res << " m";
    std::printf("In den Arelen at %.0f m: release %.0f m2, %.0f m3 in %ld cells\n", res, rep.area_m2, rep.volume_m3, rep.cells);
    volumes.push_back(rep.volume_m3);
  }
  const auto [lo, hi] = std::minmax_element(volumes.begin(), volumes.end());
  EXPECT_LT(*hi / *lo - 1, 0.02);
}

TEST(Terrain, BadThicknessRastersAreNamed) {
  TempDir d;
  make_dem(d / "dem.tif", 60, 25.0, 30);
  make_raster(d / "deep.tif", "EPSG:32632", 500300, 5200500, 25, 8, 8, [](double x, double) { return x > 500400 ? 600.0 : 1.0; });
  make_raster(d / "far.tif", "EPSG:32632", 600000, 5300000, 25, 8, 8, [](double, double) { return 1.0; });
  make_raster(d / "zero.tif", "EPSG:32632", 500300, 5200500, 25, 8, 8, [](double, double) { return 0.0; });
  make_polygons(d / "rel.geojson", {square(500300, 5200500, 300)}, "EPSG:32632");
  auto raster_release = [&](const char* raster) {
    auto s = base_scenario("dem.tif", "rel.geojson");
    s.mutable_releases(0)->clear_path();
    s.mutable_releases(0)->clear_thickness_m();
    s.mutable_releases(0)->set_thickness_raster(raster);
    return s;
  };
  expect_error(raster_release("deep.tif"), d, "release thickness raster '" + (d / "deep.tif") + "': thickness must lie in [0, 500] m, got 5");  // 540.1: resampled
  expect_error(raster_release("far.tif"), d, "far.tif' lies outside the grid");
  expect_error(raster_release("zero.tif"), d, "zero.tif' lies outside the grid, outside the area of interest or where the DEM has no data, or is thinner");
  expect_error(raster_release("missing.tif"), d, "releases[0].thickness_raster: file");
  auto both = raster_release("deep.tif");
  both.mutable_releases(0)->set_thickness_m(1);
  expect_error(both, d, "releases[0].thickness_raster: gives the thickness: leave thickness_m and thickness_attribute unset");
  auto none = base_scenario("dem.tif", "rel.geojson");
  none.mutable_releases(0)->clear_path();
  expect_error(none, d, "releases[0].path: missing (release polygons, or a thickness_raster)");
}

TEST(Terrain, SelfIntersectingPolygonIsRepairedAndSaid) {
  TempDir d;
  make_dem(d / "dem.tif", 80, 25.0, 30);
  // A bow tie.
  make_polygons(d / "bow.geojson", {{{500300, 5200500}, {500700, 5200900}, {500700, 5200500}, {500300, 5200900}, {500300, 5200500}}},
                "EPSG:32632");
  terrain::DemRequest rq;
  rq.dem_path = d / "dem.tif";
  rq.resolution = 25;
  const auto g = terrain::prepare_grid(rq);
  terrain::ReleaseRequest r;
  r.path = d / "bow.geojson";
  r.has_thickness = true;
  r.thickness = 1;
  terrain::ReleaseReport rep;
  const auto h = terrain::rasterize_releases(g, rq, {r}, &rep);
  ASSERT_EQ(rep.notes.size(), 1u);
  EXPECT_NE(rep.notes[0].find("repaired"), std::string::npos);
  EXPECT_GT(rep.cells, 50);
}

TEST(Terrain, BadInputNamesWhatIsWrong) {
  TempDir d;
  make_dem(d / "dem.tif", 60, 25.0, 30);
  make_dem(d / "nocrs.asc", 60, 25.0, 30, "", false);
  make_polygons(d / "rel.geojson", {square(500300, 5200500, 300)}, "EPSG:32632");
  make_polygons(d / "far.geojson", {square(600000, 5300000, 300)}, "EPSG:32632");
  make_polygons(d / "neg.geojson", {square(500300, 5200500, 300)}, "EPSG:32632", R"(,"t":-1)");
  auto expect = [&](const v1::Scenario& s, const std::string& needle) { expect_error(s, d, needle); };
  auto s = base_scenario("missing.tif", "rel.geojson");
  expect(s, "dem.path: file");
  expect(base_scenario("nocrs.asc", "rel.geojson"), "has no CRS and none is given");
  s = base_scenario("nocrs.asc", "rel.geojson");
  s.mutable_dem()->set_crs("EPSG:32632");
  EXPECT_NO_THROW(jobs::resolve_scenario(s, d.p.string()));
  expect(base_scenario("dem.tif", "far.geojson"), "lies outside the grid");
  s = base_scenario("dem.tif", "neg.geojson");
  s.mutable_releases(0)->clear_thickness_m();
  s.mutable_releases(0)->set_thickness_attribute("t");
  expect(s, "thickness must be > 0 m");
  s = base_scenario("dem.tif", "rel.geojson");
  s.mutable_releases(0)->set_thickness_m(-2);
  expect(s, "releases[0].thickness_m: must lie in (0, 500] m, got -2");
  s = base_scenario("dem.tif", "rel.geojson");
  s.mutable_material()->set_bed_friction_deg(95);
  expect(s, "material.bed_friction_deg: must lie in [0, 90)");
  s = base_scenario("dem.tif", "rel.geojson");
  s.mutable_numerics()->set_limiter("vanLeer");
  expect(s, "numerics.limiter: unknown 'vanLeer' (valid: minmod, vanleer, superbee)");
  s = base_scenario("dem.tif", "rel.geojson");
  s.mutable_numerics()->set_scheme("weno5");
  expect(s, "numerics.scheme: unknown 'weno5' (valid: noc-tvd)");
  s = base_scenario("dem.tif", "rel.geojson");
  s.mutable_material()->set_rheology("bingham");
  expect(s, "valid: coulomb, voellmy");
  s = base_scenario("dem.tif", "rel.geojson", 1.0);
  expect(s, "finer than a tenth of the DEM's resolution");
  s = base_scenario("dem.tif", "rel.geojson");
  s.mutable_releases(0)->set_min_slope_deg(60);
  s.mutable_releases(0)->set_max_slope_deg(70);
  expect(s, "no cell has a slope within [60.0, 70.0] deg");
  s = base_scenario("dem.tif", "rel.geojson");
  s.mutable_outputs()->add_rasters("max_height");
  expect(s, "outputs.rasters: unknown 'max_height'");
  EXPECT_THROW(jobs::parse_scenario_json(R"({"dem": {"path": "x"}, "relases": []})"), jobs::ScenarioError);
}

TEST(Terrain, DemGapsAndTheAreaPolygonAreOutsideTheDomain) {
  TempDir d;
  // A 2.4 km slope with a gap in the DEM right below the release; the area of interest leaves out
  // the northern third.
  make_dem(d / "dem.tif", 120, 20.0, 30, "EPSG:32632", true, 40, 55);
  make_polygons(d / "rel.geojson", {square(500250, 5201050, 300)}, "EPSG:32632");
  make_polygons(d / "aoi.geojson", {{{500000, 5200000}, {502400, 5200000}, {502400, 5201600}, {500000, 5201600}, {500000, 5200000}}},
                "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson");
  sc.mutable_area_of_interest()->set_path(d / "aoi.geojson");
  auto r = jobs::resolve_scenario(sc, d.p.string());
  fs::create_directories(d / "out");
  const auto sum = jobs::run_scenario(r, d / "out");
  EXPECT_GT(sum.volume_outflow, 0.01 * sum.volume_initial);  // material ran into the gap
  EXPECT_LT(sum.volume_error, 1e-12);
  const auto rec = run_record(d / "out/run.json");
  EXPECT_EQ(rec.dem().cells_without_data(), 600);  // 15 x 40 cells
  // The gap (DEM rows 40-79 = grid rows 0-39 of the clipped grid, columns 40-54) is nodata in the rasters.
  GDALDatasetUniquePtr md(GDALDataset::Open((d / "out/max_depth.tif").c_str(), GDAL_OF_RASTER));
  float v = 0;
  ASSERT_EQ(md->GetRasterBand(1)->RasterIO(GF_Read, 45, 20, 1, 1, &v, 1, 1, GDT_Float32, 0, 0), CE_None);
  EXPECT_EQ(v, -9999.0f);
}

TEST(Terrain, TheDemsOwnGridIsUsedAsItIs) {
  TempDir d;
  make_dem(d / "dem.tif", 90, 7.5, 30);  // cells of 7.5 m: not a round size
  terrain::DemRequest rq;
  rq.dem_path = d / "dem.tif";
  rq.target_crs = "dem";
  const auto g = terrain::prepare_grid(rq);
  EXPECT_EQ(g.nx, 90);
  EXPECT_EQ(g.ny, 90);
  EXPECT_EQ(g.dx, 7.5);
  EXPECT_EQ(g.x_min, 500000.0);
  GDALDatasetUniquePtr ds(GDALDataset::Open((d / "dem.tif").c_str(), GDAL_OF_RASTER));
  float z = 0;
  ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 10, 20, 1, 1, &z, 1, 1, GDT_Float32, 0, 0), CE_None);
  EXPECT_EQ(g.z[std::size_t(90 - 1 - 20) * 90 + 10], double(z));  // values unchanged (no resampling)
  // With an area of interest: a window of whole DEM cells.
  make_polygons(d / "aoi.geojson", {square(500100, 5200100, 300)}, "EPSG:32632");
  rq.aoi_path = d / "aoi.geojson";
  const auto w = terrain::prepare_grid(rq);
  EXPECT_EQ(w.dx, 7.5);
  EXPECT_NEAR(std::fmod(w.x_min - 500000.0, 7.5), 0.0, 1e-9);
  EXPECT_LE(w.x_min, 500100.0);
  EXPECT_GE(w.x_min + w.nx * w.dx, 500400.0);
}

// A shapefile without .prj holding one polygon.
void make_shapefile(const std::string& path, const std::vector<std::pair<double, double>>& ring_pts) {
  auto* drv = GetGDALDriverManager()->GetDriverByName("ESRI Shapefile");
  GDALDatasetUniquePtr ds(drv->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  auto* layer = ds->CreateLayer("rel", nullptr, wkbPolygon, nullptr);
  OGRFeature f(layer->GetLayerDefn());
  OGRPolygon p;
  OGRLinearRing ring;
  for (const auto& v : ring_pts) ring.addPoint(v.first, v.second);
  p.addRing(&ring);
  f.SetGeometry(&p);
  ASSERT_EQ(layer->CreateFeature(&f), OGRERR_NONE);
}

TEST(Terrain, LocalCrsForTerrainWithoutGeoreference) {
  TempDir d;
  make_dem(d / "dem.asc", 80, 5.0, 30, "", false);  // synthetic, no CRS at all
  make_shapefile(d / "rel.shp", square(500050, 5200250, 60));
  auto sc = base_scenario(d / "dem.asc", d / "rel.shp");
  sc.mutable_grid()->set_resolution_m(0);
  sc.mutable_dem()->set_crs("local");
  sc.mutable_releases(0)->set_crs("local");
  auto r = jobs::resolve_scenario(sc, d.p.string());
  fs::create_directories(d / "out");
  const auto sum = jobs::run_scenario(r, d / "out");
  EXPECT_EQ(sum.crs, "local metres");
  EXPECT_EQ(sum.nx, 80);
  EXPECT_EQ(sum.dx, 5.0);
  EXPECT_LT(sum.volume_error, 1e-12);
  EXPECT_TRUE(fs::exists(d / "out/max_depth.tif"));
  EXPECT_TRUE(fs::exists(d / "out/outline.gpkg"));
  EXPECT_FALSE(fs::exists(d / "out/outline.geojson"));
  ASSERT_EQ(sum.notes.size(), 1u);
  // The ISeeSnow export: on the DEM's own grid, named after the release and the simulation id.
  fs::create_directories(d / "out2");
  jobs::RunOptions opt;
  opt.iseesnow_id = "03CoulombOnly";
  jobs::run_scenario(r, d / "out2", opt);
  for (const char* f : {"rel_03CoulombOnly_null_runout_pft.asc", "rel_03CoulombOnly_null_runout_pfv.asc",
                        "rel_03CoulombOnly_null_runout.txt", "iseesnow_03CoulombOnly.csv"})
    EXPECT_TRUE(fs::exists(fs::path(d / "out2") / f)) << f;
  GDALDatasetUniquePtr pft(GDALDataset::Open((d / "out2/rel_03CoulombOnly_null_runout_pft.asc").c_str(), GDAL_OF_RASTER));
  GDALDatasetUniquePtr dem(GDALDataset::Open((d / "dem.asc").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(pft && dem);
  EXPECT_EQ(pft->GetRasterXSize(), dem->GetRasterXSize());
  double a[6], b[6];
  pft->GetGeoTransform(a);
  dem->GetGeoTransform(b);
  for (int q = 0; q < 6; ++q) EXPECT_NEAR(a[q], b[q], 1e-6);
  double mx = 0;
  std::vector<float> v(std::size_t(80) * 80);
  ASSERT_EQ(pft->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 80, 80, v.data(), 80, 80, GDT_Float32, 0, 0), CE_None);
  for (float x : v) mx = std::max(mx, double(x));
  EXPECT_NEAR(mx, sum.max_depth, 1e-3);  // the same cells: nothing resampled
  std::ifstream csv(d / "out2/iseesnow_03CoulombOnly.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_EQ(header, ",testCase,computation duration (CPU) [s],avalanche flow time [s],volume at t0 [m3],"
                    "volume at tFinal [m3],spatial resolution x [m],spatial resolution y [m],number of particles");
  EXPECT_EQ(row.rfind("3,CoulombOnly,", 0), 0u) << row;
  EXPECT_NE(row.find(",5,5,"), std::string::npos) << row;
  // A local DEM is resampled in its own frame, and cannot be related to a georeferenced release.
  sc.mutable_grid()->set_resolution_m(10);
  auto coarse = jobs::resolve_scenario(sc, d.p.string());
  fs::create_directories(d / "out3");
  const auto sum10 = jobs::run_scenario(coarse, d / "out3");
  EXPECT_EQ(sum10.nx, 40);
  EXPECT_EQ(sum10.dx, 10.0);
  EXPECT_EQ(sum10.crs, "local metres");
  EXPECT_NEAR(sum10.release_area_m2, sum.release_area_m2, 0.35 * sum.release_area_m2);
  sc.mutable_grid()->set_resolution_m(0);
  sc.mutable_releases(0)->set_crs("EPSG:32632");
  expect_error(sc, d, "a local CRS cannot be related to EPSG:32632");
}

TEST(Terrain, ReleaseWithoutCrsNeedsOne) {
  TempDir d;
  make_dem(d / "dem.tif", 80, 25.0, 30);
  make_shapefile(d / "rel.shp", square(500300, 5200500, 300));
  ASSERT_FALSE(fs::exists(d / "rel.prj"));
  terrain::DemRequest rq;
  rq.dem_path = d / "dem.tif";
  rq.resolution = 25;
  const auto g = terrain::prepare_grid(rq);
  terrain::ReleaseRequest r;
  r.path = d / "rel.shp";
  r.has_thickness = true;
  r.thickness = 1;
  try {
    terrain::rasterize_releases(g, rq, {r});
    ADD_FAILURE();
  } catch (const terrain::TerrainError& e) {
    EXPECT_NE(std::string(e.what()).find("has no CRS and none is given"), std::string::npos) << e.what();
  }
  r.crs = "EPSG:32632";
  terrain::ReleaseReport rep;
  terrain::rasterize_releases(g, rq, {r}, &rep);
  EXPECT_EQ(rep.cells, 12 * 12);
}

TEST(Terrain, GridOverTheMemoryBudgetIsRefused) {
  TempDir d;
  make_dem(d / "dem.tif", 400, 100.0, 20);  // 40 km square
  terrain::DemRequest rq;
  rq.dem_path = d / "dem.tif";
  rq.resolution = 10;  // 16 million cells
  rq.memory_budget_bytes = 1e9;
  try {
    terrain::prepare_grid(rq);
    FAIL();
  } catch (const terrain::TerrainError& e) {
    EXPECT_NE(std::string(e.what()).find("exceeds the memory budget"), std::string::npos) << e.what();
  }
}

// The maps' parameter block names the friction law and its parameters from the law's own rows
// (engine/friction): caption, labels, units; an unset parameter as what its row says it means.
TEST(Terrain, MapParametersNameTheFrictionLawFromItsRows) {
  auto s = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/tests/data/arelen-30m.json");
  const auto g = terrain::prepare_grid(s.dem);
  auto line = [&](const engine::FrictionLaw& law) {
    s.config.material.rheology = &law;
    s.scenario.mutable_material()->set_rheology(std::string(law.name));
    for (const auto& p : jobs::map_parameters(s, g, 1000))
      if (p.rfind("friction: ", 0) == 0) return p;
    return std::string();
  };
  auto* m = s.scenario.mutable_material();
  m->set_bed_friction_deg(15);
  m->clear_internal_friction_deg();
  EXPECT_EQ(line(engine::friction::coulomb), "friction: Coulomb, δ = 15°");
  m->set_internal_friction_deg(32);
  EXPECT_EQ(line(engine::friction::coulomb), "friction: Coulomb, δ = 15°, φ = 32°");
  m->clear_internal_friction_deg();
  m->set_voellmy_mu(0.2);
  m->set_voellmy_xi(1000);
  EXPECT_EQ(line(engine::friction::voellmy), "friction: Voellmy, μ = 0.2, ξ = 1000 m/s²");
  m->set_bed_friction_1_deg(20);
  m->set_bed_friction_2_deg(32);
  m->set_pf_beta(0.136);
  m->set_pf_length_m(0.5);
  // δ₃ unset means δ₁, γ unset means 0.
  EXPECT_EQ(line(engine::friction::pouliquen_forterre), "friction: Pouliquen–Forterre, δ₁ = 20°, δ₂ = 32°, δ₃ = 20°, β = 0.136, L = 0.5 m, γ = 0");
  m->set_mu_s(0.38);
  m->set_mu_2(0.64);
  m->set_mu_i0(0.279);
  m->set_grain_diameter_m(0.005);
  m->set_grain_density_kg_m3(2500);
  EXPECT_EQ(line(engine::friction::mu_i), "friction: μ(I), μs = 0.38, μ₂ = 0.64, I₀ = 0.279, d = 0.005 m, ρs = 2500 kg/m³");
}

// The 3D engine's maps name its granular viscosity and its bed from their rows (engine/vof/models,
// engine/vof/bc): the model's caption with its parameters, the bed's condition with the friction
// angle where it takes one.
TEST(Terrain, MapParametersOfThe3DEngineNameItsViscosityAndBedFromTheirRows) {
  auto s = jobs::load_scenario(std::string(RUNOUT_SOURCE_DIR) + "/tests/data/arelen-30m.json");
  const auto g = terrain::prepare_grid(s.dem);
  s.engine = jobs::kVofTerrainEngine;
  auto lines = [&] {
    std::string out;
    for (const auto& p : jobs::map_parameters(s, g, 1000))
      if (p.rfind("granular viscosity: ", 0) == 0 || p.rfind("bed: ", 0) == 0 || p.rfind("friction: ", 0) == 0) out += p + "\n";
    return out;
  };
  auto* m = s.scenario.mutable_material();
  m->set_rheology("coulomb");
  m->set_bed_friction_deg(15);
  m->set_internal_friction_deg(32);
  s.scenario.mutable_vof()->set_bed("coulomb-friction");
  EXPECT_EQ(lines(), "granular viscosity: Coulomb viscosity, φ = 32°\nbed: Coulomb friction, δ = 15°\n");
  s.scenario.mutable_vof()->set_bed("wall");
  m->set_rheology("mu_i");
  m->set_mu_s(0.38);
  m->set_mu_2(0.64);
  m->set_mu_i0(0.279);
  m->set_grain_diameter_m(0.005);
  m->set_grain_density_kg_m3(2500);
  EXPECT_EQ(lines(), "granular viscosity: μ(I) viscosity, μs = 0.38, μ₂ = 0.64, I₀ = 0.279, d = 0.005 m, ρs = 2500 kg/m³\nbed: stick wall\n");
}
