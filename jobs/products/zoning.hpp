#pragma once
// Hazard zones from scenarios by return period (scenario `zoning`, docs/user/zoning.md): the rule of
// the Swiss guideline (BFF & EISLF 1984, "Richtlinien zur Berücksichtigung der Lawinengefahr bei
// raumwirksamen Tätigkeiten") applied cell by cell to each scenario's maximum depth and pressure.
#include <cstdint>
#include <string>
#include <vector>

#include "jobs/figures/palette.hpp"
#include "terrain/terrain.hpp"

namespace runout::jobs::products {

/// The rule's numbers: red from this pressure up to design_y, any flow up to frequent_y; a cell
/// counts as reached by a scenario where its maximum depth exceeds reach_depth_m (the outline's
/// threshold).
struct ZoningRule {
  double red_pressure_kpa = 30, frequent_y = 30, design_y = 300, reach_depth_m = 0.1;
};

/// The zones, as class numbers: 0 none, then yellow, blue, red.
enum Zone : std::uint8_t { kNoZone = 0, kYellow = 1, kBlue = 2, kRed = 3 };

/// One scenario's verdict on a cell: red where it reaches with at least red_pressure_kpa and its
/// return period is at most design_y, or reaches at all with a return period of at most frequent_y;
/// blue where it reaches (up to design_y); yellow where it reaches with a longer return period;
/// none where it does not reach.
Zone zone_of(const ZoningRule& r, double return_period_y, double max_depth_m, double max_pressure_kpa);

/// One scenario's rasters on the zoning's grid (NaN or 0: not reached).
struct ZoningScenario {
  double return_period_y = 0;
  const std::vector<double>* max_depth_m = nullptr;
  const std::vector<double>* max_pressure_kpa = nullptr;
};

/// The zones of every cell: the most severe of the scenarios' verdicts; 0 outside the domain.
std::vector<std::uint8_t> zones(const ZoningRule& r, const std::vector<ZoningScenario>& scenarios,
                                const std::vector<std::uint8_t>& outside);

/// The zones' classes (yellow, blue, red: class numbers 1-3) for the raster and the polygons, and
/// their palette for the maps and QGIS, whose labels state the rule ("red: ≥ 30 kPa up to 300 y, or
/// reached up to 30 y").
std::vector<terrain::ValueClass> zone_classes(const ZoningRule& r);
figures::Palette zone_palette(const ZoningRule& r);

}  // namespace runout::jobs::products
