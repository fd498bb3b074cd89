// A hazard map on a report page: the map at a stated scale 1:N with its cells as one raster of the
// page's resolution (300 dpi by default), labelled contours, labels placed so that none overlaps
// another (moved round the point, with a leader line when moved away), ticks, a scale bar and the
// legend panel.
#include <cairo.h>
#include <gdal_priv.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "jobs/figures/hazard_map.hpp"
#include "jobs/figures/map_drawing.hpp"
#include "jobs/figures/pen.hpp"

namespace runout::figures {
using namespace detail;
using terrain::Grid;

namespace {

constexpr double kMetrePerInch = 0.0254;
constexpr int kScales[] = {1000, 2000, 2500, 5000, 10000, 12500, 20000, 25000, 50000, 100000, 200000};

// The cells' raster at the page's resolution: each pixel the colour of the cell under its centre.
std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> cell_image(const Grid& g, const HazardMap& m,
                                                                              const std::vector<std::uint8_t>& shade, const Box& ext,
                                                                              double px_per_m, int w, int h) {
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> img(cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h),
                                                                          cairo_surface_destroy);
  const int stride = cairo_image_surface_get_stride(img.get());
  unsigned char* data = cairo_image_surface_get_data(img.get());
  for (int r = 0; r < h; ++r) {
    const double y = ext[1] + ext[3] - (r + 0.5) / px_per_m;
    const int j = std::clamp(int(std::floor((y - g.y_min) / g.dx)), 0, g.ny - 1);
    for (int c = 0; c < w; ++c) {
      const double x = ext[0] + (c + 0.5) / px_per_m;
      const int i = std::clamp(int(std::floor((x - g.x_min) / g.dx)), 0, g.nx - 1);
      const std::size_t k = std::size_t(j) * g.nx + i;
      const Rgb8 col = cell_colour(g, m, k, shade[std::size_t(g.ny - 1 - j) * g.nx + i] / 255.0);
      reinterpret_cast<std::uint32_t*>(data + std::size_t(r) * stride)[c] = (std::uint32_t(col[0]) << 16) | (std::uint32_t(col[1]) << 8) | col[2];
    }
  }
  cairo_surface_mark_dirty(img.get());
  return img;
}

// Index contours' elevations along their lines, every 180 points or more, where they overlap no label.
int label_contours(cairo_t* cr, const Frame& f, const std::vector<Contour>& cs, double interval, LabelPlacer& labels) {
  int placed = 0;
  const TextStyle style{7, false, kContour};
  for (const auto& c : cs) {
    if (std::fmod(std::fabs(c.elevation), 5 * interval) > 1e-6 * interval || c.xy.size() < 2) continue;
    const std::string text = label_number(c.elevation);
    const auto size = draw_text(nullptr, 0, 0, text, style);
    double since = 90, per_line = 0;
    for (std::size_t k = 1; k < c.xy.size() && per_line < 3; ++k) {
      const double x = f.px(c.xy[k].first), y = f.py(c.xy[k].second);
      since += std::hypot(x - f.px(c.xy[k - 1].first), y - f.py(c.xy[k - 1].second));
      if (since < 180) continue;
      const Box b{x - size.w / 2 - 1, y - size.h / 2, size.w + 2, size.h};
      if (!labels.free(b)) continue;
      cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
      cairo_rectangle(cr, b[0], b[1], b[2], b[3]);
      cairo_fill(cr);
      draw_text(cr, x, b[1], text, {7, false, kContour, -1, 0, 1});
      labels.boxes.push_back(b);
      since = 0;
      ++per_line;
      ++placed;
    }
  }
  return placed;
}

// The scale 1:N at which the extent fits the room.
int choose_scale(double ext_w, double ext_h, double room_w, double room_h) {
  for (int n : kScales) {
    const double ppm = 72 / kMetrePerInch / n;
    if (ext_w * ppm <= room_w && ext_h * ppm <= room_h) return n;
  }
  return 0;
}

// Coordinate ticks on the frame's lower and left edges, a scale bar with the scale under it.
void draw_frame_furniture(cairo_t* cr, const Box& fr, const Box& ext, double ppm, int scale, const Grid& g, int& unknown) {
  cairo_save(cr);
  colour(cr, kInk);
  cairo_set_line_width(cr, 0.8);
  cairo_rectangle(cr, fr[0], fr[1], fr[2], fr[3]);
  cairo_stroke(cr);
  const double step = nice_step(std::max(ext[2], ext[3]), 5);
  const TextStyle tick{7, false, kInk, -1, 0, 1};
  for (double x = std::ceil(ext[0] / step) * step; x <= ext[0] + ext[2]; x += step) {
    const double X = fr[0] + (x - ext[0]) * ppm;
    cairo_move_to(cr, X, fr[1] + fr[3]);
    cairo_line_to(cr, X, fr[1] + fr[3] + 4);
    cairo_stroke(cr);
    unknown += draw_text(cr, X, fr[1] + fr[3] + 5, label_number(x, true), tick).unknown_glyphs;
  }
  for (double y = std::ceil(ext[1] / step) * step; y <= ext[1] + ext[3]; y += step) {
    const double Y = fr[1] + (ext[1] + ext[3] - y) * ppm;
    cairo_move_to(cr, fr[0], Y);
    cairo_line_to(cr, fr[0] - 4, Y);
    cairo_stroke(cr);
    unknown += draw_text(cr, fr[0] - 14, Y, label_number(y, true), {7, false, kInk, -1, 90, 1}).unknown_glyphs;
  }
  const double len = nice_step(ext[2], 4), bar = len * ppm, bx = fr[0], by = fr[1] + fr[3] + 20;
  scale_bar(cr, bx, by, bar, 5);
  unknown += draw_text(cr, bx + bar + 6, by - 3, length_label(len) + "     scale 1:" + label_number(scale, true) + " (on the page as printed)",
                       {8, false, kInk})
                 .unknown_glyphs;
  unknown += draw_text(cr, bx, by + 8, g.crs_name + ", cells of " + label_number(g.dx) + " m", {7, false, kInk}).unknown_glyphs;
  cairo_restore(cr);
}

}  // namespace

