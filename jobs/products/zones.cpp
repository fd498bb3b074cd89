#include "jobs/products/zones.hpp"

#include <cmath>
#include <cstdio>

namespace runout::jobs::products {
std::string legend_number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

namespace {

std::string num(double v) { return legend_number(v); }

}  // namespace

std::string zone_label(const terrain::ValueClass& c) {
  return c.name + ": " + (std::isfinite(c.to) ? num(c.from) + " – " + num(c.to) : "≥ " + num(c.from)) + " kPa";
}

ZoneMap pressure_zones(const std::vector<ZoneThreshold>& zones, const std::vector<double>& p) {
  ZoneMap z;
  z.palette.title = "pressure zones";
  z.palette.unit = "kPa";
  for (std::size_t k = 0; k < zones.size(); ++k) {
    terrain::ValueClass c;
    c.name = zones[k].name;
    c.from = zones[k].from_kpa;
    c.to = k + 1 < zones.size() ? zones[k + 1].from_kpa : NAN;
    const auto rgb = figures::zone_colour(c.name, k, zones.size());
    for (int q = 0; q < 3; ++q) c.rgb[q] = rgb[q];
    z.classes.push_back(c);
    z.palette.classes.push_back({c.from, rgb, zone_label(c)});
  }
  z.cls.assign(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) z.cls[i] = std::uint8_t(z.palette.class_of(p[i]) + 1);
  return z;
}

}  // namespace runout::jobs::products
