#include "jobs/lab_figure.hpp"

#include <cairo.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>

namespace runout::jobs {
namespace {

struct Rgb {
  double r, g, b;
};
Rgb speed_colour(double v) {  // 0..1: blue -> green -> red, as figure.png
  return {v, 1 - std::abs(2 * v - 1), 1 - v};
}
const Rgb kReference{0.85, 0.35, 0.0};  // orange: the reference values
const Rgb kOurs{0.0, 0.0, 0.0};

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

void text(cairo_t* cr, double x, double y, const std::string& s, double size = 12, const Rgb& c = kOurs, bool right = false) {
  cairo_set_source_rgb(cr, c.r, c.g, c.b);
  cairo_set_font_size(cr, size);
  double xx = x;
  if (right) {
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    xx -= e.x_advance;
  }
  cairo_move_to(cr, xx, y);
  cairo_show_text(cr, s.c_str());
}

// A "nice" tick step for the range.
double tick_step(double range, int target) {
  const double raw = range / std::max(1, target), p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

void dashed(cairo_t* cr, bool on) {
  const double d[] = {6, 4};
  cairo_set_dash(cr, on ? d : nullptr, on ? 2 : 0, 0);
}

}  // namespace

void write_section_figure(const std::string& path, const SectionFigure& f) {
  if (f.nx < 1 || f.ny < 1 || f.alpha.size() != std::size_t(f.nx) * std::size_t(f.ny))
    throw std::runtime_error("comparison figure: the section does not match its grid");
  const double Lx = f.nx * f.dx, Ly = f.ny * f.dy;
  const double left = 70, right = 30, top = 40, gap = 60;
  const double plot_w = 900;
  const double scale = std::min(plot_w / Lx, 420 / Ly);  // pixels per metre, equal in x and y
  const double sec_w = Lx * scale, sec_h = Ly * scale;
  const bool series = f.t.size() >= 2;
  const double ser_h = series ? 200 : 0;
  const int W = int(left + std::max(sec_w, 500.0) + right + 90), H = int(top + sec_h + 90 + (series ? 40 + ser_h + 100 : 0));
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surf(cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H),
                                                                         cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> ctx(cairo_create(surf.get()), cairo_destroy);
  cairo_t* cr = ctx.get();
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  {
    // The title, smaller until it fits.
    double size = 13;
    cairo_text_extents_t e;
    for (; size > 7; size -= 0.5) {
      cairo_set_font_size(cr, size);
      cairo_text_extents(cr, f.title.c_str(), &e);
      if (left + e.x_advance < W - 10) break;
    }
    text(cr, left, 22, f.title, size);
  }

  // Section: x to the right, y up.
  const double ox = left, oy = top + sec_h;
  auto X = [&](double x) { return ox + (x - f.x0) * scale; };
  auto Y = [&](double y) { return oy - (y - f.y0) * scale; };
  for (int j = 0; j < f.ny; ++j)
    for (int i = 0; i < f.nx; ++i) {
      const std::size_t k = std::size_t(i) + std::size_t(f.nx) * std::size_t(j);
      const double a = f.alpha[k];
      Rgb c{1, 1, 1};
      if (std::isnan(a)) {
        c = {0.5, 0.5, 0.5};
      } else {
        const double al = std::clamp(a, 0.0, 1.0);
        const Rgb s = speed_colour(std::min(1.0, std::hypot(f.ux[k], f.uy[k]) / std::max(f.vmax, 1e-9)));
        c = {1 - al + al * s.r, 1 - al + al * s.g, 1 - al + al * s.b};
      }
      cairo_set_source_rgb(cr, c.r, c.g, c.b);
      cairo_rectangle(cr, X(f.x0 + i * f.dx), Y(f.y0 + (j + 1) * f.dy), f.dx * scale + 0.5, f.dy * scale + 0.5);
      cairo_fill(cr);
    }
  // The free surface: where alpha crosses 0.5 between vertical neighbours.
  cairo_set_source_rgb(cr, 0, 0, 0);
  for (int i = 0; i < f.nx; ++i)
    for (int j = 0; j + 1 < f.ny; ++j) {
      const double a0 = f.alpha[std::size_t(i) + std::size_t(f.nx) * j], a1 = f.alpha[std::size_t(i) + std::size_t(f.nx) * (j + 1)];
      if (std::isnan(a0) || std::isnan(a1) || (a0 - 0.5) * (a1 - 0.5) >= 0) continue;
      const double y = f.y0 + (j + 0.5 + (0.5 - a0) / (a1 - a0)) * f.dy;
      cairo_rectangle(cr, X(f.x0 + (i + 0.5) * f.dx) - 1, Y(y) - 1, 2, 2);
      cairo_fill(cr);
    }
  // Velocity arrows in the material, about 40 across the section, the longest as long as the spacing.
  const int step = std::max(1, f.nx / 40);
  const double len = step * std::min(f.dx, f.dy) * scale * 0.95;
  cairo_set_line_width(cr, 1);
  for (int j = step / 2; j < f.ny; j += step)
    for (int i = step / 2; i < f.nx; i += step) {
      const std::size_t k = std::size_t(i) + std::size_t(f.nx) * std::size_t(j);
      if (std::isnan(f.alpha[k]) || f.alpha[k] < 0.5) continue;
      const double sp = std::hypot(f.ux[k], f.uy[k]);
      if (sp < 1e-3 * f.vmax) continue;
      const double l = len * std::min(1.0, sp / std::max(f.vmax, 1e-9)), ex = f.ux[k] / sp, ey = -f.uy[k] / sp;
      const double x0 = X(f.x0 + (i + 0.5) * f.dx) - 0.5 * l * ex, y0 = Y(f.y0 + (j + 0.5) * f.dy) - 0.5 * l * ey;
      const double x1 = x0 + l * ex, y1 = y0 + l * ey;
      cairo_move_to(cr, x0, y0);
      cairo_line_to(cr, x1, y1);
      cairo_move_to(cr, x1, y1);
      cairo_line_to(cr, x1 - 0.3 * l * (ex - 0.5 * ey), y1 - 0.3 * l * (ey + 0.5 * ex));
      cairo_move_to(cr, x1, y1);
      cairo_line_to(cr, x1 - 0.3 * l * (ex + 0.5 * ey), y1 - 0.3 * l * (ey - 0.5 * ex));
      cairo_stroke(cr);
    }
  // Frame and axes [m].
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_rectangle(cr, ox, top, sec_w, sec_h);
  cairo_stroke(cr);
  {
    const double sx = tick_step(Lx, 8), sy = tick_step(Ly, 4);
    for (double x = std::ceil(f.x0 / sx - 1e-9) * sx; x <= f.x0 + Lx + 1e-9; x += sx) {
      cairo_move_to(cr, X(x), oy);
      cairo_line_to(cr, X(x), oy + 5);
      cairo_stroke(cr);
      text(cr, X(x) - 12, oy + 18, fmt("%.2f", x), 10);
    }
    for (double y = std::ceil(f.y0 / sy - 1e-9) * sy; y <= f.y0 + Ly + 1e-9; y += sy) {
      cairo_move_to(cr, ox - 5, Y(y));
      cairo_line_to(cr, ox, Y(y));
      cairo_stroke(cr);
      text(cr, ox - 8, Y(y) + 4, fmt("%.2f", y), 10, kOurs, true);
    }
    text(cr, ox + sec_w - 30, oy + 32, "x [m]", 11);
    text(cr, 8, top + 12, "y [m]", 11);
  }
  // Colour bar.
  {
    const double bx = ox + sec_w + 20, bw = 14, bh = std::min(sec_h, 160.0);
    for (int q = 0; q < 100; ++q) {
      const Rgb c = speed_colour(q / 99.0);
      cairo_set_source_rgb(cr, c.r, c.g, c.b);
      cairo_rectangle(cr, bx, top + bh * (1 - (q + 1) / 100.0), bw, bh / 100.0 + 0.5);
      cairo_fill(cr);
    }
    text(cr, bx + bw + 4, top + 10, fmt("%.2f", f.vmax), 10);
    text(cr, bx + bw + 4, top + bh, "0", 10);
    text(cr, bx, top + bh + 16, "m/s", 10);
  }
  // Fronts and surface angles: ours in black, the reference in orange (dashed).
  double ly = oy + 48;
  if (!std::isnan(f.ref_front_min)) {
    cairo_set_source_rgba(cr, kReference.r, kReference.g, kReference.b, 0.25);
    cairo_rectangle(cr, X(f.ref_front_min), top, std::max(2.0, (f.ref_front_max - f.ref_front_min) * scale), sec_h);
    cairo_fill(cr);
  }
  if (!std::isnan(f.ref_angle) && !std::isnan(f.anchor_x) && !std::isnan(f.height) && f.ref_angle > 0) {
    // The reference slope through our surface at 70 % of the deposit's height, over the 90-50 %
    // band in which our upper surface angle is fitted.
    cairo_set_source_rgb(cr, kReference.r, kReference.g, kReference.b);
    cairo_set_line_width(cr, 2);
    dashed(cr, true);
    const double cot = 1 / std::tan(f.ref_angle * M_PI / 180), h = f.height;
    cairo_move_to(cr, X(f.anchor_x - 0.2 * h * cot), Y(f.y0 + 0.9 * h));
    cairo_line_to(cr, X(f.anchor_x + 0.2 * h * cot), Y(f.y0 + 0.5 * h));
    cairo_stroke(cr);
    dashed(cr, false);
    cairo_set_line_width(cr, 1);
  }
  if (!std::isnan(f.front)) {
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 2);
    cairo_move_to(cr, X(f.front), oy);
    cairo_line_to(cr, X(f.front), oy - 12);
    cairo_stroke(cr);
    cairo_set_line_width(cr, 1);
  }
  {
    std::string ours = "ours:";
    if (!std::isnan(f.front)) ours += " front " + fmt("%.3f m", f.front) + " (black tick)";
    if (!std::isnan(f.upper_angle)) ours += ", upper surface " + fmt("%.1f deg", f.upper_angle);
    if (ours != "ours:") text(cr, ox, ly, ours, 12);
    std::string ref;
    if (!std::isnan(f.ref_front_min)) ref += " front " + fmt("%.3f", f.ref_front_min) + "-" + fmt("%.3f m", f.ref_front_max) + " (band)";
    if (!std::isnan(f.ref_angle)) ref += std::string(ref.empty() ? "" : ",") + " upper surface " + fmt("%.0f deg", f.ref_angle) + " (dashed, through ours at 70 % height)";
    if (!ref.empty()) text(cr, ox, ly + 17, (f.ref_source.empty() ? std::string("reference") : f.ref_source) + ":" + ref, 12, kReference);
  }

