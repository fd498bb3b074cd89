#pragma once
// The map's drawing parts that both the stand-alone hazard map (hazard_map.cpp) and the report's
// map pages (map_page.cpp) draw with: the DEM's hillshade and contours, the cells in the palette's
// colours, the edges of areas, the legend panel. Internal to jobs/figures.
#include <cairo.h>
#include <gdal_priv.h>

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "jobs/figures/hazard_map.hpp"
#include "jobs/figures/pen.hpp"

namespace runout::figures::detail {

extern const Rgb kInk, kRelease, kOutline, kContour, kPath, kForest, kCover, kDam;

/// The DEM as an in-memory raster (north-up, row 0 north).
GDALDatasetUniquePtr dem_raster(const terrain::Grid& g);
/// Hillshade with GDAL's DEM tools, one byte per cell, row 0 north.
std::vector<std::uint8_t> hillshade(GDALDataset& dem, const terrain::Grid& g);

/// An elevation contour in the grid's CRS.
struct Contour {
  double elevation;
  std::vector<std::pair<double, double>> xy;
};
/// Contours every `interval` metres (GDAL's contour generator).
std::vector<Contour> contours(GDALDataset& dem, double interval);

/// Where the grid lies on the page: the grid's top-left corner at (x0, y0), s page units per cell.
struct Frame {
  const terrain::Grid& g;
  double x0, y0, s;
  double px(double x) const { return x0 + (x - g.x_min) / g.dx * s; }
  double py(double y) const { return y0 + (g.y_min + g.ny * g.dx - y) / g.dx * s; }
};

void colour(cairo_t* cr, const Rgb& c, double alpha = 1);
Rgb rgb(const Rgb8& c);
/// A cell's colour: its class's where classed, else the hillshade's grey (`sh` in 0-1), pale
/// outside the domain.
Rgb8 cell_colour(const terrain::Grid& g, const HazardMap& m, std::size_t k, double sh);
/// The edges between cells inside and outside, as one path, in `c` (a white halo first when `halo`).
void draw_edges(cairo_t* cr, const Frame& f, const std::function<bool(int, int)>& inside, const Rgb& c, double width, bool halo = false,
                bool dashed = false);
/// The map's areas as edges: class boundaries, outline, release, forest, cover, dams (widths times `w`).
void draw_area_edges(cairo_t* cr, const Frame& f, const HazardMap& m, double w);
/// The contours, index contours (every fifth) darker, clipped to the grid's frame.
void draw_contours(cairo_t* cr, const Frame& f, const std::vector<Contour>& cs, double interval);
using Box = std::array<double, 4>;  ///< x, y, w, h on the page
bool overlap(const Box& a, const Box& b);
bool within(const Box& a, const Box& frame);
/// The labels placed so far on a map; a new one goes where it overlaps none and stays in the frame.
struct LabelPlacer {
  Box frame;
  std::vector<Box> boxes;
  bool free(const Box& b) const;
};
/// Whether a label's box crosses the outline (cells under it both inside and outside).
bool crosses_outline(const Frame& f, const HazardMap& m, const Box& b);
/// A point's label: beside the point (right, left, above, below), else moved further out with a
/// leader line; the first place that overlaps no label, preferring places off the outline's line.
/// Returns 1 when a leader line was drawn, 0 when placed beside, -1 when no place was free.
int place_label(cairo_t* cr, const Frame& f, const HazardMap& m, double px, double py, const std::string& text, const TextStyle& style,
                LabelPlacer& labels, int& unknown);
/// A scale bar `length` long at (x, y): black, its right half white inside.
void scale_bar(cairo_t* cr, double x, double y, double length, double height);
/// "500 m", "2 km".
std::string length_label(double metres);
/// A point of interest's symbol.
void draw_point(cairo_t* cr, double x, double y);
/// The legend panel (colour bar, line legend, north arrow, parameters) at (x, y); a null `cr` only
/// measures. Returns the panel's bottom.
double draw_panel(cairo_t* cr, double x, double y, const HazardMap& m, double contour_interval, MapLayout& lay);

}  // namespace runout::figures::detail
