#include "terrain/points.hpp"

#include <cmath>

#include <ogrsf_frmts.h>

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

std::vector<std::pair<double, double>> read_line(const Grid& g, const std::string& path, const std::string& crs, const std::string& what) {
  detail::init_gdal();
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  if (!ds) throw TerrainError(what + ": cannot read '" + path + "' as a vector file" + detail::gdal_message());
  OGRSpatialReference dst;
  dst.importFromWkt(g.crs_wkt.c_str());
  dst.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  for (auto* layer : ds->GetLayers()) {
    const std::string file = what + " '" + path + "'";
    const auto src = detail::input_crs(layer->GetSpatialRef(), crs, file, file + " has no CRS and none is given");
    auto ct = detail::transform(src, dst, file);
    for (auto& f : layer) {
      const OGRGeometry* geom = f->GetGeometryRef();
      if (!geom || wkbFlatten(geom->getGeometryType()) != wkbLineString) continue;
      std::unique_ptr<OGRGeometry> line(geom->clone());
      if (ct && line->transform(ct.get()) != OGRERR_NONE) throw TerrainError(file + ": cannot transform it to " + g.crs_name);
      const auto* ls = line->toLineString();
      std::vector<std::pair<double, double>> out;
      for (int k = 0; k < ls->getNumPoints(); ++k) out.emplace_back(ls->getX(k), ls->getY(k));
      if (out.size() < 2) throw TerrainError(file + ": its line has fewer than two vertices");
      return out;
    }
  }
  throw TerrainError(what + ": '" + path + "' holds no line");
}

}  // namespace runout::terrain
