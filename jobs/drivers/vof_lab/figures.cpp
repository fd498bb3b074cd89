#include "jobs/drivers/vof_lab/figures.hpp"

#include <gdal_priv.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace runout::jobs::vof_lab {

namespace vof = engine::vof;

namespace {

// 3D: the flow depth per column (x, z); -1 where an obstacle not covered by flow stands.
std::vector<double> plan_depth(const vof::VofBackend& s, const LabGrid& g, double& dmax) {
  std::vector<double> depth(std::size_t(g.nx) * g.nz, -1);
  dmax = 1e-9;
  for (int k = 0; k < g.nz; ++k)
    for (int i = 0; i < g.nx; ++i) {
      double d = 0;
      bool blocked = false;
      for (int j = 0; j < g.ny; ++j) {
        const int c = g.id(i, j, k);
        if (c < 0) blocked = true;
        else d += std::clamp(s.alpha()[std::size_t(c)], 0.0, 1.0) * g.dy;
      }
      depth[std::size_t(k) * g.nx + i] = blocked && d < 1e-3 ? -1 : d;  // grey: an obstacle not covered by flow
      dmax = std::max(dmax, d);
    }
  return depth;
}

void write_png(const std::string& path, int W, int H, std::vector<unsigned char> (&rgb)[3]) {
  GDALAllRegister();
  auto* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDatasetUniquePtr img(mem->Create("", W, H, 3, GDT_Byte, nullptr));
  for (int c = 0; c < 3; ++c)
    if (img->GetRasterBand(c + 1)->RasterIO(GF_Write, 0, 0, W, H, rgb[c].data(), W, H, GDT_Byte, 0, 0) != CE_None)
      throw std::runtime_error("drawing figure.png failed");
  GDALDatasetUniquePtr out(GetGDALDriverManager()->GetDriverByName("PNG")->CreateCopy(path.c_str(), img.get(), FALSE, nullptr, nullptr, nullptr));
  if (!out) throw std::runtime_error("cannot write " + path);
}

}  // namespace

// Plane set-ups: the x-y section, material (alpha > 0.5) coloured by speed (blue slow ... red fast),
// air white. 3D: the plan view (x along, z across), flow depth coloured from blue (thin) to red
// (the deepest), obstacles grey.
void write_state_figure(const std::string& path, const vof::VofBackend& s, const LabGrid& g, double vmax) {
  const int nrow = g.three_d ? g.nz : g.ny;
  const int sc = std::max(1, 600 / std::max(g.nx, 1));
  const int W = g.nx * sc, H = nrow * sc;
  std::vector<unsigned char> rgb[3];
  for (auto& c : rgb) c.assign(std::size_t(W) * H, 255);
  double dmax = 1e-9;
  const std::vector<double> depth = g.three_d ? plan_depth(s, g, dmax) : std::vector<double>();
  for (int row = 0; row < nrow; ++row)
    for (int i = 0; i < g.nx; ++i) {
      double a = 0, v = 0;
      bool grey = false;
      if (g.three_d) {
        const double d = depth[std::size_t(row) * g.nx + i];
        grey = d < 0;
        a = d > 1e-4 ? 1.0 : 0.0;  // white: dry (below 0.1 mm)
        v = std::max(0.0, d) / dmax;
      } else {
        const int c = g.id(i, row, 0);
        grey = c < 0;
        if (!grey) {
          a = std::clamp(s.alpha()[std::size_t(c)], 0.0, 1.0);
          v = std::min(1.0, vof::norm(s.velocity()[std::size_t(c)]) / std::max(vmax, 1e-9));
        }
      }
      const double r = v, gg = 1 - std::abs(2 * v - 1), b = 1 - v;  // blue -> green -> red
      unsigned char col[3] = {static_cast<unsigned char>(255 * (1 - a + a * r)), static_cast<unsigned char>(255 * (1 - a + a * gg)),
                              static_cast<unsigned char>(255 * (1 - a + a * b))};
      if (grey) col[0] = col[1] = col[2] = 128;
      for (int q = 0; q < sc; ++q)
        for (int p = 0; p < sc; ++p) {
          const std::size_t px = std::size_t(H - 1 - (row * sc + q)) * W + i * sc + p;  // y (or z) up
          for (int c = 0; c < 3; ++c) rgb[c][px] = col[c];
        }
    }
  write_png(path, W, H, rgb);
}

