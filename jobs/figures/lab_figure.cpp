#include "jobs/figures/lab_figure.hpp"

#include "jobs/figures/pen.hpp"

#include <cairo.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <utility>

namespace runout::figures {
namespace {

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

// Text with its baseline at y (the pen places the top: the baseline lies about 0.93 size below it).
void text(cairo_t* cr, double x, double y, const std::string& s, double size = 12, const Rgb& c = kOurs, bool right = false) {
  draw_text(cr, x, y - 0.93 * size, s, {size, false, c, -1, 0, right ? 2 : 0});
}

// A "nice" tick step for the range.
double tick_step(double range, int target) {
  const double raw = range / std::max(1, target), p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

// How the reference's values are introduced in the figure text.
std::string source_name(const std::string& source) { return source.empty() ? "reference" : source; }

void dashed(cairo_t* cr, bool on) {
  const double d[] = {6, 4};
  cairo_set_dash(cr, on ? d : nullptr, on ? 2 : 0, 0);
}

// A field on a regular grid drawn at (ox, top) with `scale` pixels per metre, x to the right and y
// up: cells coloured blue -> green -> red by `value` (0..1; NaN: grey, an obstacle) and blended
// into white by `opacity`, arrows of (ux, uy) where the opacity reaches 0.5 (about 40 across, the
// longest as long as their spacing at arrow_max), the frame, the axes and the colour bar.
struct Field {
  int nx = 0, ny = 0;
  double x0 = 0, y0 = 0, dx = 0, dy = 0;
  std::vector<double> value, opacity, ux, uy;
  double arrow_max = 1;
  std::string xlabel = "x [m]", ylabel = "y [m]", bar_top, bar_unit;
  double bar_mark = NAN;  ///< a reference value on the colour bar (0..1 of it), drawn in orange
};

void draw_field(cairo_t* cr, const Field& f, double ox, double top, double scale) {
  const double Lx = f.nx * f.dx, Ly = f.ny * f.dy, sec_w = Lx * scale, sec_h = Ly * scale, oy = top + sec_h;
  auto X = [&](double x) { return ox + (x - f.x0) * scale; };
  auto Y = [&](double y) { return oy - (y - f.y0) * scale; };
  for (int j = 0; j < f.ny; ++j)
    for (int i = 0; i < f.nx; ++i) {
      const std::size_t k = std::size_t(i) + std::size_t(f.nx) * std::size_t(j);
      Rgb c{0.5, 0.5, 0.5};
      if (!std::isnan(f.value[k])) {
        const double al = std::clamp(f.opacity[k], 0.0, 1.0);
        const Rgb s = speed_colour(std::clamp(f.value[k], 0.0, 1.0));
        c = {1 - al + al * s.r, 1 - al + al * s.g, 1 - al + al * s.b};
      }
      cairo_set_source_rgb(cr, c.r, c.g, c.b);
      cairo_rectangle(cr, X(f.x0 + i * f.dx), Y(f.y0 + (j + 1) * f.dy), f.dx * scale + 0.5, f.dy * scale + 0.5);
      cairo_fill(cr);
    }
  const int step = std::max(1, f.nx / 40);
  const double len = step * std::min(f.dx, f.dy) * scale * 0.95;
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1);
  for (int j = step / 2; j < f.ny; j += step)
    for (int i = step / 2; i < f.nx; i += step) {
      const std::size_t k = std::size_t(i) + std::size_t(f.nx) * std::size_t(j);
      if (std::isnan(f.value[k]) || f.opacity[k] < 0.5) continue;
      const double sp = std::hypot(f.ux[k], f.uy[k]);
      if (sp < 1e-3 * f.arrow_max) continue;
      const double l = len * std::min(1.0, sp / std::max(f.arrow_max, 1e-9)), ex = f.ux[k] / sp, ey = -f.uy[k] / sp;
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
  const double sx = tick_step(Lx, 8), sy = tick_step(Ly, 4);
  for (double x = std::ceil(f.x0 / sx - 1e-9) * sx; x <= f.x0 + Lx + 1e-9; x += sx) {
    cairo_move_to(cr, X(x), oy);
    cairo_line_to(cr, X(x), oy + 5);
    cairo_stroke(cr);
    text(cr, X(x) - 12, oy + 18, fmt("%.2f", x + 0.0), 10);  // + 0.0: no "-0.00"
  }
  for (double y = std::ceil(f.y0 / sy - 1e-9) * sy; y <= f.y0 + Ly + 1e-9; y += sy) {
    cairo_move_to(cr, ox - 5, Y(y));
    cairo_line_to(cr, ox, Y(y));
    cairo_stroke(cr);
    text(cr, ox - 8, Y(y) + 4, fmt("%.2f", y + 0.0), 10, kOurs, true);
  }
  text(cr, ox + sec_w - 30, oy + 32, f.xlabel, 11);
  text(cr, 8, top + 12, f.ylabel, 11);
  // Colour bar.
  const double bx = ox + sec_w + 20, bw = 14, bh = std::min(sec_h, 160.0);
  for (int q = 0; q < 100; ++q) {
    const Rgb c = speed_colour(q / 99.0);
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
    cairo_rectangle(cr, bx, top + bh * (1 - (q + 1) / 100.0), bw, bh / 100.0 + 0.5);
    cairo_fill(cr);
  }
  text(cr, bx + bw + 4, top + 10, f.bar_top, 10);
  text(cr, bx + bw + 4, top + bh, "0", 10);
  text(cr, bx, top + bh + 16, f.bar_unit, 10);
  if (f.bar_mark >= 0 && f.bar_mark <= 1) {
    cairo_set_source_rgb(cr, kReference.r, kReference.g, kReference.b);
    cairo_set_line_width(cr, 2);
    cairo_move_to(cr, bx - 4, top + bh * (1 - f.bar_mark));
    cairo_line_to(cr, bx + bw + 4, top + bh * (1 - f.bar_mark));
    cairo_stroke(cr);
    cairo_set_line_width(cr, 1);
  }
}

// A PNG surface of W x H pixels, white, with the title on top (smaller until it fits).
using Surface = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using Context = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;
std::pair<Surface, Context> canvas(int W, int H, const std::string& title, double left) {
  Surface surf(cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H), cairo_surface_destroy);
  Context ctx(cairo_create(surf.get()), cairo_destroy);
  cairo_t* cr = ctx.get();
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  double size = 13;
  for (; size > 7; size -= 0.5)
    if (left + draw_text(nullptr, left, 0, title, {size}).w < W - 10) break;
  text(cr, left, 22, title, size);
  return {std::move(surf), std::move(ctx)};
}

void write_png(cairo_surface_t* surf, const std::string& path) {
  cairo_surface_flush(surf);
  if (cairo_surface_write_to_png(surf, path.c_str()) != CAIRO_STATUS_SUCCESS) throw std::runtime_error("cannot write " + path);
}

// Where the section lies on the page: its origin (bottom left), top, scale [px/m] and size.
struct SectionLayout {
  double ox, oy, top, scale, sec_w, sec_h, gap, ser_h;
};

// The section: the material coloured by speed, the free surface, ours and the reference's fronts
// and surface angles, and their captions.
void draw_section(cairo_t* cr, const SectionFigure& f, const SectionLayout& L) {
  const double ox = L.ox, oy = L.oy, top = L.top, scale = L.scale, sec_h = L.sec_h;
  // x to the right, y up; the material coloured by speed, blended into white by alpha.
  auto X = [&](double x) { return ox + (x - f.x0) * scale; };
  auto Y = [&](double y) { return oy - (y - f.y0) * scale; };
  {
    Field fl;
    fl.nx = f.nx, fl.ny = f.ny, fl.x0 = f.x0, fl.y0 = f.y0, fl.dx = f.dx, fl.dy = f.dy;
    fl.value.resize(f.alpha.size());
    fl.opacity.resize(f.alpha.size());
    for (std::size_t k = 0; k < f.alpha.size(); ++k) {
      fl.value[k] = std::isnan(f.alpha[k]) ? NAN : std::hypot(f.ux[k], f.uy[k]) / std::max(f.vmax, 1e-9);
      fl.opacity[k] = f.alpha[k];
    }
    fl.ux = f.ux, fl.uy = f.uy, fl.arrow_max = f.vmax;
    fl.bar_top = fmt("%.2f", f.vmax), fl.bar_unit = "m/s";
    draw_field(cr, fl, ox, top, scale);
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
    if (!ref.empty()) text(cr, ox, ly + 17, source_name(f.ref_source) + ":" + ref, 12, kReference);
  }

}

// The monitors over time below the section: fluxes [l/s] (or the shock's distance) on the left
// axis, the moving share [0, 1] on the right, with ours and the reference's figures.
// The captions under the monitors: what each line is, ours and the reference's figures.
void series_captions(cairo_t* cr, const SectionFigure& f, double ox, double ty, bool shock) {
  const bool box = !f.surface_angle.empty();
  text(cr, ox, ty,
       box     ? "surface angle (blue), a rigid turn (dashed), flowing layer at the centre [mm] (green), moving > 1 cm/s (grey)"
       : shock ? "the shock's distance from the end wall (blue), share of the material moving > 1 cm/s (grey)"
               : "gate flux (blue), outflow at the end (green), share of the material moving > 1 cm/s (grey)",
       11);
  std::string ours;
  auto add = [](std::string& to, const std::string& s) { to += (to.empty() ? " " : ", ") + s; };
  if (!std::isnan(f.angle_mean))
    add(ours, "surface " + fmt("%.1f", f.angle_mean) + " +- " + fmt("%.1f deg", f.angle_sd) + " once it flows, flowing layer " +
                  fmt("%.1f mm", f.layer_mean * 1e3));
  if (!std::isnan(f.fluidised)) add(ours, "fluidised " + fmt("%.2f s", f.fluidised) + " (black tick)");
  if (!std::isnan(f.gate_flux_early)) add(ours, "gate flux " + fmt("%.2f l/s", f.gate_flux_early) + " (median 0.12-0.30 s)");
  if (!std::isnan(f.strain_early)) add(ours, "gate strain rate " + fmt("%.1f 1/s", f.strain_early) + " (median 0.10-0.20 s)");
  if (!ours.empty()) text(cr, ox, ty + 17, "ours:" + ours, 11);
  std::string ref;
  if (!std::isnan(f.ref_fluidised)) add(ref, "fluidised " + fmt("%.2f s", f.ref_fluidised) + " (dashed)");
  if (!std::isnan(f.ref_outflow)) add(ref, "outflow " + fmt("%.2f l/s", f.ref_outflow) + " (dashed)");
  if (!std::isnan(f.ref_strain)) add(ref, "gate strain rate " + fmt("%.0f 1/s", f.ref_strain));
  if (box && !std::isnan(f.ref_angle)) add(ref, "surface angle " + fmt("%.0f deg", f.ref_angle) + " (dashed)");
  if (!ref.empty()) text(cr, ox, ty + 34, source_name(f.ref_source) + ":" + ref, 11, kReference);
}

void draw_series(cairo_t* cr, const SectionFigure& f, const SectionLayout& L) {
  const double ox = L.ox, top = L.top, sec_h = L.sec_h, sec_w = L.sec_w, gap = L.gap, ser_h = L.ser_h;
  const double py = top + sec_h + gap + 40, pw = std::max(sec_w, 500.0), ph = ser_h;
  const double t0 = f.t.front(), t1 = f.t.back();
  const bool shock = !f.shock.empty(), box = !f.surface_angle.empty();
  double qmax = shock ? 0.1 : 1;
  for (const auto* v : shock ? std::vector<const std::vector<double>*>{&f.shock} : std::vector<const std::vector<double>*>{&f.gate_flux, &f.outflow})
    for (double q : *v)
      if (std::isfinite(q)) qmax = std::max(qmax, q);
  if (!std::isnan(f.ref_outflow)) qmax = std::max(qmax, f.ref_outflow);
  qmax *= 1.1;
  if (box) qmax = 90;
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
  text(cr, 8, py - 8, box ? "angle [deg], layer [mm]" : shock ? "shock from the end wall [m]" : "flux [l/s, 10 cm channel]", 11);
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
  if (box) {
    std::vector<double> layer_mm(f.flowing_layer);
    for (double& v : layer_mm) v *= 1e3;
    line(layer_mm, QY, out_c);
    line(f.surface_angle, QY, gate_c);
    dashed(cr, true);
    line(f.rigid_angle, QY, Rgb{0.2, 0.2, 0.2});
    dashed(cr, false);
  } else if (shock) {
    line(f.shock, QY, gate_c);
  } else {
    line(f.gate_flux, QY, gate_c);
    line(f.outflow, QY, out_c);
  }
  cairo_set_source_rgb(cr, kReference.r, kReference.g, kReference.b);
  cairo_set_line_width(cr, 2);
  dashed(cr, true);
  for (double level : {f.ref_outflow, box ? f.ref_angle : NAN})
    if (!std::isnan(level)) {
      cairo_move_to(cr, ox, QY(level));
      cairo_line_to(cr, ox + pw, QY(level));
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
  series_captions(cr, f, ox, py + ph + 50, shock);
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
  auto [surf, ctx] = canvas(W, H, f.title, left);
  cairo_t* cr = ctx.get();

  const SectionLayout layout{left, top + sec_h, top, scale, sec_w, sec_h, gap, ser_h};
  draw_section(cr, f, layout);
  if (series) draw_series(cr, f, layout);
  write_png(surf.get(), path);
}

void write_plan_figure(const std::string& path, const PlanFigure& f) {
  const std::size_t n = std::size_t(f.nx) * std::size_t(f.nz);
  if (f.nx < 1 || f.nz < 1 || f.depth.size() != n || f.ux.size() != n || f.uz.size() != n)
    throw std::runtime_error("comparison figure: the plan view does not match its grid");
  const double Lx = f.nx * f.dx, Lz = f.nz * f.dz, left = 70, right = 30, top = 40;
  const double scale = std::min(900 / Lx, 420 / Lz), map_w = Lx * scale, map_h = Lz * scale;
  const int W = int(left + std::max(map_w, 500.0) + right + 90), H = int(top + map_h + 120 + 17 * f.shadows.size());
  auto [surf, ctx] = canvas(W, H, f.title, left);
  cairo_t* cr = ctx.get();
  // The colour scale runs to the deepest column, or to the reference's depth if that is deeper.
  double dmax = std::isfinite(f.deepest) && f.deepest > 0 ? f.deepest : 1e-3;
  const double ref_depth = f.ref_depth_ratio * f.undisturbed;
  if (std::isfinite(ref_depth)) dmax = std::max(dmax, ref_depth);
  Field fl;
  fl.nx = f.nx, fl.ny = f.nz, fl.x0 = f.x0, fl.y0 = f.z0, fl.dx = f.dx, fl.dy = f.dz;
  fl.value.resize(n), fl.opacity.resize(n);
  double umax = 1e-3;
  for (std::size_t k = 0; k < n; ++k) {
    const double d = f.depth[k];
    fl.value[k] = std::isnan(d) ? NAN : d / dmax;
    fl.opacity[k] = d >= 1e-3 ? 1 : 0;  // white: dry, depth below 1 mm as in the shadows' dry area (arrows only where wet)
    if (d >= 1e-3) umax = std::max(umax, std::hypot(f.ux[k], f.uz[k]));
  }
  fl.ux = f.ux, fl.uy = f.uz, fl.arrow_max = umax;
  fl.xlabel = f.xlabel, fl.ylabel = "z [m]", fl.bar_top = fmt("%.1f", 1e3 * dmax), fl.bar_unit = "depth [mm]";
  fl.bar_mark = std::isfinite(ref_depth) ? ref_depth / dmax : NAN;
  draw_field(cr, fl, left, top, scale);
  auto X = [&](double x) { return left + (x - f.x0) * scale; };
  auto Z = [&](double z) { return top + map_h - (z - f.z0) * scale; };
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1.5);
  dashed(cr, true);
  cairo_save(cr);
  cairo_rectangle(cr, left, top, map_w, map_h);  // the windows clipped to the map
  cairo_clip(cr);
  for (const auto& w : f.shadows) {
    cairo_rectangle(cr, X(w.x0), Z(w.z1), (w.x1 - w.x0) * scale, (w.z1 - w.z0) * scale);
    cairo_stroke(cr);
  }
  cairo_restore(cr);
  dashed(cr, false);
  if (std::isfinite(f.deepest_x) && std::isfinite(f.deepest_z)) {  // the deepest column: a cross
    const double x = X(f.deepest_x), z = Z(f.deepest_z);
    cairo_set_line_width(cr, 2);
    cairo_move_to(cr, x - 6, z - 6);
    cairo_line_to(cr, x + 6, z + 6);
    cairo_move_to(cr, x - 6, z + 6);
    cairo_line_to(cr, x + 6, z - 6);
    cairo_stroke(cr);
  }
  cairo_set_line_width(cr, 1);
  double ly = top + map_h + 50;
  std::string ours = "ours: no material";
  if (f.deepest > 0) {
    ours = "ours: deepest column " + fmt("%.1f mm", 1e3 * f.deepest) + " at x = " + fmt("%.3f", f.deepest_x) + ", z = " +
           fmt("%.3f m", f.deepest_z) + " (cross)";
    if (f.undisturbed > 0)
      ours += ", " + fmt("%.2f", f.deepest / f.undisturbed) + " times the undisturbed " + fmt("%.1f mm", 1e3 * f.undisturbed);
  }
  text(cr, left, ly, ours, 12);
  for (const auto& w : f.shadows) {
    ly += 17;
    text(cr, left, ly, "dry area behind the " + w.shape + " (dashed window, depth below 1 mm): " + fmt("%.1f cm2", 1e4 * w.dry_m2), 12);
  }
  if (std::isfinite(f.ref_depth_ratio))
    text(cr, left, ly + 17,
         source_name(f.ref_source) + ": deepest column up to " + fmt("%g", f.ref_depth_ratio) +
             " times the undisturbed depth" + (std::isfinite(ref_depth) ? " (orange mark on the colour bar)" : ""),
         12, kReference);
  write_png(surf.get(), path);
}

}  // namespace runout::figures
