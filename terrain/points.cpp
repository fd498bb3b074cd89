#include "terrain/points.hpp"

#include <cmath>

#include "terrain/gdal_support.hpp"

namespace runout::terrain {

GridPoint place_point(const Grid& g, double x, double y, const std::string& crs, const std::string& what) {
  detail::init_gdal();
  GridPoint p{x, y};
  if (!crs.empty()) {
    const auto from = detail::srs_from(crs, what + ".crs");
    OGRSpatialReference to;
    if (g.crs_wkt.empty()) to.SetLocalCS("local metres");
    else if (to.importFromWkt(g.crs_wkt.c_str()) != OGRERR_NONE) throw TerrainError(what + ": the grid's CRS cannot be read");
    to.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    const auto tr = detail::transform(from, to, what);
    if (tr && !tr->Transform(1, &p.x, &p.y))
      throw TerrainError(what + ": (" + detail::fmt(x, 6) + ", " + detail::fmt(y, 6) + ") in " + crs + " cannot be transformed to the grid's CRS " +
                         g.crs_name);
  }
  const double fi = (p.x - g.x_min) / g.dx, fj = (p.y - g.y_min) / g.dx;
  if (!(fi >= 0 && fi < g.nx && fj >= 0 && fj < g.ny))
    throw TerrainError(what + ": (" + detail::fmt(p.x) + ", " + detail::fmt(p.y) + ") in " + g.crs_name + " lies outside the grid (x " +
                       detail::fmt(g.x_min) + " to " + detail::fmt(g.x_min + g.nx * g.dx) + ", y " + detail::fmt(g.y_min) + " to " +
                       detail::fmt(g.y_min + g.ny * g.dx) + ")");
  p.i = int(std::floor(fi));
  p.j = int(std::floor(fj));
  if (g.outside[std::size_t(p.j) * std::size_t(g.nx) + std::size_t(p.i)])
    throw TerrainError(what + ": (" + detail::fmt(p.x) + ", " + detail::fmt(p.y) + ") lies outside the domain (the area of interest or the DEM's data)");
  return p;
}

}  // namespace runout::terrain
