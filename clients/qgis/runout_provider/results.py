"""A run's results as styled layers of the project, loaded when the algorithm has finished.

In the QGIS GUI, Processing loads the layers named by ``QgsProcessingContext.addLayerToLoadOnCompletion``
once the algorithm has succeeded, in the main thread, and then calls each layer's post-processor:

* the hazard rasters (``max_depth.tif``, ...; ``pressure_zones.tif``): QGIS reads the ``.qml`` of
  the same base name beside each by itself; the post-processor applies it again explicitly;
* ``outline.gpkg`` and ``pressure_zones.gpkg`` (their layer with geometries: the files also hold
  QGIS's ``layer_styles`` table): QGIS reads a GeoPackage's default style from that table;
  ``outline.qml`` and ``pressure_zones_polygons.qml`` are applied over it where they exist;
* ``timeseries.nc`` (NetCDF CF, ``depth`` and ``speed`` over time, y, x) as a mesh layer through
  MDAL (its NETCDF driver reads the regular grid as a mesh whose vertices are the cell centres):
  its frames are the datasets of two temporal dataset groups (time from the release at the epoch,
  1970-01-01T00:00:00Z, as the file's CF units say), so that the temporal controller steps
  through them; the depth shown, in the classes of ``timeseries_depth.qml`` (the speed in those of
  ``timeseries_speed.qml``). The project's time range becomes the series' span when it has none,
  and in the GUI the temporal controller gets that span with a step of the time-series interval.
  Where a run wrote no ``timeseries.nc`` (an older runout), ``timeseries_depth.tif`` is loaded as
  one raster (a band per frame).

qgis_process ignores the layers to load (there is no project to load them into).
"""
from __future__ import annotations

import json
import math
import os
import xml.etree.ElementTree as ET

from qgis.core import (
    QgsColorRampShader,
    QgsInterval,
    QgsMeshDataProviderTemporalCapabilities,
    QgsMeshDatasetIndex,
    QgsMeshLayer,
    QgsProcessingContext,
    QgsProcessingLayerPostProcessorInterface,
    QgsProcessingUtils,
    QgsTemporalNavigationObject,
    QgsUnitTypes,
)
from qgis.PyQt.QtGui import QColor
from qgis.PyQt.QtXml import QDomDocument

#: (file, style beside it or None, layer name, layer kind).
RESULT_LAYERS = [
    ("max_depth.tif", "max_depth.qml", "maximum flow depth [m]", "raster"),
    ("max_speed.tif", "max_speed.qml", "maximum flow speed [m/s]", "raster"),
    ("max_pressure.tif", "max_pressure.qml", "maximum pressure [kPa]", "raster"),
    ("deposit.tif", "deposit.qml", "deposit depth [m]", "raster"),
    ("arrival_time.tif", "arrival_time.qml", "arrival time [s]", "raster"),
    ("cover_depth.tif", "cover_depth.qml", "snow cover left [m]", "raster"),
    ("detrained_depth.tif", "detrained_depth.qml", "detrained depth [m]", "raster"),
    ("pressure_zones.tif", "pressure_zones.qml", "pressure zones", "raster"),
    ("pressure_zones.gpkg", "pressure_zones_polygons.qml", "pressure zones (polygons)", "vector"),
    ("outline.gpkg", "outline.qml", "runout outline", "vector"),
]

#: Post-processors must outlive the algorithm (Processing holds them only by pointer).
_KEEP: list = []


def ramp_items(qml_path: str) -> list[tuple[float, str, int, str]]:
    """The (value, colour, alpha, label) items of a raster style's colour ramp (runout's .qml)."""
    try:
        root = ET.parse(qml_path).getroot()
    except (OSError, ET.ParseError):
        return []
    out = []
    for it in root.iter("item"):
        try:
            v = it.get("value", "")
            value = math.inf if v.strip().lower() in ("inf", "+inf", "infinity") else float(v)
            out.append((value, it.get("color", "#000000"), int(it.get("alpha", "255")), it.get("label", "")))
        except ValueError:
            continue
    return out