MapPageLayout draw_map_page(cairo_t* cr, const Grid& g, const HazardMap& m, const MapPageSpec& spec) {
  GDALAllRegister();  // the DEM's in-memory raster, hillshade and contours
  MapPageLayout lay;
  Box ext = {spec.extent[0], spec.extent[1], spec.extent[2] - spec.extent[0], spec.extent[3] - spec.extent[1]};
  if (!(ext[2] > 0 && ext[3] > 0)) ext = {g.x_min, g.y_min, g.nx * g.dx, g.ny * g.dx};
  lay.scale = choose_scale(ext[2], ext[3], spec.w, spec.h);
  if (lay.scale == 0) throw terrain::TerrainError("report: the map's extent does not fit the page at 1:200 000");
  const double ppm = 72 / kMetrePerInch / lay.scale, px_per_m = spec.dpi / kMetrePerInch / lay.scale;
  const Box fr = {spec.x, spec.y, ext[2] * ppm, ext[3] * ppm};
  lay.frame = fr;
  auto dem = dem_raster(g);
  const auto shade = hillshade(*dem, g);
  const auto [zmin, zmax] = std::minmax_element(g.z.begin(), g.z.end());
  double interval = nice_step(*zmax - *zmin, 12);
  const auto lines = contours(*dem, interval);
  if (lines.empty()) interval = 0;
  const Frame f{g, fr[0] - (ext[0] - g.x_min) / g.dx * (g.dx * ppm), fr[1] - (g.y_min + g.ny * g.dx - ext[1] - ext[3]) / g.dx * (g.dx * ppm),
                g.dx * ppm};
  // The cells: one raster of the page's resolution.
  lay.image_w = int(std::ceil(ext[2] * px_per_m));
  lay.image_h = int(std::ceil(ext[3] * px_per_m));
  const auto img = cell_image(g, m, shade, ext, px_per_m, lay.image_w, lay.image_h);
  cairo_save(cr);
  cairo_rectangle(cr, fr[0], fr[1], fr[2], fr[3]);
  cairo_clip(cr);
  cairo_save(cr);
  cairo_translate(cr, fr[0], fr[1]);
  cairo_scale(cr, 72 / spec.dpi, 72 / spec.dpi);
  cairo_set_source_surface(cr, img.get(), 0, 0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_paint(cr);
  cairo_restore(cr);
  draw_contours(cr, f, lines, interval);
  draw_area_edges(cr, f, m, 0.5);
  if (m.path.size() >= 2) {
    cairo_new_path(cr);
    for (std::size_t k = 0; k < m.path.size(); ++k) (k ? cairo_line_to : cairo_move_to)(cr, f.px(m.path[k].first), f.py(m.path[k].second));
    stroke(cr, kPath, 1.2, true);
  }
  cairo_restore(cr);
  // The labels: points and path marks first (they matter most), then the contours' elevations.
  LabelPlacer labels{fr, {}};
  auto mark = [&](const MapPoint& p, const TextStyle& st, bool point) {
    const double x = f.px(p.x), y = f.py(p.y);
    if (x < fr[0] || y < fr[1] || x > fr[0] + fr[2] || y > fr[1] + fr[3]) return;
    cairo_new_path(cr);
    if (point) {
      cairo_arc(cr, x, y, 3, 0, 2 * M_PI);
      cairo_set_source_rgb(cr, 1, 1, 1);
      cairo_fill_preserve(cr);
      stroke(cr, kInk, 1.2);
    } else {
      cairo_arc(cr, x, y, 2.5, 0, 2 * M_PI);
      colour(cr, kPath);
      cairo_fill(cr);
    }
    labels.boxes.push_back({x - 3.5, y - 3.5, 7, 7});  // the symbol itself: no label over it
    const int placed = place_label(cr, f, m, x, y, p.name, st, labels, lay.unknown_glyphs);
    lay.leader_lines += placed == 1;
    if (placed >= 0) lay.label_boxes.push_back(labels.boxes.back());
  };
  for (const auto& p : m.points) mark(p, {9, true, kInk}, true);
  for (const auto& p : m.path_marks) mark(p, {8, false, kPath}, false);
  const std::size_t before = labels.boxes.size();
  if (interval > 0) lay.contour_labels = label_contours(cr, f, lines, interval, labels);
  lay.label_boxes.insert(lay.label_boxes.end(), labels.boxes.begin() + std::ptrdiff_t(before), labels.boxes.end());
  draw_frame_furniture(cr, fr, ext, ppm, lay.scale, g, lay.unknown_glyphs);
  // The legend panel, scaled to the page.
  MapLayout panel;
  cairo_save(cr);
  cairo_translate(cr, spec.panel_x, spec.panel_y);
  cairo_scale(cr, spec.panel_scale, spec.panel_scale);
  draw_panel(cr, 0, 0, m, interval, panel);
  cairo_restore(cr);
  lay.unknown_glyphs += panel.unknown_glyphs;
  return lay;
}

}  // namespace runout::figures
