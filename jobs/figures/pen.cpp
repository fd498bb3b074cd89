#include "jobs/figures/pen.hpp"

#include <stdexcept>

#include <cairo-pdf.h>

#include <pango/pangocairo.h>

#include <cmath>
#include <cstdio>
#include <memory>

namespace runout::figures {

TextBox draw_text(cairo_t* cr, double x, double y, const std::string& text, const TextStyle& st) {
  // Measuring without a page: a tiny image surface stands in.
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> scratch(nullptr, cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> scratch_cr(nullptr, cairo_destroy);
  const bool measure_only = cr == nullptr;
  if (measure_only) {
    scratch.reset(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 1, 1));
    scratch_cr.reset(cairo_create(scratch.get()));
    cr = scratch_cr.get();
  }
  PangoLayout* layout = pango_cairo_create_layout(cr);
  PangoFontDescription* font = pango_font_description_from_string(st.bold ? "DejaVu Sans Bold" : "DejaVu Sans");
  pango_font_description_set_absolute_size(font, st.size * PANGO_SCALE);
  pango_layout_set_font_description(layout, font);
  pango_font_description_free(font);
  if (st.wrap_width > 0) {
    pango_layout_set_width(layout, int(st.wrap_width * PANGO_SCALE));
    pango_layout_set_wrap(layout, PANGO_WRAP_WORD_CHAR);
  }
  pango_layout_set_text(layout, text.c_str(), -1);
  int w = 0, h = 0;
  pango_layout_get_pixel_size(layout, &w, &h);
  TextBox box;
  box.w = w;
  box.h = h;
  box.unknown_glyphs = pango_layout_get_unknown_glyphs_count(layout);
  box.lines = pango_layout_get_line_count(layout);
  const double dx = st.align == 1 ? -0.5 * w : st.align == 2 ? -double(w) : 0.0;
  box.x = x + dx;
  box.y = y;
  if (!measure_only) {
    cairo_save(cr);
    cairo_translate(cr, x, y);
    if (st.angle_deg != 0) cairo_rotate(cr, -st.angle_deg * M_PI / 180.0);
    cairo_move_to(cr, dx, 0);
    cairo_set_source_rgb(cr, st.colour.r, st.colour.g, st.colour.b);
    pango_cairo_show_layout(cr, layout);
    cairo_new_path(cr);  // no current point left for the next shape to start from
    cairo_restore(cr);
  }
  g_object_unref(layout);
  return box;
}

double nice_step(double span, int parts) {
  if (!(span > 0) || parts < 1) return 1;
  const double raw = span / parts, p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double f : {1.0, 2.0, 5.0, 10.0})
    if (f * p >= raw) return f * p;
  return 10 * p;
}

std::string label_number(double v, bool grouped) {
  char b[64];
  // Coordinates keep every digit (a northing of 5 187 000 m, not 5.19e+06).
  std::snprintf(b, sizeof b, std::fabs(v) >= 1e5 && std::fabs(v) < 1e10 ? "%.10g" : "%.6g", v);
  std::string s = b;
  if (!grouped || std::fabs(v) < 10000 || s.find_first_of(".e") != std::string::npos) return s;
  std::string out;
  const std::size_t start = s[0] == '-' ? 1 : 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (k > start && (s.size() - k) % 3 == 0) out += "\u2009";  // thin space
    out += s[k];
  }
  return out;
}

void stroke(cairo_t* cr, const Rgb& c, double width, bool dashed) {
  const double dash[] = {4, 3};
  cairo_set_dash(cr, dash, dashed ? 2 : 0, 0);
  cairo_set_source_rgb(cr, c.r, c.g, c.b);
  cairo_set_line_width(cr, width);
  cairo_stroke(cr);
  cairo_set_dash(cr, nullptr, 0, 0);
}

void render_png_pdf(const std::string& png_path, const std::string& pdf_path, double width, double height,
                    const std::function<void(cairo_t*)>& draw) {
  if (!png_path.empty()) {
    std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> s(
        cairo_image_surface_create(CAIRO_FORMAT_RGB24, int(std::ceil(width)), int(std::ceil(height))), cairo_surface_destroy);
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(s.get()), cairo_destroy);
    draw(cr.get());
    if (cairo_surface_write_to_png(s.get(), png_path.c_str()) != CAIRO_STATUS_SUCCESS)
      throw std::runtime_error("writing '" + png_path + "' failed");
  }
  if (!pdf_path.empty()) {
    std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> s(cairo_pdf_surface_create(pdf_path.c_str(), width, height),
                                                                         cairo_surface_destroy);
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(s.get()), cairo_destroy);
    draw(cr.get());
    cairo_surface_finish(s.get());
    if (cairo_surface_status(s.get()) != CAIRO_STATUS_SUCCESS) throw std::runtime_error("writing '" + pdf_path + "' failed");
  }
}

}  // namespace runout::figures
