#include "jobs/figures/profile_plot.hpp"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>

#include "jobs/figures/pen.hpp"

namespace runout::figures {
namespace {

constexpr double kW = 900, kLeft = 80, kRight = 30, kPanel = 150, kGap = 34;
const Rgb kInk{0.1, 0.1, 0.1}, kGround{0.45, 0.36, 0.25}, kRunout{0.75, 0.0, 0.1}, kBeta{0.1, 0.35, 0.75};
const Rgb kSeries[] = {{0.8, 0.4, 0.0}, {0.2, 0.5, 0.2}, {0.55, 0.1, 0.45}};

struct Axes {
  double x0, y0, w, h, smax, vmin, vmax;
  double px(double s) const { return x0 + s / smax * w; }
  double py(double v) const { return y0 + h - (v - vmin) / (vmax - vmin) * h; }
};

void frame(cairo_t* cr, const Axes& a, const std::string& label) {
  cairo_set_source_rgb(cr, kInk.r, kInk.g, kInk.b);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, a.x0, a.y0, a.w, a.h);
  cairo_stroke(cr);
  const double sv = nice_step(a.vmax - a.vmin, 4);
  for (double v = std::ceil(a.vmin / sv) * sv; v <= a.vmax + 1e-9; v += sv) {
    cairo_move_to(cr, a.x0 - 5, a.py(v));
    cairo_line_to(cr, a.x0, a.py(v));
    cairo_stroke(cr);
    draw_text(cr, a.x0 - 8, a.py(v) - 7, label_number(v), {11, false, kInk, -1, 0, 2});
  }
  draw_text(cr, a.x0 + 6, a.y0 + 4, label, {12, true, kInk});
}

void polyline(cairo_t* cr, const Axes& a, const std::vector<double>& s, const std::vector<double>& v, const Rgb& c, double width) {
  bool pen = false;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (!std::isfinite(v[k])) {
      pen = false;
      continue;
    }
    if (pen) cairo_line_to(cr, a.px(s[k]), a.py(v[k]));
    else cairo_move_to(cr, a.px(s[k]), a.py(v[k]));
    pen = true;
  }
  cairo_set_source_rgb(cr, c.r, c.g, c.b);
  cairo_set_line_width(cr, width);
  cairo_stroke(cr);
}

void marks(cairo_t* cr, const Axes& a, const ProfilePlot& p) {
  for (auto [s, c] : {std::pair{p.runout_s, kRunout}, {p.beta_s, kBeta}}) {
    if (s < 0) continue;
    cairo_move_to(cr, a.px(s), a.y0);
    cairo_line_to(cr, a.px(s), a.y0 + a.h);
    stroke(cr, c, 1.2, true);
  }
}

void draw(cairo_t* cr, const ProfilePlot& p, double height, double top) {
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  draw_text(cr, 20, 12, p.title, {18, true, kInk, kW - 40});
  draw_text(cr, 20, top - 26, p.note, {12, false, kInk, kW - 40});
  const double smax = std::max(1.0, p.s.empty() ? 1.0 : p.s.back()), w = kW - kLeft - kRight;
  const auto [zlo, zhi] = std::minmax_element(p.z.begin(), p.z.end());
  Axes ground{kLeft, top, w, 1.4 * kPanel, smax, *zlo, std::max(*zhi, *zlo + 1)};
  frame(cr, ground, "ground [m]");
  polyline(cr, ground, p.s, p.z, kGround, 2);
  if (p.runout_s > 0 && !p.z.empty()) {  // the alpha line: from the path's top to the runout point
    cairo_move_to(cr, ground.px(0), ground.py(p.z.front()));
    cairo_line_to(cr, ground.px(p.runout_s), ground.py(p.z.front() - std::tan(p.alpha_deg * M_PI / 180) * p.runout_s));
    cairo_set_source_rgb(cr, kRunout.r, kRunout.g, kRunout.b);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
  }
  marks(cr, ground, p);
  double y = top + ground.h + kGap;
  for (std::size_t q = 0; q < p.series.size(); ++q) {
    double hi = 0;
    for (double v : p.series[q].v)
      if (std::isfinite(v)) hi = std::max(hi, v);
    Axes a{kLeft, y, w, kPanel, smax, 0, hi > 0 ? hi * 1.05 : 1};
    frame(cr, a, p.series[q].label);
    polyline(cr, a, p.s, p.series[q].v, kSeries[q % 3], 1.6);
    marks(cr, a, p);
    y += kPanel + kGap;
  }
  const double ss = nice_step(smax, 6), yb = y - kGap;
  cairo_set_source_rgb(cr, kInk.r, kInk.g, kInk.b);
  for (double s = 0; s <= smax + 1e-9; s += ss) {
    cairo_move_to(cr, ground.px(s), yb);
    cairo_line_to(cr, ground.px(s), yb + 5);
    cairo_stroke(cr);
    draw_text(cr, ground.px(s), yb + 7, label_number(s), {11, false, kInk, -1, 0, 1});
  }
  draw_text(cr, kLeft + w / 2, yb + 24, "distance along the path (horizontal) [m]; dashed: runout point (red), beta point (blue)",
            {12, false, kInk, -1, 0, 1});
  (void)height;
}

}  // namespace

std::pair<double, double> profile_plot_size(const ProfilePlot& p) {
  if (p.s.size() < 2 || p.z.size() != p.s.size()) throw std::runtime_error("profile plot: fewer than two stations");
  const double top = 14 + draw_text(nullptr, 20, 12, p.title, {18, true, kInk, kW - 40}).h + 40;
  return {kW, std::ceil(top + 1.4 * kPanel + kGap + double(p.series.size()) * (kPanel + kGap) + 30)};
}

void draw_profile(cairo_t* cr, const ProfilePlot& p) {
  const auto [w, height] = profile_plot_size(p);
  const double top = 14 + draw_text(nullptr, 20, 12, p.title, {18, true, kInk, kW - 40}).h + 40;
  (void)w;
  draw(cr, p, height, top);
}

void draw_profile_plot(const std::string& png_path, const std::string& pdf_path, const ProfilePlot& p) {
  const auto [w, h] = profile_plot_size(p);
  render_png_pdf(png_path, pdf_path, w, h, [&](cairo_t* cr) { draw_profile(cr, p); });
}

}  // namespace runout::figures
