#include "jobs/figures/hazard_map.hpp"

#include <cairo-pdf.h>
#include <cairo.h>
#include <cpl_error.h>
#include <gdal_alg.h>
#include <gdal_priv.h>
#include <gdal_utils.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>

#include "jobs/figures/map_drawing.hpp"
#include "jobs/figures/pen.hpp"

namespace runout::figures {
using terrain::Grid;
using terrain::TerrainError;

namespace detail {

const Rgb kInk{0.1, 0.1, 0.1}, kRelease{0.05, 0.05, 0.05}, kOutline{0.43, 0.0, 0.08}, kContour{0.25, 0.22, 0.18},
    kPath{0.05, 0.2, 0.45}, kForest{0.1, 0.45, 0.12}, kCover{0.0, 0.55, 0.75}, kDam{0.45, 0.25, 0.1};
constexpr double kPanel = 290, kLeft = 84, kGap = 30, kRight = 20, kBottom = 86;

// The DEM as an in-memory raster (north-up, row 0 north).
GDALDatasetUniquePtr dem_raster(const Grid& g) {
  auto* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDatasetUniquePtr dem(mem->Create("", g.nx, g.ny, 1, GDT_Float32, nullptr));
  double gt[6] = {g.x_min, g.dx, 0, g.y_min + g.ny * g.dx, 0, -g.dx};
  dem->SetGeoTransform(gt);
  dem->SetProjection(g.crs_wkt.c_str());
  std::vector<float> rows(g.cells());
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) rows[std::size_t(r) * g.nx + i] = float(g.z[std::size_t(g.ny - 1 - r) * g.nx + i]);
  if (dem->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Float32, 0, 0) != CE_None)
    throw TerrainError("map: writing the DEM failed");
  return dem;
}

// Hillshade with GDAL's DEM tools, one byte per cell, row 0 north.
std::vector<std::uint8_t> hillshade(GDALDataset& dem, const Grid& g) {
  char* args[] = {const_cast<char*>("-of"), const_cast<char*>("MEM"), const_cast<char*>("-compute_edges"), nullptr};
  std::unique_ptr<GDALDEMProcessingOptions, decltype(&GDALDEMProcessingOptionsFree)> opt(GDALDEMProcessingOptionsNew(args, nullptr),
                                                                                         GDALDEMProcessingOptionsFree);
  GDALDatasetUniquePtr hs(GDALDataset::FromHandle(GDALDEMProcessing("", GDALDataset::ToHandle(&dem), "hillshade", nullptr, opt.get(), nullptr)));
  if (!hs) throw TerrainError(std::string("map: hillshade failed: ") + CPLGetLastErrorMsg());
  std::vector<std::uint8_t> shade(g.cells());
  if (hs->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, g.nx, g.ny, shade.data(), g.nx, g.ny, GDT_Byte, 0, 0) != CE_None)
    throw TerrainError("map: reading the hillshade failed");
  return shade;
}

// Elevation contours every `interval` metres (GDAL's contour generator), as polylines in the grid's CRS.
std::vector<Contour> contours(GDALDataset& dem, double interval) {
  auto* drv = GetGDALDriverManager()->GetDriverByName("Memory");
  GDALDatasetUniquePtr vds(drv->Create("", 0, 0, 0, GDT_Unknown, nullptr));
  OGRLayer* layer = vds->CreateLayer("contours", nullptr, wkbLineString, nullptr);
  OGRFieldDefn id("id", OFTInteger), elev("elev", OFTReal);
  layer->CreateField(&id);
  layer->CreateField(&elev);
  const std::string level = "LEVEL_INTERVAL=" + std::to_string(interval);
  const char* opts[] = {level.c_str(), "ID_FIELD=0", "ELEV_FIELD=1", nullptr};
  if (GDALContourGenerateEx(dem.GetRasterBand(1), layer, const_cast<char**>(opts), nullptr, nullptr) != CE_None)
    throw TerrainError(std::string("map: contours failed: ") + CPLGetLastErrorMsg());
  std::vector<Contour> out;
  for (auto& f : layer) {
    const OGRGeometry* geom = f->GetGeometryRef();
    if (!geom || wkbFlatten(geom->getGeometryType()) != wkbLineString) continue;
    const auto* ls = geom->toLineString();
    Contour c{f->GetFieldAsDouble(1), {}};
    for (int k = 0; k < ls->getNumPoints(); ++k) c.xy.emplace_back(ls->getX(k), ls->getY(k));
    out.push_back(std::move(c));
  }
  return out;
}


