#pragma once
// terrain/: everything geospatial between the user's files and the engine's typed grids.
// DEM ingestion (any raster GDAL reads), choice of the computation CRS (UTM zone of the area's
// centre by default), reprojection and resampling with GDAL's warper (PROJ underneath), clipping to
// the area of interest, release polygons rasterised onto the grid with thickness and slope windows,
// and the raster/vector outputs. Errors are `TerrainError` with a message that names the input.
#include <array>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace runout::terrain {

struct TerrainError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The computation grid: north-up, square cells, in a projected CRS. Row 0 is the SOUTHERN row
/// (the engine's convention: y grows with j); cell (i, j) has its centre at
/// (x_min + (i + 1/2) dx, y_min + (j + 1/2) dx).
struct Grid {
  int nx = 0, ny = 0;
  double dx = 0;
  double x_min = 0, y_min = 0;
  std::string crs_wkt;   ///< WKT of the projected CRS
  std::string crs_name;  ///< e.g. "EPSG:32632"
  std::vector<double> z; ///< elevation [m] (filled from the nearest data where `outside`)
  /// 1 for cells outside the domain: no DEM data there, or outside the area-of-interest polygon.
  std::vector<std::uint8_t> outside;
  std::size_t cells() const { return std::size_t(nx) * std::size_t(ny); }
  double cx(int i) const { return x_min + (i + 0.5) * dx; }
  double cy(int j) const { return y_min + (j + 0.5) * dx; }
};

struct DemRequest {
  std::string dem_path;
  std::string dem_crs;        ///< used when the file has none ("EPSG:2056")
  std::string aoi_path;       ///< optional polygon file
  std::string target_crs;     ///< "" / "utm", "EPSG:nnnn", "dem"
  double resolution = 0;      ///< [m]; 0: the DEM's (in metres)
  std::string resampling = "cubic";
  double memory_budget_bytes = 8.0 * (1ull << 30);
  double bytes_per_cell = 600;  ///< the solver's working set per cell, for the budget check
};

struct DemReport {
  std::string source_crs;
  double source_resolution_m = 0;
  double slope_mean_deg = 0, slope_max_deg = 0, slope_p90_deg = 0;
  double z_min = 0, z_max = 0;
  bool used_aoi = false;
  long cells_without_data = 0;   ///< DEM nodata inside the grid (outside the domain)
  long cells_outside_area = 0;   ///< outside the area-of-interest polygon
};

/// The terrain cache (grid_cache.cpp): a prepared grid and its report saved (atomically; a cache
/// that cannot be written is skipped) and read back bit for bit; load_grid is false for a missing
/// file or one that is not a cache of this version.
void save_grid(const std::string& path, const Grid& g, const DemReport& r);
bool load_grid(const std::string& path, Grid& g, DemReport& r);

/// Read, reproject, resample and clip the DEM. Throws TerrainError.
Grid prepare_grid(const DemRequest& req, DemReport* report = nullptr);

/// Slope angle [deg] per cell from centred differences (one-sided at the edges).
std::vector<double> slope_deg(const Grid& g);

/// One release: polygons (path) with a thickness per polygon, or a thickness raster (any GDAL
/// format and CRS), alone or inside the polygons.
struct ReleaseRequest {
  std::string path;  ///< polygons; may be empty when thickness_raster is given
  std::string crs;   ///< used when the file (polygons or raster) has none
  std::string thickness_raster;  ///< the thickness per point, resampled bilinearly onto the grid
  bool has_thickness = false;
  double thickness = 0;
  std::string thickness_attribute;
  bool vertical = false;  ///< thickness measured vertically (converted to normal: t cos(slope))
  bool has_min_slope = false, has_max_slope = false;
  double min_slope = 0, max_slope = 90;
  std::string min_slope_attribute, max_slope_attribute;
  bool secondary = false;  ///< released when the flow reaches it (each polygon an area of its own)
  double thickness_factor = 1;  ///< every thickness (given, attribute, raster) times this
  /// What the thickness is of, for messages (e.g. "release", or "entrainment.areas[0]" for an erodible
  /// cover, which is read with the releases' rules).
  std::string kind = "release";
};

struct ReleaseReport {
  int polygons = 0;
  long cells = 0;
  double area_m2 = 0;   ///< plan area released: inside the polygons and the slope window
  double volume_m3 = 0; ///< the volume the engines hold: sum of h dx^2 / cos(the grid's slope)
  std::vector<std::string> notes;  ///< e.g. repaired geometries
};