def style_mesh(layer: QgsMeshLayer, results_dir: str, feedback=None) -> bool:
    """The depth group active, coloured in the classes of timeseries_depth.qml (speed likewise)."""
    if layer is None or not layer.isValid():
        return False
    rs = layer.rendererSettings()
    depth_group = None
    for g in layer.datasetGroupsIndexes():
        meta = layer.datasetGroupMetadata(QgsMeshDatasetIndex(g))
        name = (meta.name() or "").lower()
        kind = "depth" if "depth" in name else "speed" if "speed" in name else None
        if kind is None:
            continue
        if kind == "depth" and depth_group is None:
            depth_group = g
        items = ramp_items(os.path.join(results_dir, f"timeseries_{kind}.qml"))
        if not items:
            continue
        shader = QgsColorRampShader()
        shader.setColorRampType(QgsColorRampShader.Discrete)
        shader.setColorRampItemList([QgsColorRampShader.ColorRampItem(v, _colour(c, a), lbl) for v, c, a, lbl in items])
        finite = [v for v, _, _, _ in items if math.isfinite(v)]
        lo, hi = (min(finite), max(finite)) if finite else (0.0, 1.0)
        shader.setMinimumValue(lo)
        shader.setMaximumValue(hi)
        ss = rs.scalarSettings(g)
        ss.setColorRampShader(shader)
        ss.setClassificationMinimumMaximum(lo, hi)
        rs.setScalarSettings(g, ss)
    if depth_group is None and layer.datasetGroupsIndexes():
        depth_group = layer.datasetGroupsIndexes()[0]
    if depth_group is not None:
        rs.setActiveScalarDatasetGroup(depth_group)
    layer.setRendererSettings(rs)
    # The frame closest to the start of the controller's range: stepping by the time-series interval
    # shows every frame once (QGIS's default, the last frame before the start, lags a frame behind:
    # the frames are written at the first step after each interval).
    layer.setTemporalMatchingMethod(QgsMeshDataProviderTemporalCapabilities.FindClosestDatasetFromStartRangeTime)
    return depth_group is not None


def frame_interval_s(results_dir: str) -> float:
    """The scenario's time-series interval (run.json), else 0."""
    try:
        with open(os.path.join(results_dir, "run.json"), encoding="utf-8") as f:
            rec = json.load(f)
        return float((rec.get("scenario") or {}).get("outputs", {}).get("timeseries_interval_s") or 0.0)
    except (OSError, ValueError, TypeError, AttributeError):
        return 0.0


def set_up_time(layer: QgsMeshLayer, project, interval_s: float) -> None:
    """The time series' span as the project's time range (when it has none) and, in the GUI, as the
    temporal controller's extent with a frame every interval_s (animated unless the user had set
    another mode): the controller's steps then show the run's frames."""
    if layer is None or not layer.isValid() or not layer.temporalProperties().isActive():
        return
    span = layer.temporalProperties().timeExtent()
    if not span.begin().isValid() or not span.end().isValid():
        return
    if project is not None:
        ts = project.timeSettings()
        if ts.temporalRange().isInfinite():
            ts.setTemporalRange(span)
            if interval_s > 0:
                ts.setTimeStep(interval_s)
                ts.setTimeStepUnit(QgsUnitTypes.TemporalSeconds)
    try:
        from qgis.utils import iface
        canvas = iface.mapCanvas() if iface is not None else None
    except Exception:  # noqa: BLE001 - no GUI (qgis_process, tests)
        canvas = None
    if canvas is None or canvas.temporalController() is None:
        return
    tc = canvas.temporalController()
    tc.setTemporalExtents(span)
    if interval_s > 0:
        tc.setFrameDuration(QgsInterval(interval_s))
    if tc.navigationMode() == QgsTemporalNavigationObject.NavigationOff:
        tc.setNavigationMode(QgsTemporalNavigationObject.Animated)
    tc.setCurrentFrameNumber(0)


def apply_qml(layer, qml_path: str) -> tuple[bool, str]:
    """The style file on the layer. Read as a document and imported: loadNamedStyle(path) would take
    a GeoPackage's default style from its layer_styles table instead of the file."""
    doc = QDomDocument("qgis")
    try:
        with open(qml_path, "rb") as f:
            parsed = doc.setContent(f.read())
    except OSError as e:
        return False, str(e)
    ok = parsed[0] if isinstance(parsed, tuple) else bool(parsed)
    if not ok:
        return False, f"not a QGIS style document ({parsed[1] if isinstance(parsed, tuple) else ''})"
    res = layer.importNamedStyle(doc)
    return bool(res[0]), res[1] if len(res) > 1 else ""