void colour(cairo_t* cr, const Rgb& c, double alpha) { cairo_set_source_rgba(cr, c.r, c.g, c.b, alpha); }
Rgb rgb(const Rgb8& c) { return {c[0] / 255.0, c[1] / 255.0, c[2] / 255.0}; }

// A cell's colour: its class's where classed, else the hillshade's grey (`sh` in 0-1), pale outside
// the domain.
Rgb8 cell_colour(const Grid& g, const HazardMap& m, std::size_t k, double sh) {
  Rgb8 c;
  const int cls = m.values.empty() ? -1 : m.palette.class_of(m.values[k]);
  if (!g.outside.empty() && g.outside[k]) c.fill(std::uint8_t(215 + 40 * sh));
  else if (cls >= 0) c = m.palette.classes[std::size_t(cls)].colour;
  else c.fill(std::uint8_t(std::clamp(70 + 185 * sh, 0.0, 255.0)));
  return c;
}

// The cells: hillshade grey, pale outside the domain, the palette's colour (opaque) where classed.
void draw_cells(cairo_t* cr, const Frame& f, const HazardMap& m, const std::vector<std::uint8_t>& shade) {
  const Grid& g = f.g;
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> img(cairo_image_surface_create(CAIRO_FORMAT_RGB24, g.nx, g.ny),
                                                                          cairo_surface_destroy);
  const int stride = cairo_image_surface_get_stride(img.get());
  unsigned char* data = cairo_image_surface_get_data(img.get());
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) {
      const std::size_t k = std::size_t(g.ny - 1 - r) * g.nx + i;
      const double sh = shade[std::size_t(r) * g.nx + i] / 255.0;
      const Rgb8 c = cell_colour(g, m, k, sh);
      auto* px = reinterpret_cast<std::uint32_t*>(data + std::size_t(r) * stride) + i;
      *px = (std::uint32_t(c[0]) << 16) | (std::uint32_t(c[1]) << 8) | c[2];
    }
  cairo_surface_mark_dirty(img.get());
  cairo_save(cr);
  cairo_translate(cr, f.x0, f.y0);
  cairo_scale(cr, f.s, f.s);
  cairo_set_source_surface(cr, img.get(), 0, 0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_rectangle(cr, 0, 0, g.nx, g.ny);
  cairo_fill(cr);
  cairo_restore(cr);
}

// The edges between cells inside and outside, as one path (cell j = 0 is the southern row).
void draw_edges(cairo_t* cr, const Frame& f, const std::function<bool(int, int)>& inside, const Rgb& c, double width, bool halo,
                bool dashed) {
  const Grid& g = f.g;
  auto in = [&](int i, int j) { return i >= 0 && j >= 0 && i < g.nx && j < g.ny && inside(i, j); };
  auto X = [&](int i) { return f.x0 + i * f.s; };
  auto Y = [&](int j) { return f.y0 + (g.ny - j) * f.s; };
  for (int j = 0; j <= g.ny; ++j)
    for (int i = 0; i <= g.nx; ++i) {
      if (j < g.ny && in(i - 1, j) != in(i, j)) {
        cairo_move_to(cr, X(i), Y(j));
        cairo_line_to(cr, X(i), Y(j + 1));
      }
      if (i < g.nx && in(i, j - 1) != in(i, j)) {
        cairo_move_to(cr, X(i), Y(j));
        cairo_line_to(cr, X(i + 1), Y(j));
      }
    }
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_SQUARE);
  if (halo) {  // a white edge first: a boundary stays visible on a fill of its own colour
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_set_line_width(cr, width + 2);
    cairo_stroke_preserve(cr);
  }
  stroke(cr, c, width, dashed);
}

