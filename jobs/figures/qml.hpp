#pragma once
// QGIS layer styles (.qml) beside the rasters, from the same palettes the maps draw with: QGIS
// opens a raster with the style of the same name beside it.
#include <string>

#include "jobs/figures/palette.hpp"

namespace runout::figures {

/// A single-band raster of values in the palette's classes (QGIS's discrete colour ramp; values below
/// the first class transparent).
void write_qml_ramp(const std::string& path, const Palette& p);

/// A class raster whose value k + 1 is the palette's class k (QGIS's paletted renderer; 0 transparent).
void write_qml_classes(const std::string& path, const Palette& p);

}  // namespace runout::figures
