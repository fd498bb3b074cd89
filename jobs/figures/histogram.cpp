#include "jobs/figures/histogram.hpp"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "jobs/figures/pen.hpp"

namespace runout::figures {
namespace {

constexpr double kW = 900, kH = 520, kLeft = 80, kRight = 30, kBottom = 70;
const Rgb kInk{0.1, 0.1, 0.1}, kBar{0.99, 0.55, 0.24}, kMark{0.75, 0.0, 0.1};

void draw(cairo_t* cr, const Histogram& h, double top) {
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  draw_text(cr, 20, 12, h.title, {18, true, kInk, kW - 40});
  draw_text(cr, 20, top - 26, h.note, {12, false, kInk, kW - 40});
  const Bins b = histogram_bins(h.values);
  const double x0 = kLeft, y0 = top, w = kW - kLeft - kRight, ht = kH - top - kBottom;
  const double lo = b.start, hi = b.start + b.width * double(std::max<std::size_t>(1, b.counts.size()));
  const int cmax = b.counts.empty() ? 1 : std::max(1, *std::max_element(b.counts.begin(), b.counts.end()));
  auto px = [&](double v) { return x0 + (v - lo) / (hi - lo) * w; };
  auto py = [&](double c) { return y0 + ht - c / (cmax * 1.08) * ht; };
  for (std::size_t k = 0; k < b.counts.size(); ++k) {
    const double a = px(lo + double(k) * b.width), c = px(lo + double(k + 1) * b.width);
    cairo_rectangle(cr, a + 1, py(b.counts[k]), c - a - 2, y0 + ht - py(b.counts[k]));
    cairo_set_source_rgb(cr, kBar.r, kBar.g, kBar.b);
    cairo_fill(cr);
  }
  cairo_set_source_rgb(cr, kInk.r, kInk.g, kInk.b);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, x0, y0, w, ht);
  cairo_stroke(cr);
  const double sc = nice_step(cmax, 5);
  for (double c = 0; c <= cmax * 1.08 + 1e-9; c += std::max(1.0, sc)) {
    cairo_move_to(cr, x0 - 5, py(c));
    cairo_line_to(cr, x0, py(c));
    cairo_stroke(cr);
    draw_text(cr, x0 - 8, py(c) - 7, label_number(c), {11, false, kInk, -1, 0, 2});
  }
  draw_text(cr, 18, y0 + ht / 2 + 30, "members", {12, false, kInk, -1, 90});
  const double sx = nice_step(hi - lo, 7);
  for (double v = std::ceil(lo / sx) * sx; v <= hi + 1e-9; v += sx) {
    cairo_move_to(cr, px(v), y0 + ht);
    cairo_line_to(cr, px(v), y0 + ht + 5);
    cairo_stroke(cr);
    draw_text(cr, px(v), y0 + ht + 7, label_number(v, true), {11, false, kInk, -1, 0, 1});
  }
  draw_text(cr, x0 + w / 2, y0 + ht + 28, h.x_label, {12, false, kInk, -1, 0, 1});
  for (const auto& [name, v] : h.marks) {
    if (!std::isfinite(v)) continue;
    cairo_move_to(cr, px(v), y0);
    cairo_line_to(cr, px(v), y0 + ht);
    stroke(cr, kMark, 1.2, true);
    draw_text(cr, px(v) + 3, y0 + 4, name, {11, false, kMark});
  }
}

}  // namespace

Bins histogram_bins(const std::vector<double>& values) {
  std::vector<double> v;
  for (double x : values)
    if (std::isfinite(x)) v.push_back(x);
  Bins b;
  if (v.empty()) return b;
  const auto [mn, mx] = std::minmax_element(v.begin(), v.end());
  const int want = std::clamp(int(std::lround(std::sqrt(double(v.size())))), 5, 30);
  b.width = *mx > *mn ? nice_step(*mx - *mn, want) : 1.0;
  b.start = std::floor(*mn / b.width) * b.width;
  const std::size_t n = std::size_t(std::floor((*mx - b.start) / b.width)) + 1;
  b.counts.assign(n, 0);
  for (double x : v) ++b.counts[std::min(n - 1, std::size_t(std::floor((x - b.start) / b.width)))];
  return b;
}

void draw_histogram(const std::string& png_path, const std::string& pdf_path, const Histogram& h) {
  const double top = 14 + draw_text(nullptr, 20, 12, h.title, {18, true, kInk, kW - 40}).h + 40;
  render_png_pdf(png_path, pdf_path, kW, kH, [&](cairo_t* cr) { draw(cr, h, top); });
}

}  // namespace runout::figures