void draw_contours(cairo_t* cr, const Frame& f, const std::vector<Contour>& cs, double interval) {
  cairo_save(cr);
  cairo_rectangle(cr, f.x0, f.y0, f.g.nx * f.s, f.g.ny * f.s);
  cairo_clip(cr);
  for (const auto& c : cs) {
    if (c.xy.size() < 2) continue;
    const bool index = std::fmod(std::fabs(c.elevation), 5 * interval) < 1e-6 * interval;
    cairo_move_to(cr, f.px(c.xy[0].first), f.py(c.xy[0].second));
    for (std::size_t k = 1; k < c.xy.size(); ++k) cairo_line_to(cr, f.px(c.xy[k].first), f.py(c.xy[k].second));
    colour(cr, kContour, index ? 0.7 : 0.4);
    cairo_set_line_width(cr, index ? 1.0 : 0.5);
    cairo_stroke(cr);
  }
  cairo_restore(cr);
}

void draw_area_edges(cairo_t* cr, const Frame& f, const HazardMap& m, double w) {
  const Grid& g = f.g;
  for (const auto& b : m.boundaries)
    for (std::size_t k = 0; k < b.palette.classes.size(); ++k)
      draw_edges(cr, f, [&](int i, int j) { return b.cls[std::size_t(j) * g.nx + i] >= k + 1; }, rgb(b.palette.classes[k].colour), 2.5 * w, true);
  if (!m.max_depth.empty())
    draw_edges(cr, f, [&](int i, int j) { return m.max_depth[std::size_t(j) * g.nx + i] > m.outline_threshold; }, kOutline, 1.6 * w);
  if (!m.release.empty())
    draw_edges(cr, f, [&](int i, int j) { return m.release[std::size_t(j) * g.nx + i] > 0; }, kRelease, 1.6 * w, true, true);
  if (!m.resistance.empty())
    draw_edges(cr, f, [&](int i, int j) { return m.resistance[std::size_t(j) * g.nx + i] != 0; }, kForest, 1.6 * w, true, true);
  if (!m.cover.empty())
    draw_edges(cr, f, [&](int i, int j) { return m.cover[std::size_t(j) * g.nx + i] != 0; }, kCover, 1.6 * w, true, true);
  if (!m.dams.empty())
    draw_edges(cr, f, [&](int i, int j) { return m.dams[std::size_t(j) * g.nx + i] != 0; }, kDam, 2.2 * w, true);
  if (!m.nest.empty()) {
    const double dash[] = {4 * w, 3 * w};
    cairo_set_dash(cr, dash, 2, 0);
    draw_edges(cr, f, [&](int i, int j) { return m.nest[std::size_t(j) * g.nx + i] != 0; }, kPath, 1.6 * w, false);
    cairo_set_dash(cr, nullptr, 0, 0);
  }
  if (!m.structures.empty())
    draw_edges(cr, f, [&](int i, int j) { return m.structures[std::size_t(j) * g.nx + i] != 0; }, kInk, 2.2 * w, true);
}

// Ticks with coordinates in the grid's CRS on the map's lower and left edges.
void draw_ticks(cairo_t* cr, const Frame& f, MapLayout& lay) {
  const Grid& g = f.g;
  const double w = g.nx * g.dx, h = g.ny * g.dx, step = nice_step(std::max(w, h), 5);
  const double bottom = f.y0 + g.ny * f.s;
  colour(cr, kInk);
  cairo_set_line_width(cr, 1);
  for (double x = std::ceil(g.x_min / step) * step; x <= g.x_min + w; x += step) {
    cairo_move_to(cr, f.px(x), bottom);
    cairo_line_to(cr, f.px(x), bottom + 6);
    cairo_stroke(cr);
    lay.unknown_glyphs += draw_text(cr, f.px(x), bottom + 8, label_number(x, true), {11, false, kInk, -1, 0, 1}).unknown_glyphs;
  }
  for (double y = std::ceil(g.y_min / step) * step; y <= g.y_min + h; y += step) {
    cairo_move_to(cr, f.x0, f.py(y));
    cairo_line_to(cr, f.x0 - 6, f.py(y));
    cairo_stroke(cr);
    lay.unknown_glyphs += draw_text(cr, f.x0 - 24, f.py(y), label_number(y, true), {11, false, kInk, -1, 90, 1}).unknown_glyphs;
  }
}

