#include "jobs/figures/load_plot.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "jobs/figures/pen.hpp"

namespace runout::figures {
namespace {

constexpr double kW = 900, kPanel = 230, kLeft = 80, kRight = 30, kGap = 60;
const Rgb kInk{0.1, 0.1, 0.1};
const Rgb kLines[] = {{0.75, 0.0, 0.1}, {0.05, 0.2, 0.55}, {0.1, 0.5, 0.2}, {0.55, 0.3, 0.0}, {0.4, 0.1, 0.5}};

struct Axis {
  double lo = 0, hi = 1;
};

// One panel: the series `value` of every structure over [t.lo, t.hi], its axis labelled `label`.
void panel(cairo_t* cr, const LoadPlot& p, double y0, const Axis& t, const std::string& label,
           std::vector<double> LoadPlot::Structure::*value) {
  const double x0 = kLeft, w = kW - kLeft - kRight;
  double vmax = 0;
  for (const auto& s : p.structures)
    for (double v : s.*value) vmax = std::max(vmax, v);
  vmax = vmax > 0 ? vmax * 1.1 : 1.0;
  auto px = [&](double v) { return x0 + (v - t.lo) / (t.hi - t.lo) * w; };
  auto py = [&](double v) { return y0 + kPanel - v / vmax * kPanel; };
  cairo_set_source_rgb(cr, kInk.r, kInk.g, kInk.b);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, x0, y0, w, kPanel);
  cairo_stroke(cr);
  const double sv = nice_step(vmax, 5);
  for (double v = 0; v <= vmax + 1e-9; v += sv) {
    cairo_move_to(cr, x0 - 5, py(v));
    cairo_line_to(cr, x0, py(v));
    cairo_stroke(cr);
    draw_text(cr, x0 - 8, py(v) - 7, label_number(v, true), {11, false, kInk, -1, 0, 2});
  }
  draw_text(cr, 18, y0 + kPanel / 2 + 40, label, {12, false, kInk, -1, 90});
  const double st = nice_step(t.hi - t.lo, 8);
  for (double v = std::ceil(t.lo / st) * st; v <= t.hi + 1e-9; v += st) {
    cairo_move_to(cr, px(v), y0 + kPanel);
    cairo_line_to(cr, px(v), y0 + kPanel + 5);
    cairo_stroke(cr);
    draw_text(cr, px(v), y0 + kPanel + 7, label_number(v), {11, false, kInk, -1, 0, 1});
  }
  for (std::size_t k = 0; k < p.structures.size(); ++k) {
    const auto& s = p.structures[k];
    const auto& v = s.*value;
    for (std::size_t q = 0; q < v.size() && q < s.t.size(); ++q)
      q ? cairo_line_to(cr, px(s.t[q]), py(v[q])) : cairo_move_to(cr, px(s.t[q]), py(v[q]));
    stroke(cr, kLines[k % 5], 1.6);
    if (v.empty()) continue;
    const std::size_t m = std::size_t(std::max_element(v.begin(), v.end()) - v.begin());
    draw_text(cr, px(s.t[m]) + 4, py(v[m]) - 16, s.name + ": " + label_number(std::round(v[m] * 10) / 10, true), {11, true, kLines[k % 5]});
  }
}

}  // namespace

void draw_load_plot(const std::string& png_path, const std::string& pdf_path, const LoadPlot& p) {
  Axis t{1e300, -1e300};
  for (const auto& s : p.structures)
    if (s.t.size() >= 2) t.lo = std::min(t.lo, s.t.front()), t.hi = std::max(t.hi, s.t.back());
  if (!(t.hi > t.lo)) throw std::runtime_error("load plot: no structure has two samples");
  const double top = 14 + draw_text(nullptr, 20, 12, p.title, {18, true, kInk, kW - 40}).h + 44;
  const double height = top + 2 * kPanel + kGap + 50;
  render_png_pdf(png_path, pdf_path, kW, height, [&](cairo_t* cr) {
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    draw_text(cr, 20, 12, p.title, {18, true, kInk, kW - 40});
    draw_text(cr, 20, top - 28, p.note, {12, false, kInk, kW - 40});
    panel(cr, p, top, t, "horizontal force [kN]", &LoadPlot::Structure::force_kn);
    panel(cr, p, top + kPanel + kGap, t, "highest pressure [kPa]", &LoadPlot::Structure::pressure_kpa);
    draw_text(cr, kLeft + (kW - kLeft - kRight) / 2, top + 2 * kPanel + kGap + 26, "time [s]", {12, false, kInk, -1, 0, 1});
  });
}

}  // namespace runout::figures