std::string figure_title(const ResolvedScenario& r, const LabGrid& g, double t) {
  std::ostringstream cells_mm;
  cells_mm << std::setprecision(3) << g.dx * 1e3 << " x " << g.dy * 1e3;
  if (g.three_d) cells_mm << " x " << g.dz * 1e3;
  return (r.scenario.name().empty() ? std::string("laboratory run") : r.scenario.name()) + ", t = " + json_number(t) + " s, cells " +
         cells_mm.str() + " mm";
}

void write_section_comparison(const std::string& path, const std::string& title, const v1::Lab& L, const LabSetup& su,
                              const vof::VofBackend& s, const Deposit& dep, const LabMonitors& mon) {
  const auto& g = su.g;
  figures::SectionFigure fig;
  fig.title = title;
  fig.nx = g.nx, fig.ny = g.ny, fig.x0 = g.x0, fig.y0 = g.y0, fig.dx = g.dx, fig.dy = g.dy;
  fig.alpha.assign(std::size_t(g.nx) * g.ny, NAN);
  fig.ux.assign(fig.alpha.size(), 0.0);
  fig.uy.assign(fig.alpha.size(), 0.0);
  for (int jj = 0; jj < g.ny; ++jj)
    for (int i = 0; i < g.nx; ++i)
      if (const int c = g.id(i, jj, 0); c >= 0) {
        const std::size_t k = std::size_t(i) + std::size_t(g.nx) * std::size_t(jj);
        fig.alpha[k] = s.alpha()[std::size_t(c)];
        fig.ux[k] = s.velocity()[std::size_t(c)].x;
        fig.uy[k] = s.velocity()[std::size_t(c)].y;
      }
  double vmax = 0.01;
  for (int c = 0; c < su.m.cells(); ++c)
    if (s.alpha()[std::size_t(c)] > 0.5) vmax = std::max(vmax, vof::norm(s.velocity()[std::size_t(c)]));
  fig.vmax = vmax;
  if (!su.has_inflow) {  // the deposit figures of a collapse
    fig.front = dep.front;
    fig.upper_angle = dep.upper_angle;
  }
  for (int i = dep.imax; i < g.nx; ++i)
    if (dep.h[std::size_t(i)] < 0.7 * dep.height) {
      fig.anchor_x = g.x0 + (i + 0.5) * g.dx;
      break;
    }
  fig.height = dep.height;
  fig.t = mon.t, fig.gate_flux = mon.gate.flux, fig.outflow = mon.outflow.q, fig.moving = mon.moving.share;
  fig.fluidised = mon.moving.t_fluid >= 0 && !su.has_inflow ? mon.moving.t_fluid : NAN;
  if (mon.shock.enabled())
    for (double x : mon.shock.x) fig.shock.push_back(L.x_max() - x);
  if (mon.surface.enabled()) {  // the rotating box: its angles and flowing layer instead of the fluxes
    v1::Monitors summary;
    mon.surface.write(summary, mon.t);
    fig.surface_angle = mon.surface.angle;
    fig.flowing_layer = mon.surface.layer;
    for (double t : mon.t) {
      const double turn = std::fmod(360.0 * t / L.rotation_period_s(), 180.0);
      fig.rigid_angle.push_back(turn <= 90 ? turn : 180 - turn);
    }
    fig.angle_mean = summary.surface_angle_mean_deg(), fig.angle_sd = summary.surface_angle_std_deg();
    fig.layer_mean = summary.flowing_layer_mean_m();
  }
  if (mon.gate.has_gate()) {
    fig.gate_flux_early = median_between(mon.t, mon.gate.flux, 0.12, 0.30);
    fig.strain_early = median_between(mon.t, mon.gate.strain, 0.10, 0.20);
  }
  if (L.has_reference()) {
    const auto& ref = L.reference();
    fig.ref_source = ref.source();
    if (ref.has_front_x_min()) fig.ref_front_min = ref.front_x_min(), fig.ref_front_max = ref.front_x_max();
    if (ref.has_surface_angle_deg()) fig.ref_angle = ref.surface_angle_deg();
    if (ref.has_fluidised_time_s()) fig.ref_fluidised = ref.fluidised_time_s();
    if (ref.has_outflow_l_s()) fig.ref_outflow = ref.outflow_l_s();
    if (ref.has_gate_strain_rate_1_s()) fig.ref_strain = ref.gate_strain_rate_1_s();
  }
  figures::write_section_figure(path, fig);
}

}  // namespace runout::jobs::vof_lab
