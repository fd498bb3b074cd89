#pragma once
// Pressure hazard zones (outputs.pressure_zones_kpa): each cell's class by its maximum pressure,
// the classes as the terrain room writes them (raster, polygons) and as the maps and QGIS draw them.
#include <cstdint>
#include <string>
#include <vector>

#include "jobs/figures/palette.hpp"
#include "jobs/scenario/scenario.hpp"
#include "terrain/terrain.hpp"

namespace runout::jobs::products {

struct ZoneMap {
  std::vector<std::uint8_t> cls;             ///< per cell: 0 in no zone, k + 1 in zone k
  std::vector<terrain::ValueClass> classes;  ///< zone k: [from_kpa, next zone's from_kpa) [kPa]
  figures::Palette palette;                  ///< the same classes for the maps and the QGIS style
};

/// The zones of `max_pressure_kpa` (per cell, [kPa]; NaN in none). Zone k holds the cells whose value
/// is at least zones[k].from_kpa and below zones[k + 1].from_kpa.
ZoneMap pressure_zones(const std::vector<ZoneThreshold>& zones, const std::vector<double>& max_pressure_kpa);

/// A number as the legends write it ("30", "0.5", "1e+03": printf's %g).
std::string legend_number(double v);

/// "blue: 3 – 30 kPa", "red: ≥ 30 kPa"
std::string zone_label(const terrain::ValueClass& c);

}  // namespace runout::jobs::products
