// What a run's hazard maps become for the hazard engineer: pressure in kPa with its unit in the band
// metadata, the pressure zones (raster, polygons, run.json) and the QGIS styles, on a synthetic slope.
#include <fstream>
#include <sstream>

#include <cairo-pdf.h>

#include "jobs/figures/hazard_map.hpp"
#include "jobs/figures/palette.hpp"
#include "jobs/products/path.hpp"
#include "jobs/products/zones.hpp"
#include "tests/support/run_helpers.hpp"

using namespace runout::test_support::run;

namespace {

// A band's cells, row 0 north (GDAL's order).
std::vector<double> band_values(const fs::path& path, GDALDataType type = GDT_Float64) {
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
  EXPECT_TRUE(ds) << path;
  if (!ds) return {};
  const int nx = ds->GetRasterXSize(), ny = ds->GetRasterYSize();
  std::vector<double> v(std::size_t(nx) * ny);
  EXPECT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, nx, ny, v.data(), nx, ny, type, 0, 0), CE_None);
  return v;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace

TEST(HazardProducts, ZonesClassifyByTheirLowerBoundsInclusive) {
  const std::vector<jobs::ZoneThreshold> z = {{"yellow", 1}, {"blue", 3}, {"red", 30}};
  const auto m = jobs::products::pressure_zones(z, {0.0, 0.999, 1.0, 2.9999, 3.0, 29.99, 30.0, 1e4, NAN});
  EXPECT_EQ(std::vector<int>(m.cls.begin(), m.cls.end()), (std::vector<int>{0, 0, 1, 1, 2, 2, 3, 3, 0}));
  ASSERT_EQ(m.classes.size(), 3u);
  EXPECT_EQ(m.classes[1].to, 30.0);
  EXPECT_TRUE(std::isnan(m.classes[2].to));
  EXPECT_EQ(jobs::products::zone_label(m.classes[2]), "red: ≥ 30 kPa");
  // A colour name colours the zone; other names take their rank on the ramp.
  EXPECT_EQ(figures::hex(m.palette.classes[1].colour), "#005ce6");
  const auto other = jobs::products::pressure_zones({{"low", 1}, {"high", 10}}, {});
  EXPECT_NE(other.palette.classes[0].colour, other.palette.classes[1].colour);
}

