#pragma once
// The drawing room's pen: UTF-8 text with Pango (real fonts, wrapping, measured extents), round
// tick steps and number labels, for every figure drawn with Cairo.
#include <cairo.h>

#include <functional>
#include <string>
#include <vector>

namespace runout::figures {

struct Rgb {
  double r = 0, g = 0, b = 0;
};

/// What a piece of text took on the page.
struct TextBox {
  double x = 0, y = 0, w = 0, h = 0;
  int unknown_glyphs = 0;  ///< characters the font could not draw (0: every character shown)
  int lines = 1;
};

struct TextStyle {
  double size = 12;       ///< [device units: pixels in a PNG, points in a PDF]
  bool bold = false;
  Rgb colour{};
  double wrap_width = -1;  ///< wrap at words beyond this width; -1: one line
  double angle_deg = 0;    ///< counter-clockwise about (x, y)
  int align = 0;           ///< 0 left, 1 centre, 2 right of x
};

/// Draw `text` (UTF-8) with its top-left (or top-centre, top-right) at (x, y); returns its box.
/// With a null `cr` it only measures.
TextBox draw_text(cairo_t* cr, double x, double y, const std::string& text, const TextStyle& style);

/// A round step (1, 2 or 5 times a power of ten) that cuts `span` into about `parts` parts.
double nice_step(double span, int parts);

/// A number for labels: no trailing zeros, thousands apart with thin spaces when `grouped`.
std::string label_number(double v, bool grouped = false);

/// Stroke the current path in `c`, solid or dashed (4 on, 3 off), `width` wide.
void stroke(cairo_t* cr, const Rgb& c, double width, bool dashed = false);

/// Draw a page of `width` x `height` with `draw` into a PNG (pixels) and a PDF (points); either path
/// may be empty. Throws std::runtime_error naming the file that cannot be written.
void render_png_pdf(const std::string& png_path, const std::string& pdf_path, double width, double height,
                    const std::function<void(cairo_t*)>& draw);

}  // namespace runout::figures
