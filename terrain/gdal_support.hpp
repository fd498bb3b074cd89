#pragma once
// What the terrain room's files share about GDAL and OGR: start-up, error text, CRS handling,
// number formatting for messages and in-memory rasters on a Grid. Internal to terrain/.
#include <gdal_priv.h>
#include <gdal_utils.h>
#include <ogr_spatialref.h>

#include <memory>
#include <string>
#include <vector>

#include "terrain/terrain.hpp"

namespace runout::terrain::detail {

/// Registers GDAL's drivers once; GDAL's own error printing is off (errors are read back).
void init_gdal();
/// ": <GDAL's last error>" or "".
std::string gdal_message();
/// A number for messages, `prec` decimals (4 significant digits for huge values).
std::string fmt(double v, int prec = 1);
/// A CRS from user input ("EPSG:2056", WKT, PROJ, or "local" for local Cartesian metres); errors
/// name `what`.
OGRSpatialReference srs_from(const std::string& text, const std::string& what);
/// An input's CRS: its own (`own`, when it has one), else the user's `given` (errors naming
/// `given_what`); with neither, a TerrainError saying `no_crs`.
OGRSpatialReference input_crs(const OGRSpatialReference* own, const std::string& given, const std::string& given_what,
                              const std::string& no_crs);
OGRSpatialReference wgs84();
/// The grid's CRS, x first (easting, or longitude).
OGRSpatialReference grid_crs(const Grid& g);
std::string wkt(const OGRSpatialReference& s);
/// "EPSG:32632", the CRS's name, or "local metres".
std::string crs_name(const OGRSpatialReference& s);
/// A coordinate transformation; nullptr for two local CRSs (the identity: they have no datum to relate).
std::unique_ptr<OGRCoordinateTransformation> transform(const OGRSpatialReference& from, const OGRSpatialReference& to,
                                                       const std::string& what);
/// GDAL's warper options from gdalwarp's command-line arguments.
std::unique_ptr<GDALWarpAppOptions, decltype(&GDALWarpAppOptionsFree)> warp_options(std::vector<std::string> args);
/// The fixed spacing [m] of the surface on which the release's slope window is evaluated: the DEM's
/// pixel size (in metres on the ground for a geographic DEM) / 8, not below 1 m (a DEM finer than
/// 1 m: its own pixel size). It depends on the DEM alone, never on the grid (the grid's cell size
/// only for a DEM without a georeferenced pixel size).
double slope_spacing(const DemRequest& req, const Grid& g);
/// The DEM of `req` in the grid's CRS at spacing `res` (slope_spacing), resampled as the grid is
/// (req.resampling: its continuous surface, e.g. cubic), over [x0, x1] x [y0, y1] of the grid's CRS
/// (widened to whole cells and to at least 3 x 3); cells without data take the elevation of the
/// nearest data.
Grid dem_surface(const DemRequest& req, const Grid& g, double res, double x0, double y0, double x1, double y1);
/// The number in attribute `attr` of feature `f` (a text that reads as a number counts); errors name
/// `what` and list the attributes the feature has.
double field_value(OGRFeature& f, const std::string& attr, const std::string& what);
/// A one-band in-memory raster on the grid (north-up, the grid's CRS).
GDALDatasetUniquePtr mem_raster(const Grid& g, GDALDataType type);
/// The rows of a raster, north first (GDAL's order), from `value(k)` of cell k (row 0 south).
template <class T, class F>
std::vector<T> north_first(const Grid& g, F value) {
  std::vector<T> rows(g.cells());
  for (int r = 0; r < g.ny; ++r)
    for (int i = 0; i < g.nx; ++i) rows[std::size_t(r) * g.nx + i] = value(std::size_t(g.ny - 1 - r) * g.nx + i);
  return rows;
}

}  // namespace runout::terrain::detail
