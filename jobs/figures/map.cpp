#include "jobs/figures/map.hpp"

#include <cpl_error.h>
#include <gdal_priv.h>
#include <gdal_utils.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <sstream>

namespace runout::figures {
using terrain::TerrainError;
namespace {

// A 5 x 7 pixel font for the legend, the scale bar and the title: each glyph is 7 rows of 5 bits
// (bit 4 = leftmost column).
struct Glyph {
  char c;
  std::array<std::uint8_t, 7> rows;
};
constexpr Glyph kFont[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}},
    {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}}, {'>', {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'[', {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E}}, {']', {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E}},
    {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}}, {'/', {0x01, 0x01, 0x02, 0x04, 0x08, 0x10, 0x10}},
    {'a', {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}}, {'b', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1E}},
    {'c', {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E}}, {'d', {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F}},
    {'e', {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}}, {'f', {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}},
    {'g', {0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E}}, {'h', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'i', {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}}, {'k', {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}},
    {'l', {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}}, {'m', {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11}},
    {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}}, {'o', {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}},
    {'p', {0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10}}, {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}},
    {'s', {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E}}, {'t', {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06}},
    {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D}}, {'v', {0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04}},
    {'w', {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A}}, {'x', {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11}},
    {'y', {0x00, 0x00, 0x11, 0x11, 0x0F, 0x01, 0x0E}}, {'z', {0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F}},
    {'A', {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}}, {'D', {0x1E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1E}},
    {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}}, {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}},
    {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}}, {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}},
    {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}}, {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
    {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}}, {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}},
    {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}}, {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
    {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}}, {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
    {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}}, {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}},
    {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}}, {'Y', {0x11, 0x11, 0x0A, 0x04, 0x04, 0x04, 0x04}},
    {'j', {0x02, 0x00, 0x06, 0x02, 0x02, 0x12, 0x0C}}, {'q', {0x00, 0x00, 0x0D, 0x13, 0x0F, 0x01, 0x01}}, {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
    {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}}, {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}},
};

struct Image {
  int w, h;
  std::vector<std::uint8_t> r, g, b;
  Image(int w_, int h_) : w(w_), h(h_), r(std::size_t(w_) * h_, 255), g(r), b(r) {}
  void set(int x, int y, std::array<std::uint8_t, 3> c) {
    if (x < 0 || y < 0 || x >= w || y >= h) return;
    const std::size_t k = std::size_t(y) * w + x;
    r[k] = c[0];
    g[k] = c[1];
    b[k] = c[2];
  }
  void rect(int x0, int y0, int x1, int y1, std::array<std::uint8_t, 3> c) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) set(x, y, c);
  }
  // Text at (x, y) top-left, `s` pixels per font pixel; returns the width drawn.
  int text(int x, int y, const std::string& t, int s = 2, std::array<std::uint8_t, 3> c = {0, 0, 0}) {
    int cx = x;
    for (char ch : t) {
      if (ch == ' ') {
        cx += 4 * s;
        continue;
      }
      const Glyph* gl = nullptr;
      for (const auto& f : kFont)
        if (f.c == ch) gl = &f;
      if (!gl) continue;
      for (int row = 0; row < 7; ++row)
        for (int col = 0; col < 5; ++col)
          if (gl->rows[row] & (0x10 >> col)) rect(cx + col * s, y + row * s, cx + (col + 1) * s, y + (row + 1) * s, c);
      cx += 6 * s;
    }
    return cx - x;
  }
};

// Depth classes and colours (yellow to dark red), upper bounds in metres.
struct DepthClass {
  double lo;
  std::array<std::uint8_t, 3> c;
  const char* label;
};
constexpr DepthClass kClasses[] = {{0.1, {255, 255, 178}, "0.1 - 0.5"}, {0.5, {254, 204, 92}, "0.5 - 1"},
                                   {1.0, {253, 141, 60}, "1 - 2"},      {2.0, {240, 59, 32}, "2 - 5"},
                                   {5.0, {189, 0, 38}, "> 5"}};

// Hillshade with GDAL's DEM tools (north-up raster, row 0 north), one byte per cell.
std::vector<std::uint8_t> hillshade(const Grid& g) {
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
  char* args[] = {const_cast<char*>("-of"), const_cast<char*>("MEM"), const_cast<char*>("-compute_edges"), nullptr};
  std::unique_ptr<GDALDEMProcessingOptions, decltype(&GDALDEMProcessingOptionsFree)> opt(
      GDALDEMProcessingOptionsNew(args, nullptr), GDALDEMProcessingOptionsFree);
  GDALDatasetUniquePtr hs(GDALDataset::FromHandle(
      GDALDEMProcessing("", GDALDataset::ToHandle(dem.get()), "hillshade", nullptr, opt.get(), nullptr)));
  if (!hs) throw TerrainError(std::string("map: hillshade failed: ") + CPLGetLastErrorMsg());
  std::vector<std::uint8_t> shade(g.cells());
  if (hs->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, g.nx, g.ny, shade.data(), g.nx, g.ny, GDT_Byte, 0, 0) != CE_None)
    throw TerrainError("map: reading the hillshade failed");
  return shade;
}

}  // namespace

