#pragma once
// QGIS layer styles (.qml) beside the rasters and for the polygons, from the same palettes the maps
// draw with: QGIS opens a raster with the style of the same name beside it, and a GeoPackage layer
// with the default style in its layer_styles table.
#include <string>
#include <vector>

#include "jobs/figures/palette.hpp"

namespace runout::figures {

/// A single-band raster of values in the palette's classes (QGIS's discrete colour ramp; values below
/// the first class transparent).
void write_qml_ramp(const std::string& path, const Palette& p);

/// A class raster whose value k + 1 is the palette's class k (QGIS's paletted renderer; 0 transparent).
void write_qml_classes(const std::string& path, const Palette& p);

/// The style of class polygons whose field `name` holds the palette's class names (`names[k]` for
/// class k): QGIS's categorised renderer, each class filled in its colour at 45 % opacity and
/// outlined in it. Returns the QML document (also for a GeoPackage's layer_styles).
std::string qml_polygon_classes(const Palette& p, const std::vector<std::string>& names);

/// The style of the runout outline: no fill, a line in the maps' outline colour.
std::string qml_outline();

/// Write a QML document to `path`. Throws std::runtime_error.
void write_qml(const std::string& path, const std::string& qml);

}  // namespace runout::figures
