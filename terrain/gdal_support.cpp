#include "terrain/gdal_support.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <sstream>

namespace runout::terrain::detail {

void init_gdal() {
  static std::once_flag once;
  std::call_once(once, [] {
    GDALAllRegister();
    CPLSetErrorHandler(CPLQuietErrorHandler);  // errors are read back and reported by us
  });
}

std::string gdal_message() {
  const char* m = CPLGetLastErrorMsg();
  return (m && *m) ? std::string(": ") + m : std::string();
}

std::string fmt(double v, int prec) {
  std::ostringstream o;
  if (std::abs(v) >= 1e9) {  // no 300-digit numbers in messages
    o.precision(4);
    o << v;
    return o.str();
  }
  o.setf(std::ios::fixed);
  o.precision(prec);
  o << v;
  return o.str();
}

OGRSpatialReference srs_from(const std::string& text, const std::string& what) {
  OGRSpatialReference s;
  if (text == "local") {  // local Cartesian metres: synthetic terrain, surveys without georeference
    s.SetLocalCS("local metres");
    s.SetLinearUnits(SRS_UL_METER, 1.0);
    return s;
  }
  if (s.SetFromUserInput(text.c_str()) != OGRERR_NONE)
    throw TerrainError(what + ": unknown CRS '" + text + "' (use e.g. EPSG:2056 or a WKT/PROJ string)");
  s.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return s;
}

OGRSpatialReference input_crs(const OGRSpatialReference* own, const std::string& given, const std::string& given_what,
                              const std::string& no_crs) {
  if (own && !own->IsEmpty()) {  // the file's own CRS wins; a given one is only for files without
    OGRSpatialReference s = *own;
    s.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    return s;
  }
  if (given.empty()) throw TerrainError(no_crs);
  return srs_from(given, given_what);
}

std::unique_ptr<GDALWarpAppOptions, decltype(&GDALWarpAppOptionsFree)> warp_options(std::vector<std::string> args) {
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::unique_ptr<GDALWarpAppOptions, decltype(&GDALWarpAppOptionsFree)> o(GDALWarpAppOptionsNew(argv.data(), nullptr),
                                                                           GDALWarpAppOptionsFree);
  if (!o) throw TerrainError("internal: warp options rejected" + gdal_message());
  return o;
}

OGRSpatialReference wgs84() {
  OGRSpatialReference s;
  s.importFromEPSG(4326);
  s.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return s;
}

std::string wkt(const OGRSpatialReference& s) {
  char* w = nullptr;
  s.exportToWkt(&w);
  std::string out = w ? w : "";
  CPLFree(w);
  return out;
}

std::string crs_name(const OGRSpatialReference& s) {
  if (s.IsLocal()) return "local metres";
  const char* auth = s.GetAuthorityName(nullptr);
  const char* code = s.GetAuthorityCode(nullptr);
  if (auth && code) return std::string(auth) + ":" + code;
  const char* n = s.GetName();
  return n ? n : "unnamed CRS";
}

// A coordinate transformation; nullptr for two local CRSs (the identity: they have no datum to relate).
std::unique_ptr<OGRCoordinateTransformation> transform(const OGRSpatialReference& from, const OGRSpatialReference& to,
                                                       const std::string& what) {
  if (from.IsLocal() || to.IsLocal()) {
    if (from.IsLocal() && to.IsLocal()) return nullptr;
    throw TerrainError(what + ": a local CRS cannot be related to " + (from.IsLocal() ? crs_name(to) : crs_name(from)) +
                       "; give every input in the same local CRS");
  }
  std::unique_ptr<OGRCoordinateTransformation> t(OGRCreateCoordinateTransformation(&from, &to));
  if (!t) throw TerrainError(what + ": no coordinate transformation between the CRSs" + gdal_message());
  return t;
}

GDALDatasetUniquePtr mem_raster(const Grid& g, GDALDataType type) {
  auto* drv = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDatasetUniquePtr ds(drv->Create("", g.nx, g.ny, 1, type, nullptr));
  double gt[6] = {g.x_min, g.dx, 0, g.y_min + g.ny * g.dx, 0, -g.dx};
  ds->SetGeoTransform(gt);
  ds->SetProjection(g.crs_wkt.c_str());
  return ds;
}

// A feature's numeric attribute; errors name `what` and list the attributes there are.
double field_value(OGRFeature& f, const std::string& attr, const std::string& what) {
  const int idx = f.GetFieldIndex(attr.c_str());
  if (idx < 0) {
    std::string names;
    for (int k = 0; k < f.GetFieldCount(); ++k) names += (k ? ", " : "") + std::string(f.GetFieldDefnRef(k)->GetNameRef());
    throw TerrainError(what + ": no attribute '" + attr + "' (attributes: " + (names.empty() ? "none" : names) + ")");
  }
  if (!f.IsFieldSetAndNotNull(idx)) throw TerrainError(what + ": attribute '" + attr + "' is empty");
  const OGRFieldType type = f.GetFieldDefnRef(idx)->GetType();
  if (type == OFTString) {  // GDAL reads a text that is not a number as 0
    const std::string text = f.GetFieldAsString(idx);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    while (end && *end && std::isspace(static_cast<unsigned char>(*end))) ++end;
    if (text.empty() || end == text.c_str() || *end) throw TerrainError(what + ": attribute '" + attr + "' is not a number: '" + text + "'");
    return v;
  }
  if (type != OFTInteger && type != OFTInteger64 && type != OFTReal)
    throw TerrainError(what + ": attribute '" + attr + "' is not a number (" + OGRFieldDefn::GetFieldTypeName(type) + ")");
  return f.GetFieldAsDouble(idx);
}

OGRSpatialReference grid_crs(const Grid& g) {
  OGRSpatialReference dst;
  dst.importFromWkt(g.crs_wkt.c_str());
  dst.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return dst;
}

}  // namespace runout::terrain::detail
