#include "jobs/figures/palette.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

namespace runout::figures {

int Palette::class_of(double v) const {
  if (!std::isfinite(v)) return -1;
  int c = -1;
  for (std::size_t k = 0; k < classes.size(); ++k)
    if (v >= classes[k].from) c = int(k);
  return c;
}

namespace {

// A palette from ascending bounds and colours: labels "a – b" and "≥ z" in the unit's numbers.
Palette make(const std::string& title, const std::string& unit, const std::vector<double>& from, const std::vector<Rgb8>& colours) {
  Palette p{title, unit, {}};
  auto num = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", v);
    return std::string(b);
  };
  for (std::size_t k = 0; k < from.size(); ++k) {
    const std::string label = k + 1 < from.size() ? num(from[k]) + " – " + num(from[k + 1]) : "≥ " + num(from[k]);
    p.classes.push_back({from[k], colours[k], label});
  }
  return p;
}

// ColorBrewer's YlOrRd (sequential, colour-blind safe), and its blues for times.
const std::vector<Rgb8> kYlOrRd6 = {{{255, 255, 178}}, {{254, 217, 118}}, {{254, 178, 76}}, {{253, 141, 60}}, {{240, 59, 32}}, {{189, 0, 38}}};
const std::vector<Rgb8> kYlOrRd5 = {{{255, 255, 178}}, {{254, 204, 92}}, {{253, 141, 60}}, {{240, 59, 32}}, {{189, 0, 38}}};
const std::vector<Rgb8> kPuBu6 = {{{4, 90, 141}}, {{43, 140, 190}}, {{116, 169, 207}}, {{166, 189, 219}}, {{208, 209, 230}}, {{241, 238, 246}}};
const std::vector<Rgb8> kYlGnBu5 = {{{255, 255, 204}}, {{161, 218, 180}}, {{65, 182, 196}}, {{44, 127, 184}}, {{37, 52, 148}}};

}  // namespace

const Palette& hazard_palette(const std::string& raster) {
  static const std::map<std::string, Palette> p = {
      {"max_depth", make("maximum flow depth", "m", {0.1, 0.5, 1, 2, 5}, kYlOrRd5)},
      {"max_speed", make("maximum flow speed", "m/s", {1, 5, 10, 20, 30, 50}, kYlOrRd6)},
      {"max_pressure", make("maximum pressure", "kPa", {1, 3, 10, 30, 100, 300}, kYlOrRd6)},
      {"deposit", make("deposit depth", "m", {0.1, 0.5, 1, 2, 5}, kYlGnBu5)},
      {"arrival_time", make("arrival time", "s", {0, 10, 20, 40, 80, 160}, kPuBu6)},
  };
  return p.at(raster);
}

const Palette& probability_palette() {
  static const Palette p = [] {
    Palette q{"probability", "", {}};
    const std::vector<double> from = {1e-9, 0.1, 0.3, 0.5, 0.7, 0.9};
    const char* labels[] = {"> 0 – 0.1", "0.1 – 0.3", "0.3 – 0.5", "0.5 – 0.7", "0.7 – 0.9", "≥ 0.9"};
    for (std::size_t k = 0; k < from.size(); ++k) q.classes.push_back({from[k], kYlOrRd6[k], labels[k]});
    return q;
  }();
  return p;
}

Rgb8 zone_colour(const std::string& name, std::size_t k, std::size_t n) {
  static const std::map<std::string, Rgb8> named = {
      {"yellow", {{255, 221, 0}}}, {"blue", {{0, 92, 230}}},   {"red", {{220, 0, 0}}},      {"orange", {{255, 140, 0}}},
      {"green", {{0, 160, 60}}},   {"purple", {{128, 0, 160}}}, {"brown", {{140, 80, 20}}}, {"grey", {{128, 128, 128}}},
      {"gray", {{128, 128, 128}}}, {"black", {{0, 0, 0}}},      {"white", {{255, 255, 255}}},
  };
  std::string low = name;
  std::transform(low.begin(), low.end(), low.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (auto it = named.find(low); it != named.end()) return it->second;
  const double f = n > 1 ? double(k) / double(n - 1) : 1.0;  // along YlOrRd
  const double pos = f * double(kYlOrRd6.size() - 1);
  const std::size_t a = std::size_t(std::floor(pos)), b = std::min(a + 1, kYlOrRd6.size() - 1);
  Rgb8 c;
  for (int q = 0; q < 3; ++q) c[q] = std::uint8_t(std::lround(kYlOrRd6[a][q] + (pos - a) * (kYlOrRd6[b][q] - kYlOrRd6[a][q])));
  return c;
}

std::string hex(const Rgb8& c) {
  char b[8];
  std::snprintf(b, sizeof b, "#%02x%02x%02x", c[0], c[1], c[2]);
  return b;
}

}  // namespace runout::figures