def _colour(hexcode: str, alpha: int) -> QColor:
    c = QColor(hexcode)
    c.setAlpha(alpha)
    return c


class StylePostProcessor(QgsProcessingLayerPostProcessorInterface):
    """Applies a .qml style (and for the time series the mesh's colours) to a loaded result."""

    def __init__(self, qml: str | None = None, mesh_results: str | None = None):
        super().__init__()
        self.qml = qml
        self.mesh_results = mesh_results

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802 - QGIS's name
        if layer is None:
            return
        if self.qml and os.path.isfile(self.qml):
            ok, msg = apply_qml(layer, self.qml)
            if not ok and feedback is not None:
                feedback.reportError(f"style {self.qml} not applied to '{layer.name()}': {msg}")
        if self.mesh_results and isinstance(layer, QgsMeshLayer):
            style_mesh(layer, self.mesh_results, feedback)
            set_up_time(layer, context.project() if context is not None else None, frame_interval_s(self.mesh_results))
        layer.triggerRepaint()


def _details(name: str, context: QgsProcessingContext, hint, post: StylePostProcessor | None):
    d = QgsProcessingContext.LayerDetails(name, context.project(), "", hint)
    d.forceName = True
    if post is not None:
        _KEEP.append(post)
        d.setPostProcessor(post)
    return d


def vector_source(path: str) -> str:
    """A GeoPackage's polygons as a layer source: ``path|layername=NAME`` of its first layer with
    geometries (the file also holds QGIS's table of styles, ``layer_styles``); the path when unsure."""
    try:
        from osgeo import ogr
        ds = ogr.Open(path)
        names = [ds.GetLayer(i).GetName() for i in range(ds.GetLayerCount())
                 if ds.GetLayer(i).GetGeomType() != ogr.wkbNone] if ds is not None else []
        ds = None
    except Exception:  # noqa: BLE001 - QGIS then takes the file's first layer
        names = []
    return f"{path}|layername={names[0]}" if names else path


def result_layers(results_dir: str) -> list[tuple[str, str | None, str, str]]:
    """The result files present, as (path, style path or None, layer name, kind); the time series last."""
    out = []
    for fname, qml, label, kind in RESULT_LAYERS:
        p = os.path.join(results_dir, fname)
        if os.path.isfile(p):
            q = os.path.join(results_dir, qml) if qml else None
            out.append((p, q if q and os.path.isfile(q) else None, label, kind))
    nc = os.path.join(results_dir, "timeseries.nc")
    tif = os.path.join(results_dir, "timeseries_depth.tif")
    if os.path.isfile(nc):
        out.append((nc, None, "flow depth and speed over time", "mesh"))
    elif os.path.isfile(tif):
        q = os.path.join(results_dir, "timeseries_depth.qml")
        out.append((tif, q if os.path.isfile(q) else None, "flow depth over time (a band per frame)", "raster"))
    return out


def load_on_completion(results_dir: str, context: QgsProcessingContext, feedback, title: str = "") -> int:
    """Queue the run's results to be loaded into the project when the algorithm has finished; their count."""
    prefix = (title[:60] + "...: " if len(title) > 60 else title + ": ") if title else ""
    hints = {"raster": QgsProcessingUtils.LayerHint.Raster, "vector": QgsProcessingUtils.LayerHint.Vector,
             "mesh": QgsProcessingUtils.LayerHint.Mesh}
    n = 0
    for path, qml, label, kind in result_layers(results_dir):
        post = StylePostProcessor(qml=qml, mesh_results=results_dir if kind == "mesh" else None)
        source = vector_source(path) if kind == "vector" else path
        context.addLayerToLoadOnCompletion(source, _details(prefix + label, context, hints[kind], post))
        n += 1
    if n and feedback is not None:
        feedback.pushInfo(f"{n} result layers to load from {results_dir}")
    return n