bool overlap(const Box& a, const Box& b) {
  return a[0] < b[0] + b[2] && b[0] < a[0] + a[2] && a[1] < b[1] + b[3] && b[1] < a[1] + a[3];
}
bool within(const Box& a, const Box& frame) {
  return a[0] >= frame[0] && a[1] >= frame[1] && a[0] + a[2] <= frame[0] + frame[2] && a[1] + a[3] <= frame[1] + frame[3];
}

bool LabelPlacer::free(const Box& b) const {
  if (!within(b, frame)) return false;
  return std::none_of(boxes.begin(), boxes.end(), [&](const Box& o) { return overlap(b, o); });
}


// Whether a label's box crosses the outline (cells under it both inside and outside).
bool crosses_outline(const Frame& f, const HazardMap& m, const Box& b) {
  if (m.max_depth.empty()) return false;
  const Grid& g = f.g;
  bool in = false, out = false;
  for (double y = b[1]; y <= b[1] + b[3]; y += std::max(1.0, f.s / 2))
    for (double x = b[0]; x <= b[0] + b[2]; x += std::max(1.0, f.s / 2)) {
      const int i = int(std::floor((x - f.x0) / f.s)), j = g.ny - 1 - int(std::floor((y - f.y0) / f.s));
      if (i < 0 || j < 0 || i >= g.nx || j >= g.ny) continue;
      (m.max_depth[std::size_t(j) * g.nx + i] > m.outline_threshold ? in : out) = true;
    }
  return in && out;
}

// A point's label: beside the point (right, left, above, below), else moved further out with a
// leader line; the first place that overlaps no label, preferring places off the outline's line.
// Returns 1 when a leader line was drawn, 0 when placed beside, -1 when no place was free.
int place_label(cairo_t* cr, const Frame& f, const HazardMap& m, double px, double py, const std::string& text, const TextStyle& style,
                LabelPlacer& labels, int& unknown) {
  const auto size = draw_text(nullptr, 0, 0, text, style);
  const double w = size.w, h = size.h;
  std::vector<std::pair<Box, bool>> candidates = {{{px + 7, py - h / 2, w, h}, false},
                                                  {{px - 7 - w, py - h / 2, w, h}, false},
                                                  {{px - w / 2, py - 7 - h, w, h}, false},
                                                  {{px - w / 2, py + 7, w, h}, false}};
  for (double r : {30.0, 55.0, 85.0})
    for (int a = 0; a < 8; ++a) {
      const double dx = std::cos(a * M_PI / 4), dy = -std::sin(a * M_PI / 4);
      const double cx = px + r * dx, cy = py + r * dy;
      candidates.push_back({{dx >= 0 ? cx : cx - w, cy - h / 2, w, h}, true});
    }
  const std::pair<Box, bool>* chosen = nullptr;
  for (int pass = 0; pass < 2 && !chosen; ++pass)  // off the outline's line first, then anywhere free
    for (const auto& c : candidates)
      if (labels.free(c.first) && (pass == 1 || !crosses_outline(f, m, c.first))) {
        chosen = &c;
        break;
      }
  if (!chosen) return -1;
  const Box& b = chosen->first;
  if (chosen->second) {  // the leader line from the point to the label's nearer side
    cairo_new_path(cr);
    cairo_move_to(cr, px, py);
    cairo_line_to(cr, b[0] + (b[0] > px ? 0 : b[2]), b[1] + b[3] / 2);
    stroke(cr, kInk, 0.6);
  }
  cairo_set_source_rgba(cr, 1, 1, 1, 0.8);
  cairo_rectangle(cr, b[0] - 1, b[1], b[2] + 2, b[3]);
  cairo_fill(cr);
  unknown += draw_text(cr, b[0], b[1], text, style).unknown_glyphs;
  labels.boxes.push_back(b);
  return chosen->second ? 1 : 0;
}