/// A secondary release area: one polygon of a secondary release (or its whole thickness raster).
struct ReleaseArea {
  std::string name;       ///< e.g. "polygon 2 of 'secondary.geojson'"
  std::vector<double> h;  ///< normal thickness per cell (row 0 south)
  double volume_m3 = 0;
};
/// The areas of the secondary releases (ReleaseRequest::secondary), each polygon its own, with the
/// same thickness, slope-window and domain rules as the primary releases. Throws TerrainError.
std::vector<ReleaseArea> secondary_release_areas(const Grid& g, const DemRequest& dem, const std::vector<ReleaseRequest>& releases);

/// Normal release thickness per cell (row 0 south), maximum over overlapping polygons and the
/// primary releases (secondary ones are left out: secondary_release_areas). Each cell carries the
/// volume of the part of it inside the polygon and inside the slope window, the slope taken from
/// `dem` (the grid's DEM request) at the DEM's own resolution on samples finer than the cell
/// (releases.cpp, Lattice), so that the released volume does not depend on the grid.
std::vector<double> rasterize_releases(const Grid& g, const DemRequest& dem, const std::vector<ReleaseRequest>& releases,
                                       ReleaseReport* report = nullptr);

/// A dam or wall (scenario `dams[]`): crest lines, or footprints (polygons), with a height above the
/// ground (for every feature, or per feature from an attribute).
struct DamRequest {
  std::string field;  ///< for messages, e.g. "dams[0]"
  std::string path, crs;
  bool has_height = false;
  double height = 0;            ///< [m]
  std::string height_attribute;
  std::string top_attribute;    ///< each feature's top elevation [m]: the height is the top less the cell's ground
  /// A surface model (DSM raster): the top at each cell's centre (nearest sample), the height the top
  /// less the cell's ground; cells where that is below min_height are not the structure. With `path`
  /// only inside the footprints; without it (empty path) wherever the surface stands that high.
  std::string surface_path;
  double min_height = 2;        ///< [m]
  /// Footprints only: the cells whose centres lie inside (at least the cell holding each footprint's
  /// centroid), not the cells the outline passes through (the 3D engine's structures).
  bool centres_only = false;
};

/// A dam as the depth-averaged engine sees it: a height above the ground on the cells the geometry
/// touches (every cell a crest line passes through, every cell a footprint covers or its outline
/// passes through; the engine's faces to lower cells are steps, engine Sh2dConfig::dam_height). The
/// cells a line passes through touch at least at corners, and the flow crosses only the cells'
/// faces, so a crest line one cell wide blocks every path across it. For crest lines, the flux gauge
/// across the crest (engine FluxGauge): the cells the lines pass through and which of their faces
/// lead to the lines' right (+1) or left (-1): the side of the neighbour's centre seen along the
/// line's right-hand normal in the cell.
struct DamCells {
  std::vector<double> height;  ///< per cell, the dam's height above the ground [m] (0 off the dam)
  std::vector<std::size_t> crest;  ///< crest lines: the cells they pass through
  std::vector<std::array<std::int8_t, 4>> sides;  ///< per crest cell: its W, E, S, N faces' side
  int features = 0;
  bool lines = false;        ///< crest lines (else footprints)
  double length_m = 0;       ///< crest lines: their length on the grid
  long cells = 0;            ///< the dam's cells
};
/// Throws TerrainError naming rq.field (unreadable file, no CRS, a geometry neither line nor polygon,
/// lines mixed with polygons, a height missing or outside (0, 100] m, a top below the ground, a dam on
/// no cell of the domain).
DamCells rasterize_dam(const Grid& g, const DamRequest& rq);

/// What a raster band says about itself (GDAL's band description, unit type and metadata): QGIS
/// shows the description as the band's name and the unit beside its values.
struct BandInfo {
  std::string description;  ///< e.g. "maximum flow depth normal to the surface"
  std::string unit;         ///< e.g. "m", "kPa"; "" for classes
  std::vector<std::pair<std::string, std::string>> metadata = {};  ///< further items (e.g. TIME_S)
};
/// The cells (row 0 south) whose centres lie inside any polygon of the vector file `path` (its own
/// CRS, else `crs`); cells outside the domain are 0. Errors name `what` (e.g. "observations.outline_path").
std::vector<std::uint8_t> rasterize_polygons(const Grid& g, const std::string& path, const std::string& crs, const std::string& what);

/// What a raster band says, Float32, DEFLATE, CRS and nodata set, overviews when larger than a
/// tile; NaN cells are written as nodata.
void write_cog(const std::string& path, const Grid& g, const std::vector<double>& values, const BandInfo& band);