TEST(HazardProducts, PressureZonesFollowTheMaxPressureRasterCellForCell) {
  TempDir d;
  make_dem(d / "dem.tif", 120, 20.0, 30);
  make_polygons(d / "rel.geojson", {square(500200, 5201000, 300)}, "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson");
  for (auto [name, from] : {std::pair{"yellow", 1.0}, {"blue", 10.0}, {"red", 100.0}}) {
    auto* z = sc.mutable_outputs()->add_pressure_zones_kpa();
    z->set_name(name);
    z->set_from_kpa(from);
  }
  auto r = jobs::resolve_scenario(sc, d.p.string());
  fs::create_directories(d / "out");
  const auto sum = jobs::run_scenario(r, d / "out");
  const fs::path out = d / "out";
  // Pressure in kPa, said in the band metadata; run.json's maxima are the rasters'.
  GDALDatasetUniquePtr pr(GDALDataset::Open((out / "max_pressure.tif").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(pr);
  EXPECT_STREQ(pr->GetRasterBand(1)->GetUnitType(), "kPa");
  EXPECT_NE(std::string(pr->GetRasterBand(1)->GetDescription()).find("[kPa]"), std::string::npos);
  const auto p = band_values(out / "max_pressure.tif"), h = band_values(out / "max_depth.tif"), sp = band_values(out / "max_speed.tif");
  const auto zone = band_values(out / "pressure_zones.tif");
  const auto rec = run_record(out / "run.json");
  double pmax = 0, smax = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (p[k] > -9999) pmax = std::max(pmax, p[k]);
    if (sp[k] > -9999) smax = std::max(smax, sp[k]);
  }
  EXPECT_NEAR(rec.results().max_pressure_kpa(), pmax, 1e-6 * pmax);  // Float32 raster
  EXPECT_NEAR(rec.solver().max_speed_m_s(), smax, 1e-6 * smax);
  EXPECT_GT(pmax, 100.0);  // the red zone is reached
  // Each cell's zone is its maximum pressure's class, inside the outline (max depth > 0.1 m).
  std::vector<long> count(4, 0);
  for (std::size_t k = 0; k < p.size(); ++k) {
    int want = 0;
    if (h[k] > 0.1) want = p[k] >= 100 ? 3 : p[k] >= 10 ? 2 : p[k] >= 1 ? 1 : 0;
    ASSERT_EQ(int(zone[k]), want) << "cell " << k << ": " << p[k] << " kPa, " << h[k] << " m";
    ++count[std::size_t(want)];
  }
  // The polygons: per zone, the area of its cells, with the name and bounds as attributes; the same
  // in run.json.
  GDALDatasetUniquePtr gp(GDALDataset::Open((out / "pressure_zones.gpkg").c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(gp);
  std::map<std::string, double> area;
  for (auto& f : gp->GetLayerByName("pressure_zones")) {
    ASSERT_TRUE(f->GetGeometryRef()->IsValid());
    area[f->GetFieldAsString("name")] += OGR_G_Area(OGRGeometry::ToHandle(f->GetGeometryRef()));
    if (std::string(f->GetFieldAsString("name")) == "red") EXPECT_TRUE(f->IsFieldNull(f->GetFieldIndex("to_kpa")));
    if (std::string(f->GetFieldAsString("name")) == "blue") EXPECT_EQ(f->GetFieldAsDouble("to_kpa"), 100.0);
  }
  ASSERT_EQ(rec.results().pressure_zones_size(), 3);
  const char* names[] = {"yellow", "blue", "red"};
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(area[names[k]], count[std::size_t(k) + 1] * 400.0, 1e-6) << names[k];
    EXPECT_EQ(rec.results().pressure_zones(k).name(), names[k]);
    EXPECT_NEAR(rec.results().pressure_zones(k).area_m2(), count[std::size_t(k) + 1] * 400.0, 1e-6) << names[k];
  }
  EXPECT_EQ(rec.results().affected_area_criterion(), "max depth > 0.1 m");
  EXPECT_EQ(rec.results().pressure_zones_criterion(), "max pressure rho u^2 where max depth > 0.1 m");
  GDALDatasetUniquePtr gj(GDALDataset::Open((out / "pressure_zones.geojson").c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(gj);
  EXPECT_GT(gj->GetLayer(0)->GetFeatureCount(), 0);
  // QGIS styles beside the rasters, in the maps' colours.
  const std::string qml = slurp(out / "max_pressure.qml"), zq = slurp(out / "pressure_zones.qml");
  for (const auto& c : figures::hazard_palette("max_pressure").classes)
    EXPECT_NE(qml.find("color=\"" + figures::hex(c.colour) + "\""), std::string::npos) << c.label;
  EXPECT_NE(zq.find("label=\"blue: 10 – 100 kPa\""), std::string::npos) << zq;
  EXPECT_NE(zq.find("color=\"#005ce6\""), std::string::npos) << zq;
  for (const char* f : {"max_depth.qml", "max_speed.qml", "deposit.qml", "arrival_time.qml"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  (void)sum;
}

TEST(HazardProducts, BadPressureZonesAreNamed) {
  const std::string dir = std::string(RUNOUT_SOURCE_DIR) + "/tests/data";
  auto refused = [&](std::initializer_list<std::pair<const char*, double>> zones, std::initializer_list<std::string> needles) {
    v1::Scenario s = jobs::parse_scenario_json(slurp(dir + "/arelen-30m.json"));
    for (auto [name, from] : zones) {
      auto* z = s.mutable_outputs()->add_pressure_zones_kpa();
      z->set_name(name);
      z->set_from_kpa(from);
    }
    try {
      jobs::resolve_scenario(s, dir);
      ADD_FAILURE() << "no error, expected one naming " << *needles.begin();
    } catch (const jobs::ScenarioError& e) {
      for (const auto& n : needles) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
    }
  };
  refused({{"blue", 30}, {"red", 3}}, {"outputs.pressure_zones_kpa[1].from_kpa", "must ascend"});
  refused({{"", 3}}, {"outputs.pressure_zones_kpa[0].name", "missing"});
  refused({{"blue", 3}, {"blue", 30}}, {"outputs.pressure_zones_kpa[1].name", "names zone 0"});
  refused({{"blue", 0}}, {"outputs.pressure_zones_kpa[0].from_kpa", "missing"});
  refused({{"blue", -3}}, {"outputs.pressure_zones_kpa[0].from_kpa"});
}

namespace {

// A plane tilted to the south-west on 100 x 80 cells of 10 m with a value that grows to the east.
terrain::Grid tilted_grid() {
  terrain::Grid g;
  g.nx = 100;
  g.ny = 80;
  g.dx = 10;
  g.x_min = 600000;
  g.y_min = 5200000;
  OGRSpatialReference srs;
  srs.importFromEPSG(32632);
  char* wkt = nullptr;
  srs.exportToWkt(&wkt);
  g.crs_wkt = wkt;
  CPLFree(wkt);
  g.crs_name = "EPSG:32632";
  g.z.resize(g.cells());
  g.outside.assign(g.cells(), 0);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) g.z[std::size_t(j) * g.nx + i] = 1000 + 3.0 * i + 5.0 * j + 20 * std::sin(0.1 * i);
  return g;
}

}  // namespace

TEST(HazardProducts, MapsShowTheWholeUtf8TitleAndColourBarsMatchTheDrawnColours) {
  TempDir d;
  const auto g = tilted_grid();
  figures::HazardMap m;
  m.title = "Zürich: 45° slope, 30 % (test)";
  m.palette = figures::hazard_palette("max_speed");
  m.values.resize(g.cells());
  m.max_depth.resize(g.cells());
  m.release.assign(g.cells(), 0);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const std::size_t k = std::size_t(j) * g.nx + i;
      m.values[k] = j > 10 && j < 70 ? 0.6 * i : NAN;  // 0 to 60 m/s from west to east: every class
      m.max_depth[k] = j > 10 && j < 70 && i > 5 ? 1.0 : 0.0;
      if (j > 55 && j < 65 && i > 5 && i < 15) m.release[k] = 2;
    }
  m.points.push_back({"Hütte", 600500, 5200400});
  m.parameters = {"engine: depth-averaged Savage–Hutter", "friction: Coulomb, δ = 20°"};
  const auto lay = figures::draw_hazard_map(d / "map.png", d / "map.pdf", g, m);
  // The title whole, on one line, every character drawn.
  EXPECT_EQ(lay.unknown_glyphs, 0);
  EXPECT_EQ(lay.title_lines, 1);
  EXPECT_GT(lay.title[2], 200.0);
  EXPECT_LE(lay.title[0] + lay.title[2], lay.width);
  std::ifstream pdf(d / "map.pdf", std::ios::binary);
  std::string head(5, ' ');
  pdf.read(head.data(), 5);
  EXPECT_EQ(head, "%PDF-");
  // The pixels of the PNG.
  GDALDatasetUniquePtr png(GDALDataset::Open((d / "map.png").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(png);
  ASSERT_EQ(png->GetRasterXSize(), lay.width);
  ASSERT_GE(png->GetRasterCount(), 3);
  auto pixel = [&](double x, double y) {
    figures::Rgb8 c{};
    for (int b = 0; b < 3; ++b)
      if (png->GetRasterBand(b + 1)->RasterIO(GF_Read, int(x), int(y), 1, 1, &c[std::size_t(b)], 1, 1, GDT_Byte, 0, 0) != CE_None)
        ADD_FAILURE() << "reading pixel " << x << ", " << y;
    return c;
  };
  // Each colour bar swatch shows its class's colour ...
  ASSERT_EQ(lay.swatches.size(), m.palette.classes.size());
  for (std::size_t k = 0; k < lay.swatches.size(); ++k) {
    const auto& sw = lay.swatches[k];
    EXPECT_EQ(pixel(sw[0] + sw[2] / 2, sw[1] + sw[3] / 2), m.palette.classes[k].colour) << m.palette.classes[k].label;
  }
  // ... and the map shows the same colour at the centres of the cells of that class (all but the few
  // under a contour line or an outline).
  for (std::size_t k = 0; k < m.palette.classes.size(); ++k) {
    int cells = 0, same = 0;
    for (int j = 15; j < 50; j += 3)
      for (int i = 1; i < g.nx - 1; ++i) {
        if (m.palette.class_of(m.values[std::size_t(j) * g.nx + i - 1]) != int(k) ||
            m.palette.class_of(m.values[std::size_t(j) * g.nx + i + 1]) != int(k))
          continue;
        ++cells;
        same += pixel(lay.map_x + (i + 0.5) * lay.cell_px, lay.map_y + (g.ny - 1 - j + 0.5) * lay.cell_px) == m.palette.classes[k].colour;
      }
    ASSERT_GT(cells, 10) << m.palette.classes[k].label;
    EXPECT_GT(same, 0.8 * cells) << m.palette.classes[k].label << ": " << same << " of " << cells;
  }
  // A title longer than the page wraps, and stays whole.
  m.title = std::string(40, 'x') + " " + std::string(60, 'y') + " Zürich: 45° slope, 30 % (test) " + std::string(50, 'z');
  const auto wrapped = figures::draw_hazard_map(d / "long.png", "", g, m);
  EXPECT_GT(wrapped.title_lines, 1);
  EXPECT_LE(wrapped.title[0] + wrapped.title[2], wrapped.width);
  EXPECT_EQ(wrapped.unknown_glyphs, 0);
}

// Scores against an observed outline with known answers: the run's own outline (in WGS84) scores a
// critical success index of exactly 1; a rectangle scores the cells counted here from max_depth.tif.
TEST(HazardProducts, ObservedOutlineScoresHaveKnownAnswers) {
  TempDir d;
  make_dem(d / "dem.tif", 120, 20.0, 30);
  make_polygons(d / "rel.geojson", {square(500200, 5201000, 300)}, "EPSG:32632");
  auto sc = base_scenario(d / "dem.tif", d / "rel.geojson");
  fs::create_directories(d / "first");
  const auto first = jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "first");
  // The run's own outline, in WGS84: every simulated cell a hit.
  sc.mutable_observations()->set_outline_path(d / "first/outline.geojson");
  fs::create_directories(d / "self");
  jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "self");
  const auto self = run_record(d / "self/run.json").results().observation_scores();
  EXPECT_EQ(self.critical_success_index(), 1.0);
  EXPECT_EQ(self.true_positive_m2(), first.affected_area_m2);
  EXPECT_EQ(self.false_positive_m2(), 0.0);
  EXPECT_EQ(self.false_negative_m2(), 0.0);
  EXPECT_EQ(self.true_positive_rate(), 1.0);
  EXPECT_EQ(self.false_positive_rate(), 0.0);
  EXPECT_EQ(self.criterion(), "max depth > 0.1 m");
  EXPECT_TRUE(fs::exists(d / "self/map_observation.png"));
  EXPECT_TRUE(fs::exists(d / "self/map_observation.pdf"));
  // A rectangle over the lower part of the slope: the counts by hand from max_depth.tif.
  const double x0 = 501000, x1 = 502000, y0 = 5200800, y1 = 5201600;
  make_polygons(d / "obs.geojson", {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}}}, "EPSG:32632");
  sc.mutable_observations()->set_outline_path("obs.geojson");
  fs::create_directories(d / "rect");
  jobs::run_scenario(jobs::resolve_scenario(sc, d.p.string()), d / "rect");
  GDALDatasetUniquePtr md(GDALDataset::Open((d / "rect/max_depth.tif").c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(md);
  double gt[6];
  md->GetGeoTransform(gt);
  const auto h = band_values(d / "rect/max_depth.tif");
  const int nx = md->GetRasterXSize(), ny = md->GetRasterYSize();
  double tp = 0, fp = 0, fn = 0, tn = 0;
  for (int r = 0; r < ny; ++r)
    for (int i = 0; i < nx; ++i) {
      const double v = h[std::size_t(r) * nx + i];
      if (v == -9999) continue;  // outside the domain
      const double cx = gt[0] + (i + 0.5) * gt[1], cy = gt[3] + (r + 0.5) * gt[5];
      const bool sim = v > 0.1, obs = cx > x0 && cx < x1 && cy > y0 && cy < y1;
      (sim && obs ? tp : sim ? fp : obs ? fn : tn) += gt[1] * gt[1];
    }
  ASSERT_GT(tp, 0);
  ASSERT_GT(fp, 0);
  ASSERT_GT(fn, 0);
  const auto rect = run_record(d / "rect/run.json").results().observation_scores();
  EXPECT_EQ(rect.true_positive_m2(), tp);
  EXPECT_EQ(rect.false_positive_m2(), fp);
  EXPECT_EQ(rect.false_negative_m2(), fn);
  EXPECT_EQ(rect.true_negative_m2(), tn);
  EXPECT_NEAR(rect.critical_success_index(), tp / (tp + fp + fn), 1e-9);  // run.json: 10 significant digits
  EXPECT_NEAR(rect.true_positive_rate(), tp / (tp + fn), 1e-9);
  EXPECT_NEAR(rect.false_positive_rate(), fp / (fp + tn), 1e-9);
  // An observation that is not there, or covers no cell of the domain, is refused before the run.
  sc.mutable_observations()->set_outline_path("missing.geojson");
  expect_error(sc, d, "observations.outline_path");
  make_polygons(d / "far.geojson", {square(700000, 5300000, 300)}, "EPSG:32632");
  sc.mutable_observations()->set_outline_path("far.geojson");
  expect_error(sc, d, "observations.outline_path: '");
}

// The path analysis on a slope of 30 deg that runs into a flat: the runout point is the last section
// reaching the threshold, alpha follows from the ground, beta lies at the slope's foot, and the
// runout zone's area counts the threshold's cells beyond it.
TEST(HazardProducts, PathAnalysisHasKnownAnswers) {
  terrain::Grid g = tilted_grid();  // 100 x 80 cells of 10 m
  const double t30 = std::tan(30 * M_PI / 180);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) g.z[std::size_t(j) * g.nx + i] = 1000 - t30 * std::min(g.cx(i) - g.x_min, 500.0);
  std::vector<double> depth(g.cells(), 0), speed(g.cells(), 0), pressure(g.cells(), 0), release(g.cells(), 0);
  for (int j = 30; j < 50; ++j)
    for (int i = 0; i < 72; ++i) {  // a band 200 m wide to x = 720 m (cell centres up to 715 m)
      const std::size_t k = std::size_t(j) * g.nx + i;
      pressure[k] = i < 60 ? 50 : 2;
      depth[k] = 1;
      speed[k] = 10;
      if (i < 10) release[k] = 1;
    }
  jobs::PathSettings set;
  const jobs::products::Line line = {{g.x_min + 5, g.y_min + 400}, {g.x_min + 995, g.y_min + 400}};
  const auto p = jobs::products::analyse_path(g, line, {depth, speed, pressure, release}, set);
  ASSERT_TRUE(p.runout);
  EXPECT_NEAR(p.s[*p.runout], 710, 10.0);  // the last cell at least 1 kPa ends at 720 m from x_min (the line starts at 5 m)
  const double drop = 1000 - t30 * std::min(p.x.front() - g.x_min, 500.0) - (1000 - t30 * 500);
  EXPECT_NEAR(p.alpha_deg, std::atan(drop / p.s[*p.runout]) * 180 / M_PI, 0.5);
  ASSERT_TRUE(p.beta);
  EXPECT_NEAR(p.x[*p.beta] - g.x_min, 500, 20.0);  // the slope's foot (the slope is taken over four sections)
  // Beyond beta: the band's cells from there to 720 m, 20 cells across.
  const double expect_area = (720 - std::ceil((p.x[*p.beta] - g.x_min - 5) / 10) * 10 - 0) / 10 * 20 * 100;
  EXPECT_NEAR(p.runout_zone_area_m2, expect_area, 20 * 100 * 1.0);
  EXPECT_EQ(p.criterion, "max pressure >= 1 kPa");
  // With the depth as the marker and a threshold above the band's depth, no runout point.
  set.field = "pft";
  set.threshold = 2;
  EXPECT_FALSE(jobs::products::analyse_path(g, line, {depth, speed, pressure, release}, set).runout);
}

// A report's map page, known answers on the tilted grid (1000 x 800 m) in a room of 500 x 400 pt:
// the scale is the smallest round one at which it fits (1:10 000: 283 x 227 pt; 1:5000 would need
// 567 pt), the cells' raster has the page's 300 dpi (1000 m at 1:10 000 is 3.94 in: 1182 pixels),
// and the labels of six points crowded into 60 m (the names longer than the points' spacing) are
// placed so that no two overlap, some moved out with leader lines.
TEST(HazardProducts, AReportMapPageHasItsScaleItsResolutionAndLabelsThatDoNotOverlap) {
  TempDir d;
  const auto g = tilted_grid();
  figures::HazardMap m;
  m.title = "test";
  m.palette = figures::hazard_palette("max_depth");
  m.values.assign(g.cells(), 1.0);
  m.max_depth.assign(g.cells(), 1.0);
  for (int k = 0; k < 6; ++k) m.points.push_back({"farmhouse number " + std::to_string(k), g.x_min + 500 + 10 * k, g.y_min + 400 + 10 * k});
  figures::MapPageSpec spec;
  spec.x = 40;
  spec.y = 40;
  spec.w = 500;
  spec.h = 400;
  spec.panel_x = 560;
  spec.panel_y = 40;
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surf(cairo_pdf_surface_create((d / "page.pdf").c_str(), 842, 595),
                                                                          cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surf.get()), cairo_destroy);
  const auto lay = figures::draw_map_page(cr.get(), g, m, spec);
  EXPECT_EQ(lay.scale, 10000);
  EXPECT_NEAR(lay.frame[2], 1000 * 72 / 0.0254 / 10000, 1e-9);
  EXPECT_NEAR(lay.frame[3], 800 * 72 / 0.0254 / 10000, 1e-9);
  EXPECT_EQ(lay.image_w, 1182);
  EXPECT_EQ(lay.image_h, 945);
  EXPECT_EQ(lay.unknown_glyphs, 0);
  ASSERT_GE(lay.label_boxes.size(), 6u);
  for (std::size_t a = 0; a < lay.label_boxes.size(); ++a)
    for (std::size_t b = a + 1; b < lay.label_boxes.size(); ++b) {
      const auto &p = lay.label_boxes[a], &q = lay.label_boxes[b];
      EXPECT_FALSE(p[0] < q[0] + q[2] && q[0] < p[0] + p[2] && p[1] < q[1] + q[3] && q[1] < p[1] + p[3]) << a << " and " << b << " overlap";
    }
  EXPECT_GT(lay.leader_lines, 0);
  // Too large for the room even at 1:200 000: refused, named.
  spec.w = spec.h = 2;
  EXPECT_THROW(figures::draw_map_page(cr.get(), g, m, spec), terrain::TerrainError);
}

// The flow's own path, known answers on the tilted grid (100 x 80 cells of 10 m):
// - a mass-centre track along a diagonal starts at the release's upper edge (back along the track's
//   first direction), passes every track point (points closer than half a cell dropped) and goes on
//   in the last direction to the domain's edge; a track that did not move gives no path;
// - a flow that split into a short branch (north) and a long one (east) has its longest flow line
//   from the release's highest cell to the long branch's tip, on released or outlined cells all the
//   way (but for the smoothing's corner).
TEST(HazardProducts, TheFlowsPathFollowsItsMassCentreOrItsFarthestBranch) {
  const terrain::Grid g = tilted_grid();
  std::vector<double> release(g.cells(), 0), depth(g.cells(), 0);
  for (int j = 40; j < 46; ++j)
    for (int i = 10; i < 16; ++i) release[std::size_t(j) * g.nx + i] = 1;  // x 100-160 m, y 400-460 m from the corner
  const double x0 = g.x_min, y0 = g.y_min;
  std::vector<jobs::products::TrackPoint> track = {{0, x0 + 130, y0 + 430}, {5, x0 + 130.2, y0 + 430}, {10, x0 + 230, y0 + 380},
                                                   {15, x0 + 330, y0 + 330}, {20, x0 + 430, y0 + 280}};
  const auto line = jobs::products::flow_path(g, track, release);
  ASSERT_GE(line.size(), 6u);
  // The top: on the line back from (130, 430) against (100, -50), the last released cell's point
  // lies within a cell of the release's upper-left corner (100, 460).
  EXPECT_NEAR(line.front().first - x0, 100, 12.0);
  EXPECT_NEAR(line.front().second - y0, 445, 12.0);
  EXPECT_DOUBLE_EQ(line[1].first, x0 + 130);  // then the track, the point 0.2 m on dropped
  EXPECT_DOUBLE_EQ(line[2].first, x0 + 230);
  EXPECT_DOUBLE_EQ(line[4].second, y0 + 280);
  // On to the edge in the last direction (2, -1): the bottom edge at y = 0 is met at x = 990 m.
  EXPECT_LT(line.back().second - y0, 10.0);
  EXPECT_NEAR(line.back().first - x0, 430 + 2 * 280, 25.0);
  EXPECT_TRUE(jobs::products::flow_path(g, {{0, x0 + 130, y0 + 430}, {5, x0 + 131, y0 + 430}}, release).empty());
  // A second release beyond a gap on the line back is another release: the top stays at this one's edge.
  auto two = release;
  for (int j = 46; j < 52; ++j)
    for (int i = 0; i < 5; ++i) two[std::size_t(j) * g.nx + i] = 1;  // up the line back, 40 m past the first one's edge
  EXPECT_EQ(jobs::products::flow_path(g, track, two).front(), line.front());

  // A split flow: from the release a branch 3 cells wide north to y = 700 m and one east to x = 900 m.
  for (int j = 40; j < 70; ++j)
    for (int i = 12; i < 15; ++i) depth[std::size_t(j) * g.nx + i] = 1;
  for (int j = 41; j < 44; ++j)
    for (int i = 12; i < 90; ++i) depth[std::size_t(j) * g.nx + i] = 1;
  std::pair<double, double> far;
  const auto longest = jobs::products::longest_flow_line(g, release, depth, 0.1, &far);
  EXPECT_DOUBLE_EQ(far.first, g.cx(89));  // the east branch's tip
  EXPECT_GE(far.second, g.cy(41));
  EXPECT_LE(far.second, g.cy(43));
  ASSERT_GE(longest.size(), 70u);
  std::size_t on_flow = 0, before_tip = 0;
  for (const auto& [x, y] : longest) {
    if (x > far.first + 1) break;  // the straight extension beyond the tip
    ++before_tip;
    const int i = int((x - g.x_min) / g.dx), j = int((y - g.y_min) / g.dx);
    on_flow += depth[std::size_t(j) * g.nx + i] > 0.1 || release[std::size_t(j) * g.nx + i] > 0;
  }
  EXPECT_GE(on_flow + 2, before_tip);  // the five-cell smoothing may cut the corner where the branch leaves the release
  // Along the east branch (rows 41-43) the line keeps to its middle row, not to an edge.
  int middle = 0, along = 0;
  for (const auto& [x, y] : longest)
    if (x > x0 + 300 && x < x0 + 800) ++along, middle += std::fabs(y - g.cy(42)) < 1e-9;
  EXPECT_GT(along, 40);
  EXPECT_EQ(middle, along);
  // The mass centre of such a flow lies between the branches, off the outline: not a path.
  EXPECT_FALSE(jobs::products::track_inside_outline(g, {{0, x0 + 130, y0 + 430}, {10, x0 + 400, y0 + 600}}, depth, 0.1));
  EXPECT_TRUE(jobs::products::track_inside_outline(g, {{0, x0 + 130, y0 + 430}, {10, x0 + 400, y0 + 420}}, depth, 0.1));
  EXPECT_NEAR(jobs::products::distance_to_line(longest, x0 + 500, g.cy(42) + 300), 300, 1e-9);
}

namespace {

// The pixels of a map's frame (the grid's cells) whose colour satisfies `pred(r, g, b)`.
template <class Pred>
long map_pixels(const std::string& png_path, const figures::MapLayout& lay, const terrain::Grid& g, Pred pred) {
  GDALDatasetUniquePtr png(GDALDataset::Open(png_path.c_str(), GDAL_OF_RASTER));
  EXPECT_TRUE(png);
  if (!png) return 0L;
  const int w = png->GetRasterXSize(), h = png->GetRasterYSize();
  std::vector<std::uint8_t> rgb[3];
  for (int b = 0; b < 3; ++b) {
    rgb[b].resize(std::size_t(w) * h);
    EXPECT_EQ(png->GetRasterBand(b + 1)->RasterIO(GF_Read, 0, 0, w, h, rgb[b].data(), w, h, GDT_Byte, 0, 0), CE_None);
  }
  long n = 0;
  for (int y = int(lay.map_y); y < int(lay.map_y + g.ny * lay.cell_px) && y < h; ++y)
    for (int x = int(lay.map_x); x < int(lay.map_x + g.nx * lay.cell_px) && x < w; ++x) {
      const std::size_t k = std::size_t(y) * w + x;
      n += pred(int(rgb[0][k]), int(rgb[1][k]), int(rgb[2][k]));
    }
  return n;
}

// A block of cells (i in [20, 60), j in [20, 50)) as a mask.
std::vector<std::uint8_t> block_mask(const terrain::Grid& g) {
  std::vector<std::uint8_t> m(g.cells(), 0);
  for (int j = 20; j < 50; ++j)
    for (int i = 20; i < 60; ++i) m[std::size_t(j) * g.nx + i] = 1;
  return m;
}

}  // namespace

// Resistance areas (forest) are outlined on the maps in green, the erodible cover in blue and dams in
// brown: the same map with an area shows pixels of its colour along its edges that the map without
// it has not.
TEST(HazardProducts, MapsOutlineTheResistanceAreasTheCoverAndTheDams) {
  TempDir d;
  const auto g = tilted_grid();
  figures::HazardMap m;
  m.title = "forest";
  m.palette = figures::hazard_palette("max_depth");
  m.values.assign(g.cells(), NAN);
  auto green = [](int r, int gr, int b) { return gr > r + 50 && gr > b + 50; };
  auto blue = [](int r, int gr, int b) { return b > r + 100 && gr > r + 80 && b > gr + 20; };
  const auto plain = figures::draw_hazard_map(d / "plain.png", "", g, m);
  m.resistance = block_mask(g);
  const auto forest = figures::draw_hazard_map(d / "forest.png", "", g, m);
  const long edge_px = long(2 * (30 + 40) * forest.cell_px);  // the area's perimeter in pixels
  EXPECT_EQ(map_pixels(d / "plain.png", plain, g, green), 0);
  EXPECT_GT(map_pixels(d / "forest.png", forest, g, green), edge_px / 3);  // a dashed line, 1.6 px wide
  m.resistance.clear();
  m.cover = block_mask(g);
  const auto cover = figures::draw_hazard_map(d / "cover.png", "", g, m);
  EXPECT_EQ(map_pixels(d / "plain.png", plain, g, blue), 0);
  EXPECT_GT(map_pixels(d / "cover.png", cover, g, blue), edge_px / 3);
  m.cover.clear();
  m.dams = block_mask(g);
  auto brown = [](int r, int gr, int b) { return r > gr + 40 && gr > b + 30 && r < 200; };
  const auto dam = figures::draw_hazard_map(d / "dam.png", "", g, m);
  EXPECT_EQ(map_pixels(d / "plain.png", plain, g, brown), 0);
  EXPECT_GT(map_pixels(d / "dam.png", dam, g, brown), edge_px / 2);  // a solid line, 2.2 px wide
}