  if (!series) {
    cairo_surface_flush(surf.get());
    if (cairo_surface_write_to_png(surf.get(), path.c_str()) != CAIRO_STATUS_SUCCESS) throw std::runtime_error("cannot write " + path);
    return;
  }
  // Monitors over time: fluxes [l/s] on the left axis, the moving share [0, 1] on the right.
  const double py = top + sec_h + gap + 40, pw = std::max(sec_w, 500.0), ph = ser_h;
  const double t0 = f.t.front(), t1 = f.t.back();
  const bool shock = !f.shock.empty();
  double qmax = shock ? 0.1 : 1;
  for (const auto* v : shock ? std::vector<const std::vector<double>*>{&f.shock} : std::vector<const std::vector<double>*>{&f.gate_flux, &f.outflow})
    for (double q : *v)
      if (std::isfinite(q)) qmax = std::max(qmax, q);
  if (!std::isnan(f.ref_outflow)) qmax = std::max(qmax, f.ref_outflow);
  qmax *= 1.1;
  auto TX = [&](double t) { return ox + (t - t0) / std::max(1e-12, t1 - t0) * pw; };
  auto QY = [&](double q) { return py + ph - q / qmax * ph; };
  auto SY = [&](double s) { return py + ph - s * ph; };
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_rectangle(cr, ox, py, pw, ph);
  cairo_stroke(cr);
  const double st = tick_step(t1 - t0, 8), sq = tick_step(qmax, 4);
  for (double t = std::ceil(t0 / st - 1e-9) * st; t <= t1 + 1e-9; t += st) {
    cairo_move_to(cr, TX(t), py + ph);
    cairo_line_to(cr, TX(t), py + ph + 5);
    cairo_stroke(cr);
    text(cr, TX(t) - 10, py + ph + 18, fmt("%.2f", t), 10);
  }
  for (double q = 0; q <= qmax + 1e-9; q += sq) {
    cairo_move_to(cr, ox - 5, QY(q));
    cairo_line_to(cr, ox, QY(q));
    cairo_stroke(cr);
    text(cr, ox - 8, QY(q) + 4, fmt("%g", q), 10, kOurs, true);
  }
  for (double sh : {0.0, 0.5, 1.0}) {
    cairo_move_to(cr, ox + pw, SY(sh));
    cairo_line_to(cr, ox + pw + 5, SY(sh));
    cairo_stroke(cr);
    text(cr, ox + pw + 8, SY(sh) + 4, fmt("%.1f", sh), 10);
  }
  text(cr, ox + pw - 25, py + ph + 32, "t [s]", 11);
  text(cr, 8, py - 8, shock ? "shock from the end wall [m]" : "flux [l/s, 10 cm channel]", 11);
  text(cr, ox + pw - 60, py - 8, "moving share", 11, {0.45, 0.45, 0.45});
  auto line = [&](const std::vector<double>& v, auto yf, const Rgb& c) {
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
    cairo_set_line_width(cr, 1.5);
    bool pen = false;
    for (std::size_t q = 0; q < v.size() && q < f.t.size(); ++q) {
      if (!std::isfinite(v[q])) {
        pen = false;
        continue;
      }
      if (pen) cairo_line_to(cr, TX(f.t[q]), yf(v[q]));
      else cairo_move_to(cr, TX(f.t[q]), yf(v[q]));
      pen = true;
    }
    cairo_stroke(cr);
    cairo_set_line_width(cr, 1);
  };
  const Rgb gate_c{0.1, 0.3, 0.9}, out_c{0.1, 0.6, 0.2}, mov_c{0.55, 0.55, 0.55};
  line(f.moving, SY, mov_c);
  if (shock) {
    line(f.shock, QY, gate_c);
  } else {
    line(f.gate_flux, QY, gate_c);
    line(f.outflow, QY, out_c);
  }
  cairo_set_source_rgb(cr, kReference.r, kReference.g, kReference.b);
  cairo_set_line_width(cr, 2);
  dashed(cr, true);
  if (!std::isnan(f.ref_outflow)) {
    cairo_move_to(cr, ox, QY(f.ref_outflow));
    cairo_line_to(cr, ox + pw, QY(f.ref_outflow));
    cairo_stroke(cr);
  }
  if (!std::isnan(f.ref_fluidised) && f.ref_fluidised >= t0 && f.ref_fluidised <= t1) {
    cairo_move_to(cr, TX(f.ref_fluidised), py);
    cairo_line_to(cr, TX(f.ref_fluidised), py + ph);
    cairo_stroke(cr);
  }
  dashed(cr, false);
  if (!std::isnan(f.fluidised)) {
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 2);
    cairo_move_to(cr, TX(f.fluidised), py + ph);
    cairo_line_to(cr, TX(f.fluidised), py + ph - 12);
    cairo_stroke(cr);
  }
  cairo_set_line_width(cr, 1);
  double ty = py + ph + 50;
  text(cr, ox, ty,
       shock ? "the shock's distance from the end wall (blue), share of the material moving > 1 cm/s (grey)"
             : "gate flux (blue), outflow at the end (green), share of the material moving > 1 cm/s (grey)",
       11);
  std::string ours;
  auto add = [](std::string& to, const std::string& s) { to += (to.empty() ? " " : ", ") + s; };
  if (!std::isnan(f.fluidised)) add(ours, "fluidised " + fmt("%.2f s", f.fluidised) + " (black tick)");
  if (!std::isnan(f.gate_flux_early)) add(ours, "gate flux " + fmt("%.2f l/s", f.gate_flux_early) + " (median 0.12-0.30 s)");
  if (!std::isnan(f.strain_early)) add(ours, "gate strain rate " + fmt("%.1f 1/s", f.strain_early) + " (median 0.10-0.20 s)");
  if (!ours.empty()) text(cr, ox, ty + 17, "ours:" + ours, 11);
  std::string ref;
  if (!std::isnan(f.ref_fluidised)) add(ref, "fluidised " + fmt("%.2f s", f.ref_fluidised) + " (dashed)");
  if (!std::isnan(f.ref_outflow)) add(ref, "outflow " + fmt("%.2f l/s", f.ref_outflow) + " (dashed)");
  if (!std::isnan(f.ref_strain)) add(ref, "gate strain rate " + fmt("%.0f 1/s", f.ref_strain));
  if (!ref.empty()) text(cr, ox, ty + 34, (f.ref_source.empty() ? std::string("reference") : f.ref_source) + ":" + ref, 11, kReference);
  cairo_surface_flush(surf.get());
  if (cairo_surface_write_to_png(surf.get(), path.c_str()) != CAIRO_STATUS_SUCCESS) throw std::runtime_error("cannot write " + path);
}

}  // namespace runout::jobs