/// A field of a time cube: its variable name, long name, unit and its values at frame b (row 0 south).
struct CubeField {
  std::string name, long_name, unit;
  std::function<std::vector<double>(std::size_t)> values;
};
/// The frames as one NetCDF-4 file with the CF conventions (time, y, x; coordinate variables, the
/// grid's CRS as grid mapping; Float32, DEFLATE, nodata -9999 for NaN and the cells outside the
/// domain). Time is in seconds since the release, which CF's units put at 1970-01-01. Throws TerrainError.
void write_time_cube(const std::string& path, const Grid& g, const std::vector<double>& times_s, const std::vector<CubeField>& fields);

/// A multi-band Cloud Optimized GeoTIFF on the grid (DEFLATE, BigTIFF when needed), Float32, nodata -9999
/// (NaN and the cells outside the domain): band k holds values(k) (row 0 south) and bands[k]'s
/// description, unit and metadata; `dataset_metadata` goes to the file. Bands are written one at a
/// time into a tiled GeoTIFF beside it (`path`.part.tif, removed), so that a long series never needs
/// to be in memory at once.
void write_band_stack(const std::string& path, const Grid& g, const std::vector<BandInfo>& bands,
                      const std::function<std::vector<double>(std::size_t)>& values,
                      const std::vector<std::pair<std::string, std::string>>& dataset_metadata);

/// One class of a class raster or of class polygons: class k (1-based) is cells whose value lies in
/// [from, to) (to NaN: no upper bound).
struct ValueClass {
  std::string name;
  double from = 0, to = 0;
  std::uint8_t rgb[3] = {0, 0, 0};
};
/// A class raster as a cloud-optimised GeoTIFF, Byte: 0 in no class, k for `classes[k-1]`, 255
/// outside the domain (nodata), with the class names as GDAL category names and a colour table.
void write_class_cog(const std::string& path, const Grid& g, const std::vector<std::uint8_t>& cls,
                     const std::vector<ValueClass>& classes, const BandInfo& band);

struct ClassArea {
  int polygons = 0;
  double area_m2 = 0;
};
/// Polygons of each class of `cls` (0: none): a GeoPackage in the grid's CRS and, unless the grid's
/// CRS is local, GeoJSON in WGS84, with the attributes name, from_<unit>, to_<unit> (null when open)
/// and area_m2. Returns each class's polygons and area (index k-1 for class k).
std::vector<ClassArea> write_class_polygons(const std::string& geojson_path, const std::string& gpkg_path, const std::string& layer,
                                            const Grid& g, const std::vector<std::uint8_t>& cls, const std::vector<ValueClass>& classes,
                                            const std::string& unit);

struct OutlineReport {
  int polygons = 0;
  double area_m2 = 0;
  bool geojson = false;  ///< written (not for a grid in a local CRS)
};
/// Add `qml` (a QGIS style document) to the GeoPackage's layer_styles table as the default style of
/// `layer` (QGIS's table: QGIS applies it when it opens the layer). Throws TerrainError.
void add_layer_style(const std::string& gpkg_path, const std::string& layer, const std::string& style_name, const std::string& qml);

/// Outline of the cells where values > threshold: GeoJSON in WGS84 lon/lat (unless the grid's CRS is
/// local) and GeoPackage in the grid's CRS.
OutlineReport write_outline(const std::string& geojson_path, const std::string& gpkg_path, const Grid& g,
                            const std::vector<double>& values, double threshold);

/// ESRI ASCII grid of `values` (computed on `g`) on the raster grid of the file `template_path` (its
/// size, extent and CRS; resampled bilinearly where the grids differ), nodata -9999. For benchmark
/// exports that demand the input DEM's grid (ISeeSnow).
void write_ascii_on(const std::string& path, const std::string& template_path, const Grid& g, const std::vector<double>& values);

/// Band 1 of the raster `path` on the grid (row 0 south; nodata as NaN): read as it is when it lies
/// on the grid, else resampled onto it (nearest neighbour, GDAL's warper). Errors name `what`.
std::vector<double> read_raster_on(const std::string& path, const Grid& g, const std::string& what);

/// The grid of a raster written on a run's grid (elevation.tif): its size, cells, CRS, band 1 as the
/// ground and its nodata cells as outside the domain. Errors name `what`.
Grid grid_of_raster(const std::string& path, const std::string& what);

/// `values` with the cells outside the domain (Grid::outside) as NaN: nodata in every raster written.
std::vector<double> masked_outside(const Grid& g, const std::vector<double>& values);

}  // namespace runout::terrain
