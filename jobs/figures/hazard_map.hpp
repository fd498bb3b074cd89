#pragma once
// The report-ready map of one hazard quantity on the terrain, as PNG and PDF (Cairo, Pango): the
// hillshade with elevation contours (GDAL's contour generator), the quantity in its palette's
// classes with a colour bar that shows the same colours, the release and the runout outline,
// boundaries of classes (e.g. the pressure zones), named points of interest, coordinate ticks in
// the grid's CRS, a scale bar, a north arrow, the title (wrapped, never cut) and a parameter block.
#include <array>
#include <string>
#include <vector>

#include "jobs/figures/palette.hpp"
#include "terrain/terrain.hpp"

// Cairo's context, declared as cairo.h does (the header itself stays inside jobs/figures).
typedef struct _cairo cairo_t;

namespace runout::figures {

struct MapPoint {
  std::string name;
  double x = 0, y = 0;  ///< in the grid's CRS
};

/// Lines around the cells of a class raster's classes (value k + 1 is class k), in the class's colour.
struct ClassBoundaries {
  std::vector<std::uint8_t> cls;  ///< per cell, row 0 south
  Palette palette;
};

struct HazardMap {
  std::string title;                    ///< UTF-8, wrapped to the page's width
  Palette palette;                      ///< the quantity's classes and the colour bar
  std::vector<double> values;           ///< per cell (row 0 south); NaN or below the first class: not coloured
  std::vector<double> release;          ///< release thickness per cell (> 0: released)
  std::vector<std::uint8_t> resistance;  ///< cells of resistance areas (forest), outlined; empty: none
  std::vector<std::uint8_t> cover;       ///< cells of erodible cover (entrainment), outlined; empty: none
  std::vector<std::uint8_t> dams;        ///< cells raised by dams and walls, outlined; empty: none
  std::vector<std::uint8_t> structures;  ///< cells of structures (buildings, pylons), outlined; empty: none
  std::vector<std::uint8_t> nest;        ///< cells of a 3D nest (its values the 3D engine's), outlined dashed; empty: none
  std::vector<double> max_depth;        ///< for the outline
  double outline_threshold = 0.1;       ///< [m]
  std::vector<ClassBoundaries> boundaries;
  std::vector<MapPoint> points;
  std::vector<std::pair<double, double>> path;  ///< the avalanche path's vertices in the grid's CRS (drawn when given)
  std::vector<MapPoint> path_marks;             ///< named points on it (the runout point, the beta point)
  std::vector<std::string> parameters;  ///< the parameter block, one line each
  /// Under the colour bar: where the quantity is coloured (e.g. "coloured inside the outline only");
  /// empty: nothing said.
  std::string colour_note;
  /// Under the colour bar: the largest finite value of `values` in the palette's unit (so that a
  /// top class's "≥ 300" says how far it goes).
  bool show_maximum = false;
};

/// `values` with every cell where `max_depth` is at most `threshold` set to NaN: a quantity coloured
/// only inside the runout outline.
std::vector<double> inside_outline(const std::vector<double>& values, const std::vector<double>& max_depth, double threshold);

/// Where things were drawn on the PNG (pixels), for checks.
struct MapLayout {
  int width = 0, height = 0;
  double map_x = 0, map_y = 0, cell_px = 0;  ///< the map's top-left corner and pixels per cell
  std::vector<std::array<double, 4>> swatches;  ///< colour bar boxes x, y, w, h, one per class
  std::array<double, 4> title{};                ///< the title's box
  int title_lines = 1, unknown_glyphs = 0;      ///< over every text drawn
  double contour_interval_m = 0;
  /// The labels of the points and path marks (x, y, w, h), in the map's frame, no two overlapping
  /// and, where a place allowed it, none across the outline's line.
  std::vector<std::array<double, 4>> label_boxes;
};

/// A map on a report page (map_page.cpp): the extent drawn at a stated scale 1:N (the smallest of
/// 1:1000, 2000, 2500, 5000, 10 000, 12 500, 20 000, 25 000, 50 000, 100 000, 200 000 at which it fits
/// the room), its cells as one raster of `dpi`, labelled index contours, coordinate ticks, a scale bar
/// and the legend panel.
struct MapPageSpec {
  double x = 0, y = 0, w = 0, h = 0;  ///< the room for the map on the page [pt]
  double panel_x = 0, panel_y = 0, panel_scale = 0.75;  ///< the legend panel's top-left [pt] and its size
  double dpi = 300;
  std::array<double, 4> extent{};  ///< x_min, y_min, x_max, y_max shown (grid's CRS); all 0: the grid
};
struct MapPageLayout {
  int scale = 0;                  ///< 1:scale
  std::array<double, 4> frame{};  ///< the map's box on the page [pt]
  int image_w = 0, image_h = 0;   ///< the cells' raster [pixels]
  int contour_labels = 0, leader_lines = 0;
  std::vector<std::array<double, 4>> label_boxes;  ///< every label placed (x, y, w, h); no two overlap
  int unknown_glyphs = 0;
};
/// Draw the map page's map into `cr` (a PDF page of points). Throws terrain::TerrainError when the
/// extent does not fit the room at 1:200 000.
MapPageLayout draw_map_page(cairo_t* cr, const terrain::Grid& g, const HazardMap& m, const MapPageSpec& spec);

/// Draw the map into `png_path` and `pdf_path` (either may be empty). Throws terrain::TerrainError.
MapLayout draw_hazard_map(const std::string& png_path, const std::string& pdf_path, const terrain::Grid& g, const HazardMap& m);

}  // namespace runout::figures