void scale_bar(cairo_t* cr, double x, double y, double length, double height) {
  colour(cr, kInk);
  cairo_rectangle(cr, x, y, length, height);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_rectangle(cr, x + length / 2, y + 1, length / 2 - 1, height - 2);
  cairo_fill(cr);
}

std::string length_label(double metres) { return metres >= 1000 ? label_number(metres / 1000) + " km" : label_number(metres) + " m"; }

// A scale bar under the map, and the CRS beside it.
void draw_scale(cairo_t* cr, const Frame& f, MapLayout& lay) {
  const Grid& g = f.g;
  const double len = nice_step(g.nx * g.dx, 4), bar = len / g.dx * f.s, x = f.x0, y = f.y0 + g.ny * f.s + 34;
  scale_bar(cr, x, y, bar, 7);
  lay.unknown_glyphs += draw_text(cr, x + bar + 8, y - 4, length_label(len), {11, false, kInk}).unknown_glyphs;
  lay.unknown_glyphs += draw_text(cr, x, y + 12, g.crs_name + ", cells of " + label_number(g.dx) + " m", {11, false, kInk}).unknown_glyphs;
}

void draw_point(cairo_t* cr, double x, double y) {
  cairo_new_path(cr);
  cairo_arc(cr, x, y, 4.5, 0, 2 * M_PI);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_fill_preserve(cr);
  colour(cr, kInk);
  cairo_set_line_width(cr, 2);
  cairo_stroke(cr);
}

void legend_line(cairo_t* cr, double x, double y, const Rgb& c, double width, bool dashed = false) {
  if (!cr) return;
  cairo_new_path(cr);
  cairo_move_to(cr, x, y);
  cairo_line_to(cr, x + 28, y);
  stroke(cr, c, width, dashed);
}