void write_map_png(const std::string& path, const Grid& g, const std::vector<double>& max_depth,
                   const std::vector<double>& release, const MapRequest& req) {
  GDALAllRegister();
  const std::vector<std::uint8_t> shade = hillshade(g);
  auto* mem = GetGDALDriverManager()->GetDriverByName("MEM");

  const int s = std::max(1, req.scale), mw = g.nx * s, mh = g.ny * s, pad = 10, legend = 210, top = 30;
  Image img(mw + 2 * pad + legend, std::max(mh + top + 50, 330));
  auto at = [&](const std::vector<double>& v, int i, int r) { return v[std::size_t(g.ny - 1 - r) * g.nx + i]; };
  auto cls = [&](double d) {
    int c = -1;
    for (int k = 0; k < 5; ++k)
      if (d > kClasses[k].lo) c = k;
    return c;
  };
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) {
      const double sh = shade[std::size_t(r) * g.nx + i] / 255.0;
      std::array<std::uint8_t, 3> c;
      if (!g.outside.empty() && g.outside[std::size_t(g.ny - 1 - r) * g.nx + i]) {  // outside the domain: pale
        const auto v = std::uint8_t(215 + 40 * sh);
        img.rect(pad + i * s, top + r * s, pad + (i + 1) * s, top + (r + 1) * s, {v, v, v});
        continue;
      }
      const int k = cls(at(max_depth, i, r));
      for (int q = 0; q < 3; ++q) {
        const double base = 60 + 195 * sh;
        const double v = k < 0 ? base : 0.35 * base + 0.65 * kClasses[k].c[q] * (0.55 + 0.45 * sh);
        c[q] = std::uint8_t(std::clamp(v, 0.0, 255.0));
      }
      img.rect(pad + i * s, top + r * s, pad + (i + 1) * s, top + (r + 1) * s, c);
    }
  // Edges of the release (blue) and of the outline (dark red).
  auto edge = [&](int i, int r, auto inside) {
    if (!inside(i, r)) return false;
    return i == 0 || r == 0 || i == g.nx - 1 || r == g.ny - 1 || !inside(i - 1, r) || !inside(i + 1, r) ||
           !inside(i, r - 1) || !inside(i, r + 1);
  };
  auto in_out = [&](int i, int r) { return at(max_depth, i, r) > req.outline_threshold; };
  auto in_rel = [&](int i, int r) { return at(release, i, r) > 0; };
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) {
      if (edge(i, r, in_out)) img.rect(pad + i * s, top + r * s, pad + (i + 1) * s, top + (r + 1) * s, {110, 0, 20});
      if (edge(i, r, in_rel)) img.rect(pad + i * s, top + r * s, pad + (i + 1) * s, top + (r + 1) * s, {30, 80, 220});
    }
  img.text(pad, 8, req.title, 2);
  // Legend.
  const int lx = pad + mw + 15;
  int ly = top;
  img.text(lx, ly, "max depth [m]", 2);
  ly += 24;
  for (int k = 0; k < 5; ++k) {
    img.rect(lx, ly, lx + 26, ly + 16, kClasses[k].c);
    img.text(lx + 34, ly + 2, kClasses[k].label, 2);
    ly += 22;
  }
  ly += 8;
  img.rect(lx, ly + 6, lx + 26, ly + 10, {30, 80, 220});
  img.text(lx + 34, ly + 2, "release", 2);
  ly += 22;
  img.rect(lx, ly + 6, lx + 26, ly + 10, {110, 0, 20});
  std::ostringstream ot;
  ot << "outline " << req.outline_threshold << " m";
  img.text(lx + 34, ly + 2, ot.str(), 2);
  ly += 34;
  // North arrow.
  img.text(lx + 8, ly, "N", 3);
  for (int k = 0; k < 12; ++k) img.rect(lx + 15 - k / 2, ly + 26 + k, lx + 16 + k / 2, ly + 27 + k, {0, 0, 0});
  // Scale bar: a round length near a quarter of the map's width.
  const double width_m = g.nx * g.dx;
  double len = std::pow(10.0, std::floor(std::log10(width_m / 4)));
  for (double f : {5.0, 2.0, 1.0})
    if (len * f <= width_m / 3) {
      len *= f;
      break;
    }
  const int bar = int(std::lround(len / g.dx * s)), by = top + mh + 14;
  img.rect(pad, by, pad + bar, by + 6, {0, 0, 0});
  img.rect(pad + bar / 2, by + 1, pad + bar - 1, by + 5, {255, 255, 255});
  std::ostringstream sl;
  if (len >= 1000) sl << len / 1000 << " km";
  else sl << len << " m";
  img.text(pad + bar + 8, by - 4, sl.str(), 2);
  img.text(pad, by + 16, g.crs_name + ", cells of " + std::to_string(int(std::lround(g.dx))) + " m", 2);

  GDALDatasetUniquePtr out(mem->Create("", img.w, img.h, 3, GDT_Byte, nullptr));
  std::vector<std::uint8_t>* bands[] = {&img.r, &img.g, &img.b};
  for (int k = 0; k < 3; ++k)
    if (out->GetRasterBand(k + 1)->RasterIO(GF_Write, 0, 0, img.w, img.h, bands[k]->data(), img.w, img.h, GDT_Byte, 0, 0) != CE_None)
      throw TerrainError("map: composing the picture failed");
  auto* png = GetGDALDriverManager()->GetDriverByName("PNG");
  GDALDatasetUniquePtr f(png->CreateCopy(path.c_str(), out.get(), FALSE, nullptr, nullptr, nullptr));
  if (!f) throw TerrainError("writing '" + path + "' failed: " + CPLGetLastErrorMsg());
}

}  // namespace runout::figures
