"""QGIS layers as the files a scenario names.

A layer backed by a plain file that runout reads as it is (a GeoTIFF or other GDAL raster file; a
GeoJSON, a Shapefile, a GeoPackage holding only this layer, without a filter) is named by its own
path, so that the run reads exactly the file the layer shows. Anything else (a memory or database
layer, one layer of a GeoPackage of several, a filtered layer, a web service) is written into the
run's ``inputs`` folder first: rasters as GeoTIFF, vectors as GeoPackage with their attributes.
"""
from __future__ import annotations

import os
import re

from qgis.core import (
    QgsProcessingException,
    QgsProviderRegistry,
    QgsRasterFileWriter,
    QgsRasterLayer,
    QgsRasterPipe,
    QgsVectorFileWriter,
    QgsVectorLayer,
    QgsWkbTypes,
)

#: runout reads every layer of a vector file (its releases, area of interest, ...): a file of
#: several layers is exported unless it holds just this one.
_VSI = re.compile(r"^/vsi[a-z0-9_]+/", re.I)


def _safe(name: str) -> str:
    s = re.sub(r"[^\w.-]+", "_", name).strip("._")
    return s or "layer"


def plain_vector_file(layer: QgsVectorLayer) -> str | None:
    """The file that holds exactly this vector layer, when runout can read it as it is; else None."""
    if layer is None or layer.providerType() != "ogr":
        return None
    if layer.subsetString():
        return None
    parts = QgsProviderRegistry.instance().decodeUri("ogr", layer.source())
    path = parts.get("path") or ""
    if not path or _VSI.match(path) or not os.path.isfile(path):
        return None
    if parts.get("subset") or parts.get("geometryType") or parts.get("layerId") not in (None, "", -1, "-1", 0, "0"):
        return None
    try:
        from osgeo import ogr
        ds = ogr.Open(path)
        if ds is None:
            return None
        count = ds.GetLayerCount()
        if count != 1:
            return None
        wanted = parts.get("layerName")
        if wanted and ds.GetLayer(0).GetName() != wanted:
            return None
    except Exception:  # noqa: BLE001 - when in doubt, export
        return None
    return os.path.abspath(path)


def plain_raster_file(layer: QgsRasterLayer) -> str | None:
    """The raster file of this layer when GDAL reads it as it is (no subdataset, no virtual path); else None."""
    if layer is None or layer.providerType() != "gdal":
        return None
    parts = QgsProviderRegistry.instance().decodeUri("gdal", layer.source())
    path = parts.get("path") or ""
    if not path or _VSI.match(path) or not os.path.isfile(path) or parts.get("layerName"):
        return None
    return os.path.abspath(path)


def vector_input(layer: QgsVectorLayer, what: str, inputs_dir: str, context, feedback) -> str:
    """The path the scenario names for a vector layer: its own file, or a GeoPackage written into inputs_dir."""
    path = plain_vector_file(layer)
    if path:
        feedback.pushInfo(f"{what}: the layer's file {path}")
        return path
    os.makedirs(inputs_dir, exist_ok=True)
    out = os.path.join(inputs_dir, _safe(what) + ".gpkg")
    if os.path.exists(out):
        os.remove(out)
    opts = QgsVectorFileWriter.SaveVectorOptions()
    opts.driverName = "GPKG"
    opts.layerName = _safe(what)
    opts.fileEncoding = "UTF-8"
    res = QgsVectorFileWriter.writeAsVectorFormatV3(layer, out, context.transformContext(), opts)
    err, msg = res[0], res[1]
    if err != QgsVectorFileWriter.NoError:
        raise QgsProcessingException(f"{what}: writing the layer '{layer.name()}' to {out} failed: {msg}")
    feedback.pushInfo(f"{what}: the layer '{layer.name()}' written to {out} (not a plain file runout reads as it is)")
    return out


def raster_input(layer: QgsRasterLayer, what: str, inputs_dir: str, context, feedback) -> str:
    """The path the scenario names for a raster layer: its own file, or a GeoTIFF written into inputs_dir."""
    path = plain_raster_file(layer)
    if path:
        feedback.pushInfo(f"{what}: the layer's file {path}")
        return path
    os.makedirs(inputs_dir, exist_ok=True)
    out = os.path.join(inputs_dir, _safe(what) + ".tif")
    if os.path.exists(out):
        os.remove(out)
    provider = layer.dataProvider()
    if provider is None or provider.xSize() <= 0 or provider.ySize() <= 0:
        raise QgsProcessingException(f"{what}: the layer '{layer.name()}' has no pixel grid of its own "
                                     "(a web map?); save it as a GeoTIFF first")
    pipe = QgsRasterPipe()
    if not pipe.set(provider.clone()):
        raise QgsProcessingException(f"{what}: cannot read the layer '{layer.name()}'")
    writer = QgsRasterFileWriter(out)
    writer.setOutputFormat("GTiff")
    writer.setCreateOptions(["COMPRESS=DEFLATE", "TILED=YES"])
    err = writer.writeRaster(pipe, provider.xSize(), provider.ySize(), provider.extent(), provider.crs(),
                             context.transformContext())
    if err != QgsRasterFileWriter.NoError:
        raise QgsProcessingException(f"{what}: writing the layer '{layer.name()}' to {out} failed (error {int(err)})")
    feedback.pushInfo(f"{what}: the layer '{layer.name()}' written to {out} (not a plain raster file)")
    return out


def crs_text(crs) -> str:
    """A CRS as the scenario takes it: "EPSG:4326" (any AUTH:CODE), else its WKT."""
    if crs is None or not crs.isValid():
        return ""
    return crs.authid() or crs.toWkt()


def points_of_interest(layer: QgsVectorLayer, name_field: str | None, what: str = "points of interest") -> list[dict]:
    """``outputs.points_of_interest``: every point (every part of a multi-point) with its name and the layer's CRS."""
    if layer.geometryType() != QgsWkbTypes.PointGeometry:
        raise QgsProcessingException(f"{what}: the layer '{layer.name()}' holds no points")
    if name_field and layer.fields().indexFromName(name_field) < 0:
        raise QgsProcessingException(f"{what}: the layer '{layer.name()}' has no field '{name_field}' "
                                     f"(its fields: {', '.join(layer.fields().names()) or 'none'})")
    crs = crs_text(layer.crs())
    out = []
    for f in layer.getFeatures():
        g = f.geometry()
        if g is None or g.isEmpty():
            continue
        name = str(f[name_field]) if name_field and f[name_field] not in (None, "") else f"point {f.id()}"
        pts = g.asMultiPoint() if g.isMultipart() else [g.asPoint()]
        for k, p in enumerate(pts):
            e = {"name": name if len(pts) == 1 else f"{name} ({k + 1})", "x": p.x(), "y": p.y()}
            if crs:
                e["crs"] = crs
            out.append(e)
    if not out:
        raise QgsProcessingException(f"{what}: the layer '{layer.name()}' has no points")
    return out


def require_field(layer: QgsVectorLayer, field: str, what: str, numeric: bool = True) -> None:
    """A clear error when the layer lacks the field (or it is not numeric)."""
    idx = layer.fields().indexFromName(field)
    if idx < 0:
        raise QgsProcessingException(f"{what}: the layer '{layer.name()}' has no field '{field}' "
                                     f"(its fields: {', '.join(layer.fields().names()) or 'none'})")
    if numeric and not layer.fields().at(idx).isNumeric():
        raise QgsProcessingException(f"{what}: the field '{field}' of the layer '{layer.name()}' is not numeric "
                                     f"({layer.fields().at(idx).typeName()})")