// The right-hand panel: colour bar, line legend, north arrow, parameters. A null `cr` only
// measures; returns the panel's bottom.
double draw_panel(cairo_t* cr, double x, double y, const HazardMap& m, double contour_interval, MapLayout& lay) {
  const TextStyle head{14, true, kInk, kPanel}, body{12, false, kInk, kPanel - 38};
  auto text = [&](double tx, double ty, const std::string& s, const TextStyle& st) {
    const auto b = draw_text(cr, tx, ty, s, st);
    lay.unknown_glyphs += b.unknown_glyphs;
    return b.h;
  };
  y += text(x, y, m.palette.title + (m.palette.unit.empty() ? "" : " [" + m.palette.unit + "]"), head) + 8;
  for (const auto& c : m.palette.classes) {
    if (cr) {
      cairo_set_source_rgb(cr, c.colour[0] / 255.0, c.colour[1] / 255.0, c.colour[2] / 255.0);
      cairo_rectangle(cr, x, y, 28, 20);
      cairo_fill(cr);
      lay.swatches.push_back({x, y, 28, 20});
    }
    const double h = text(x + 38, y + 2, c.label, body);
    y += std::max(24.0, h + 6);
  }
  if (m.show_maximum) {
    double top = -HUGE_VAL;
    for (double v : m.values)
      if (std::isfinite(v)) top = std::max(top, v);
    char four[32];  // four significant digits
    std::snprintf(four, sizeof four, "%.4g", top);
    if (std::isfinite(top))
      y += text(x, y + 2, "maximum " + label_number(std::strtod(four, nullptr)) + (m.palette.unit.empty() ? "" : " " + m.palette.unit), body) + 6;
  }
  if (!m.colour_note.empty()) y += text(x, y + 2, m.colour_note, {12, false, kInk, kPanel}) + 6;
  y += 10;
  auto item = [&](const std::string& label, const std::function<void(double)>& symbol) {
    if (cr) symbol(y + 9);
    const double h = text(x + 38, y + 1, label, body);
    y += std::max(22.0, h + 6);
  };
  if (!m.release.empty()) item("release", [&](double yy) { legend_line(cr, x, yy, kRelease, 2, true); });
  if (!m.resistance.empty()) item("resistance area (forest)", [&](double yy) { legend_line(cr, x, yy, kForest, 2, true); });
  if (!m.cover.empty()) item("erodible cover (entrainment)", [&](double yy) { legend_line(cr, x, yy, kCover, 2, true); });
  if (!m.dams.empty()) item("dam or wall", [&](double yy) { legend_line(cr, x, yy, kDam, 3); });
  if (!m.structures.empty()) item("structure", [&](double yy) { legend_line(cr, x, yy, kInk, 3); });
  if (!m.nest.empty()) item("3D nest: values inside from the 3D engine", [&](double yy) { legend_line(cr, x, yy, kPath, 2); });
  if (!m.max_depth.empty())
    item("outline: max depth > " + label_number(m.outline_threshold) + " m", [&](double yy) { legend_line(cr, x, yy, kOutline, 2); });
  for (const auto& b : m.boundaries)
    for (const auto& c : b.palette.classes) item(c.label, [&](double yy) { legend_line(cr, x, yy, rgb(c.colour), 2.5); });
  if (contour_interval > 0)
    item("contours every " + label_number(contour_interval) + " m", [&](double yy) { legend_line(cr, x, yy, kContour, 1); });
  if (!m.path.empty()) item("path (runout point, beta point)", [&](double yy) { legend_line(cr, x, yy, kPath, 2, true); });
  if (!m.points.empty()) item("point of interest", [&](double yy) { draw_point(cr, x + 14, yy); });
  // North arrow (the grid is north-up).
  y += 8;
  if (cr) {
    colour(cr, kInk);
    cairo_move_to(cr, x + 14, y + 16);
    cairo_line_to(cr, x + 4, y + 44);
    cairo_line_to(cr, x + 14, y + 36);
    cairo_line_to(cr, x + 24, y + 44);
    cairo_close_path(cr);
    cairo_fill(cr);
  }
  text(x + 14, y - 2, "N", {14, true, kInk, -1, 0, 1});
  y += 58;
  if (!m.parameters.empty()) {
    y += text(x, y, "Parameters", head) + 4;
    for (const auto& p : m.parameters) y += text(x, y, p, {11, false, kInk, kPanel}) + 2;
  }
  return y;
}

}  // namespace detail

using namespace detail;

std::vector<double> inside_outline(const std::vector<double>& values, const std::vector<double>& max_depth, double threshold) {
  std::vector<double> v = values;
  for (std::size_t k = 0; k < v.size() && k < max_depth.size(); ++k)
    if (!(max_depth[k] > threshold)) v[k] = NAN;
  return v;
}

