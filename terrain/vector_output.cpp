// What a run writes on its grid as polygons: the runout outline and the polygons of value classes
// (pressure zones), each as a GeoPackage in the grid's CRS and GeoJSON in WGS84 (RFC 7946).
#include <gdal_alg.h>
#include <gdal_priv.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "terrain/gdal_support.hpp"
#include "terrain/terrain.hpp"

namespace runout::terrain {

using namespace detail;

namespace {

// The polygons of the non-zero cells of `cls`, their class in the field "class", in an in-memory
// layer in the grid's CRS.
struct ClassLayer {
  GDALDatasetUniquePtr ds;
  OGRLayer* layer = nullptr;
  OGRSpatialReference srs;
};
ClassLayer polygonize(const Grid& g, const std::vector<std::uint8_t>& cls, const std::string& what) {
  ClassLayer out;
  auto raster = mem_raster(g, GDT_Byte);
  auto rows = north_first<std::uint8_t>(g, [&](std::size_t k) { return cls[k]; });
  if (raster->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, g.nx, g.ny, rows.data(), g.nx, g.ny, GDT_Byte, 0, 0) != CE_None)
    throw TerrainError(what + ": writing the classes failed" + gdal_message());
  out.srs.importFromWkt(g.crs_wkt.c_str());
  out.srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  auto* mem = GetGDALDriverManager()->GetDriverByName("Memory");
  out.ds.reset(mem->Create("", 0, 0, 0, GDT_Unknown, nullptr));
  out.layer = out.ds->CreateLayer("classes", &out.srs, wkbPolygon, nullptr);
  OGRFieldDefn fd("class", OFTInteger);
  out.layer->CreateField(&fd);
  auto* band = raster->GetRasterBand(1);
  if (GDALPolygonize(band, band, out.layer, 0, nullptr, nullptr, nullptr) != CE_None)
    throw TerrainError(what + ": polygonising failed" + gdal_message());
  return out;
}

// The polygons of `in` as a new file of `driver` (GPKG or GeoJSON), transformed by `ct` (null: as
// they are), with the attributes name, from_<unit>, to_<unit> and area_m2 (the plan area in the
// grid's CRS).
void write_layer(const ClassLayer& in, const char* driver, const std::string& path, const std::string& layer_name,
                 const OGRSpatialReference& srs, OGRCoordinateTransformation* ct, const std::vector<ValueClass>& classes,
                 const std::string& unit, std::vector<ClassArea>* areas) {
  auto* drv = GetGDALDriverManager()->GetDriverByName(driver);
  GDALDatasetUniquePtr ds(drv->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  if (!ds) throw TerrainError("writing '" + path + "' failed" + gdal_message());
  const char* gj[] = {"RFC7946=YES", nullptr};
  OGRSpatialReference layer_srs(srs);
  OGRLayer* out = ds->CreateLayer(layer_name.c_str(), &layer_srs, wkbPolygon, ct ? const_cast<char**>(gj) : nullptr);
  if (!out) throw TerrainError("writing '" + path + "' failed" + gdal_message());
  OGRFieldDefn name("name", OFTString), from(("from_" + unit).c_str(), OFTReal), to(("to_" + unit).c_str(), OFTReal),
      area("area_m2", OFTReal);
  for (auto* f : {&name, &from, &to, &area}) out->CreateField(f);
  in.layer->ResetReading();
  for (auto& f : in.layer) {
    const OGRGeometry* geom = f->GetGeometryRef();
    const int k = f->GetFieldAsInteger("class");
    if (!geom || k < 1 || std::size_t(k) > classes.size()) continue;
    const ValueClass& c = classes[std::size_t(k) - 1];
    const double a = geom->toPolygon()->get_Area();
    OGRFeature o(out->GetLayerDefn());
    o.SetField("name", c.name.c_str());
    o.SetField(("from_" + unit).c_str(), c.from);
    if (std::isfinite(c.to)) o.SetField(("to_" + unit).c_str(), c.to);
    else o.SetFieldNull(o.GetFieldIndex(("to_" + unit).c_str()));
    o.SetField("area_m2", a);
    std::unique_ptr<OGRGeometry> w(geom->clone());
    if (ct && w->transform(ct) != OGRERR_NONE) throw TerrainError("writing '" + path + "': transforming to WGS84 failed");
    o.SetGeometry(w.get());
    if (out->CreateFeature(&o) != OGRERR_NONE) throw TerrainError("writing '" + path + "' failed" + gdal_message());
    if (areas) {
      ++(*areas)[std::size_t(k) - 1].polygons;
      (*areas)[std::size_t(k) - 1].area_m2 += a;
    }
  }
}

}  // namespace

std::vector<ClassArea> write_class_polygons(const std::string& geojson_path, const std::string& gpkg_path, const std::string& layer,
                                            const Grid& g, const std::vector<std::uint8_t>& cls, const std::vector<ValueClass>& classes,
                                            const std::string& unit) {
  init_gdal();
  const ClassLayer polys = polygonize(g, cls, "'" + gpkg_path + "'");
  std::vector<ClassArea> areas(classes.size());
  write_layer(polys, "GPKG", gpkg_path, layer, polys.srs, nullptr, classes, unit, &areas);
  if (polys.srs.IsLocal()) return areas;  // no geographic coordinates: no GeoJSON (RFC 7946 is WGS84)
  auto ll = wgs84();
  auto ct = transform(polys.srs, ll, "'" + geojson_path + "'");
  write_layer(polys, "GeoJSON", geojson_path, layer, ll, ct.get(), classes, unit, nullptr);
  return areas;
}

void add_layer_style(const std::string& gpkg_path, const std::string& layer, const std::string& style_name, const std::string& qml) {
  init_gdal();
  GDALDatasetUniquePtr ds(GDALDataset::Open(gpkg_path.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE));
  if (!ds) throw TerrainError("'" + gpkg_path + "': cannot open it to add its style" + gdal_message());
  OGRLayer* styles = ds->GetLayerByName("layer_styles");
  if (!styles) {  // QGIS's own table of styles (the columns it writes and reads)
    styles = ds->CreateLayer("layer_styles", nullptr, wkbNone, nullptr);
    if (!styles) throw TerrainError("'" + gpkg_path + "': cannot create its layer_styles table" + gdal_message());
    for (const char* f : {"f_table_catalog", "f_table_schema", "f_table_name", "f_geometry_column", "styleName", "styleQML", "styleSLD"}) {
      OGRFieldDefn d(f, OFTString);
      styles->CreateField(&d);
    }
    OGRFieldDefn def("useAsDefault", OFTInteger);
    def.SetSubType(OFSTBoolean);
    styles->CreateField(&def);
    for (const char* f : {"description", "owner", "ui"}) {
      OGRFieldDefn d(f, OFTString);
      styles->CreateField(&d);
    }
    OGRFieldDefn t("update_time", OFTDateTime);
    styles->CreateField(&t);
  }
  OGRLayer* target = ds->GetLayerByName(layer.c_str());
  if (!target) throw TerrainError("'" + gpkg_path + "' has no layer '" + layer + "' to style");
  OGRFeature f(styles->GetLayerDefn());
  f.SetField("f_table_catalog", "");
  f.SetField("f_table_schema", "");
  f.SetField("f_table_name", layer.c_str());
  f.SetField("f_geometry_column", target->GetGeometryColumn());
  f.SetField("styleName", style_name.c_str());
  f.SetField("styleQML", qml.c_str());
  f.SetField("styleSLD", "");
  f.SetField("useAsDefault", 1);
  f.SetField("description", "runout's style of the layer");
  f.SetField("owner", "");
  if (styles->CreateFeature(&f) != OGRERR_NONE) throw TerrainError("'" + gpkg_path + "': cannot add the style" + gdal_message());
}

OutlineReport write_outline(const std::string& geojson_path, const std::string& gpkg_path, const Grid& g,
                            const std::vector<double>& values, double threshold) {
  std::vector<std::uint8_t> inside(g.cells());
  for (std::size_t k = 0; k < inside.size(); ++k) inside[k] = values[k] > threshold;
  std::ostringstream name;
  name << "max depth > " << threshold << " m";
  ValueClass c;
  c.name = name.str();
  c.from = threshold;
  c.to = NAN;
  const auto a = write_class_polygons(geojson_path, gpkg_path, "runout_outline", g, inside, {c}, "m");
  OutlineReport rep;
  rep.polygons = a[0].polygons;
  rep.area_m2 = a[0].area_m2;
  OGRSpatialReference srs;
  srs.importFromWkt(g.crs_wkt.c_str());
  rep.geojson = !srs.IsLocal();
  return rep;
}

}  // namespace runout::terrain
