#include "jobs/products/zoning.hpp"

#include "jobs/products/zones.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace runout::jobs::products {
namespace {

std::string num(double v) { return legend_number(v); }

}  // namespace

Zone zone_of(const ZoningRule& r, double t, double depth, double pressure) {
  if (!(depth > r.reach_depth_m)) return kNoZone;
  if (t > r.design_y) return kYellow;
  if (t <= r.frequent_y || pressure >= r.red_pressure_kpa) return kRed;
  return kBlue;
}

std::vector<std::uint8_t> zones(const ZoningRule& r, const std::vector<ZoningScenario>& scenarios, const std::vector<std::uint8_t>& outside) {
  const std::size_t n = scenarios.empty() ? 0 : scenarios.front().max_depth_m->size();
  std::vector<std::uint8_t> z(n, kNoZone);
  for (const auto& s : scenarios)
    for (std::size_t k = 0; k < n; ++k) {
      if (!outside.empty() && outside[k]) continue;
      z[k] = std::max<std::uint8_t>(z[k], zone_of(r, s.return_period_y, (*s.max_depth_m)[k], (*s.max_pressure_kpa)[k]));
    }
  return z;
}

std::vector<terrain::ValueClass> zone_classes(const ZoningRule&) {
  const char* names[3] = {"yellow", "blue", "red"};
  std::vector<terrain::ValueClass> out;
  for (int k = 0; k < 3; ++k) {
    terrain::ValueClass c;
    c.name = names[k];
    c.from = k + 1;
    c.to = k < 2 ? k + 2 : NAN;
    const auto rgb = figures::zone_colour(names[k], std::size_t(k), 3);
    for (int q = 0; q < 3; ++q) c.rgb[q] = rgb[q];
    out.push_back(c);
  }
  return out;
}

figures::Palette zone_palette(const ZoningRule& r) {
  const std::string design = num(r.design_y) + " y";
  const std::string labels[3] = {
      "yellow: reached only beyond " + design,
      "blue: reached up to " + design + ", below " + num(r.red_pressure_kpa) + " kPa",
      "red: ≥ " + num(r.red_pressure_kpa) + " kPa up to " + design + ", or reached up to " + num(r.frequent_y) + " y"};
  figures::Palette p;
  p.title = "hazard zones";
  const auto classes = zone_classes(r);
  for (std::size_t k = 0; k < classes.size(); ++k) {
    const auto& c = classes[k];
    p.classes.push_back({c.from, {{c.rgb[0], c.rgb[1], c.rgb[2]}}, labels[k]});
  }
  return p;
}

}  // namespace runout::jobs::products