MapLayout draw_hazard_map(const std::string& png_path, const std::string& pdf_path, const Grid& g, const HazardMap& m) {
  GDALAllRegister();
  auto dem = dem_raster(g);
  const auto shade = hillshade(*dem, g);
  const auto [zmin, zmax] = std::minmax_element(g.z.begin(), g.z.end());
  MapLayout lay;
  lay.contour_interval_m = nice_step(*zmax - *zmin, 12);
  const auto lines = contours(*dem, lay.contour_interval_m);
  if (lines.empty()) lay.contour_interval_m = 0;  // flat ground (or none given): no contours, none in the legend

  // Page layout: the title over the whole width, the map, the panel to its right.
  const double s = std::clamp(std::min(900.0 / g.nx, 800.0 / g.ny), 0.2, 8.0), mw = g.nx * s, mh = g.ny * s;
  const double width = kLeft + mw + kGap + kPanel + kRight;
  const TextStyle title{20, true, kInk, width - 40};
  const auto tb = draw_text(nullptr, 20, 14, m.title, title);
  const double top = 14 + tb.h + 22;
  MapLayout probe;
  const double panel_bottom = draw_panel(nullptr, kLeft + mw + kGap, top, m, lay.contour_interval_m, probe);
  const double height = std::max(top + mh + kBottom, panel_bottom + 20);
  lay.width = int(std::ceil(width));
  lay.height = int(std::ceil(height));
  lay.map_x = kLeft;
  lay.map_y = top;
  lay.cell_px = s;

  auto draw = [&](cairo_t* cr) {
    MapLayout l = lay;
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    const auto t = draw_text(cr, 20, 14, m.title, title);
    l.title = {t.x, t.y, t.w, t.h};
    l.title_lines = t.lines;
    l.unknown_glyphs += t.unknown_glyphs;
    const Frame f{g, kLeft, top, s};
    draw_cells(cr, f, m, shade);
    draw_contours(cr, f, lines, lay.contour_interval_m);
    draw_area_edges(cr, f, m, 1.0);
    if (m.path.size() >= 2) {
      cairo_new_path(cr);
      for (std::size_t k = 0; k < m.path.size(); ++k)
        (k ? cairo_line_to : cairo_move_to)(cr, f.px(m.path[k].first), f.py(m.path[k].second));
      stroke(cr, kPath, 2, true);
      for (const auto& p : m.path_marks) {
        cairo_new_path(cr);
        cairo_arc(cr, f.px(p.x), f.py(p.y), 4, 0, 2 * M_PI);
        colour(cr, kPath);
        cairo_fill(cr);
      }
    }
    for (const auto& p : m.points) draw_point(cr, f.px(p.x), f.py(p.y));
    // The labels where no two overlap and, where it can be, off the outline's line (points first).
    LabelPlacer labels{{kLeft, top, mw, mh}, {}};
    for (const auto* marks : {&m.points, &m.path_marks})
      for (const auto& p : *marks) labels.boxes.push_back({f.px(p.x) - 5, f.py(p.y) - 5, 10, 10});
    for (const auto& p : m.points) place_label(cr, f, m, f.px(p.x), f.py(p.y), p.name, {12, true, kInk}, labels, l.unknown_glyphs);
    if (m.path.size() >= 2)
      for (const auto& p : m.path_marks) place_label(cr, f, m, f.px(p.x), f.py(p.y), p.name, {11, false, kPath}, labels, l.unknown_glyphs);
    const std::size_t symbols = m.points.size() + m.path_marks.size();
    l.label_boxes.assign(labels.boxes.begin() + std::ptrdiff_t(symbols), labels.boxes.end());
    colour(cr, kInk);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, kLeft, top, mw, mh);
    cairo_stroke(cr);
    draw_ticks(cr, f, l);
    draw_scale(cr, f, l);
    draw_panel(cr, kLeft + mw + kGap, top, m, lay.contour_interval_m, l);
    return l;
  };
  MapLayout out = lay;
  if (!png_path.empty()) {
    std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surf(
        cairo_image_surface_create(CAIRO_FORMAT_RGB24, lay.width, lay.height), cairo_surface_destroy);
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surf.get()), cairo_destroy);
    out = draw(cr.get());
    if (cairo_surface_write_to_png(surf.get(), png_path.c_str()) != CAIRO_STATUS_SUCCESS)
      throw TerrainError("writing '" + png_path + "' failed");
  }
  if (!pdf_path.empty()) {
    std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surf(cairo_pdf_surface_create(pdf_path.c_str(), width, height),
                                                                            cairo_surface_destroy);
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surf.get()), cairo_destroy);
    const auto l = draw(cr.get());
    if (png_path.empty()) out = l;
    cairo_surface_finish(surf.get());
    if (cairo_surface_status(surf.get()) != CAIRO_STATUS_SUCCESS) throw TerrainError("writing '" + pdf_path + "' failed");
  }
  return out;
}

}  // namespace runout::figures
