#pragma once
// The colour classes of every quantity a run maps: one table that the maps, the QGIS styles (.qml)
// and the colour bars all draw from, so that what a map shows and what its legend and QGIS say agree.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace runout::figures {

using Rgb8 = std::array<std::uint8_t, 3>;

/// A class of values [from, next class's from); the last class has no upper bound.
struct ColourClass {
  double from = 0;
  Rgb8 colour{};
  std::string label;  ///< e.g. "0.5 – 1"
};

struct Palette {
  std::string title;  ///< e.g. "maximum flow depth"
  std::string unit;   ///< e.g. "m"
  std::vector<ColourClass> classes;  ///< ascending
  /// The class of v (the last whose `from` is at most v); -1 below the first or not finite.
  int class_of(double v) const;
};

/// The palette of a hazard raster by its name (max_depth, max_speed, max_pressure [kPa], deposit,
/// arrival_time). Throws std::out_of_range for another name.
const Palette& hazard_palette(const std::string& raster);

/// The palette of a probability (0-1; an ensemble's probability of exceedance): 0 is not coloured.
const Palette& probability_palette();

/// A named colour (yellow, blue, red, orange, green, purple, brown, grey, black, white) or, for
/// another name, the colour of rank `k` of `n` on a yellow-to-dark-red ramp.
Rgb8 zone_colour(const std::string& name, std::size_t k, std::size_t n);

/// "#rrggbb"
std::string hex(const Rgb8& c);

}  // namespace runout::figures
