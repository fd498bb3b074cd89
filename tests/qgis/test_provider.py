#!/usr/bin/env python3
"""The QGIS Processing provider (clients/qgis/runout_provider) headless, through qgis_process.

1. The bundled In den Arelen scenario is built from its layers by ``runout:run`` (the DEM, the
   release polygons with their thickness and slope-window fields, the area of interest, the point
   of interest as a point layer written here, the scenario's grid, material, numerics and outputs,
   all read from scenarios/in-den-arelen.json) and run with the runout program under test. Every
   hazard raster must be byte for byte the one of ``runout run scenarios/in-den-arelen.json``,
   run here into another folder. On a difference the test says what differs (pixels, metadata,
   the resolved scenarios) and fails.
2. A release layer without the named thickness field fails with a message naming the field.
3. ``runout:run_file`` runs scenarios/in-den-arelen-30m.json locally and, against a ``runout serve``
   started here, as a job of the service (EXECUTION=service, through runout's Python client): the
   job's hazard rasters equal the local run's (skipped without gRPC for Python or protoc).
4. The results as the QGIS GUI loads them (the plugin's layers to load on completion, with their
   post-processors), through QGIS's Python: the rasters styled, the outline's and the zones'
   styles applied, the time series (runout's timeseries.nc) a temporal mesh layer whose frames the
   temporal controller steps through.

Nothing is written outside a temporary folder: QGIS gets a throwaway HOME (profile, settings,
XDG folders), the plugin is enabled there with ``qgis_process plugins enable runout_provider``,
and Python writes no bytecode into the source tree.

    python3 tests/qgis/test_provider.py --runout build/bin/runout [--source-dir .] [--keep] [-v]

Exit 0 on success, 1 on a failure, 77 (ctest's SKIP_RETURN_CODE) when qgis_process is absent.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SKIP = 77
HAZARD_RASTERS = ["max_depth.tif", "max_speed.tif", "max_pressure.tif", "deposit.tif", "arrival_time.tif"]
HERE = Path(__file__).resolve().parent


class Failure(Exception):
    pass


def log(msg: str) -> None:
    print(msg, flush=True)


def find_qgis_process(given: str | None) -> str | None:
    """qgis_process; on Debian the binary itself (qgis_process.bin): the /usr/bin/qgis_process wrapper
    passes /etc/default/qgis's QGIS_OPTS (--noversioncheck, a desktop option) on, which qgis_process
    refuses ("Command --noversioncheck not known!")."""
    if given:
        return given if shutil.which(given) else None
    env = os.environ.get("QGIS_PROCESS")
    if env:
        return shutil.which(env)
    for name in ("qgis_process.bin", "qgis_process"):
        p = shutil.which(name)
        if p:
            return p
    return None


def qgis_env(tmp: Path, source: Path) -> dict:
    home = tmp / "home"
    run = home / "run"
    for d in (home, run, home / ".config", home / ".local" / "share", home / ".cache"):
        d.mkdir(parents=True, exist_ok=True)
    os.chmod(run, 0o700)
    env = dict(os.environ)
    env.update({
        "HOME": str(home),
        "XDG_RUNTIME_DIR": str(run),
        "XDG_CONFIG_HOME": str(home / ".config"),
        "XDG_DATA_HOME": str(home / ".local" / "share"),
        "XDG_CACHE_HOME": str(home / ".cache"),
        "QT_QPA_PLATFORM": "offscreen",
        "QGIS_PLUGINPATH": str(source / "clients" / "qgis"),
        "PYTHONDONTWRITEBYTECODE": "1",
        # QGIS computes a raster layer's statistics when it loads it (for its default renderer) and
        # GDAL would keep them beside the file (davos_srtm3.tif.aux.xml in the source tree).
        "GDAL_PAM_ENABLED": "NO",
        "PYTHONWARNINGS": "ignore::DeprecationWarning",
    })
    for k in ("QGIS_CUSTOM_CONFIG_PATH", "PYTHONPATH", "PYTHONHOME", "RUNOUT_PROGRAM"):
        env.pop(k, None)
    return env


def run(cmd, env=None, timeout=300, verbose=False):
    t0 = time.monotonic()
    r = subprocess.run([str(c) for c in cmd], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                       timeout=timeout)
    if verbose:
        log(f"$ {' '.join(str(c) for c in cmd)}  (exit {r.returncode}, {time.monotonic() - t0:.1f} s)")
        if r.stdout.strip():
            log(r.stdout.rstrip())
        if r.stderr.strip():
            log(r.stderr.rstrip())
    return r


def write_points(path: Path, pois: list[dict]) -> None:
    """The scenario's points of interest as a GeoJSON point layer (name field ``name``)."""
    crs = {p.get("crs", "") for p in pois}
    if len(crs) != 1:
        raise Failure(f"the scenario's points of interest have several CRSs: {crs}")
    crs = crs.pop() or "EPSG:4326"
    auth, _, code = crs.partition(":")
    fc = {"type": "FeatureCollection", "name": "points_of_interest",
          "crs": {"type": "name", "properties": {"name": f"urn:ogc:def:crs:{auth}::{code}"}},
          "features": [{"type": "Feature", "properties": {"name": p["name"]},
                        "geometry": {"type": "Point", "coordinates": [p["x"], p["y"]]}} for p in pois]}
    path.write_text(json.dumps(fc, indent=1), encoding="utf-8")


def algorithm_args(s: dict, base: Path, poi_path: Path | None, out: Path, runout: Path) -> list[str]:
    """qgis_process's --NAME=VALUE arguments of runout:run for the scenario s (its paths relative to base)."""
    if len(s.get("releases", [])) != 1:
        raise Failure("the test expects a scenario with one release")
    rel = s["releases"][0]
    a = {
        "DEM": base / s["dem"]["path"],
        "RELEASE": base / rel["path"],
        "THICKNESS_MEASURED": rel.get("thickness_measured", "normal"),
        "NAME": s.get("name", ""),
        "EXECUTION": "local",
        "PROGRAM": runout,
        "OUTPUT": out,
    }
    if "thickness_attribute" in rel:
        a["THICKNESS_FIELD"] = rel["thickness_attribute"]
    if "thickness_m" in rel:
        a["THICKNESS"] = rel["thickness_m"]
    for k, p in (("min_slope_attribute", "MIN_SLOPE_FIELD"), ("max_slope_attribute", "MAX_SLOPE_FIELD"),
                 ("min_slope_deg", "MIN_SLOPE"), ("max_slope_deg", "MAX_SLOPE")):
        if k in rel:
            a[p] = rel[k]
    if "area_of_interest" in s:
        a["AOI"] = base / s["area_of_interest"]["path"]
    g = s.get("grid", {})
    a["RESOLUTION"] = g.get("resolution_m", 0)
    a["GRID_CRS"] = g.get("crs", "utm")
    a["RESAMPLING"] = g.get("resampling", "cubic")
    m = s.get("material", {})
    names = {"density_kg_m3": "DENSITY", "bed_friction_deg": "BED_FRICTION", "internal_friction_deg": "INTERNAL_FRICTION",
             "voellmy_mu": "VOELLMY_MU", "voellmy_xi": "VOELLMY_XI"}
    a["RHEOLOGY"] = m.get("rheology", "coulomb")
    a["EARTH_PRESSURE"] = m.get("earth_pressure", "unity")
    for k, v in m.items():
        if k in names:
            a[names[k]] = v
        elif k not in ("rheology", "earth_pressure"):
            raise Failure(f"material.{k}: the test does not pass it on")
    n = s.get("numerics", {})
    for k, p in (("limiter", "LIMITER"), ("cfl", "CFL"), ("end_time_s", "END_TIME"), ("stop_fraction", "STOP_FRACTION"),
                 ("boundary", "BOUNDARY")):
        if k in n:
            a[p] = n[k]
    o = s.get("outputs", {})
    for k, p in (("outline_threshold_m", "OUTLINE_THRESHOLD"), ("flow_threshold_m", "FLOW_THRESHOLD"),
                 ("timeseries_interval_s", "TIMESERIES_INTERVAL")):
        if k in o:
            a[p] = o[k]
    if "timeseries_interval_s" not in o:
        a["TIMESERIES_INTERVAL"] = 0
    if o.get("points_of_interest"):
        a["POINTS"] = poi_path
        a["POINTS_NAME_FIELD"] = "name"
    left = set(s) - {"name", "engine", "dem", "area_of_interest", "grid", "releases", "material", "numerics", "outputs"}
    if left:
        raise Failure(f"scenario fields the test does not pass on: {sorted(left)}")
    return [f"{k}={v}" for k, v in a.items()]


def diagnose(ref: Path, got: Path, name: str, qgis_python: str, env: dict) -> str:
    """What differs between two rasters: size, pixels, metadata (through GDAL's Python, when there)."""
    code = r"""
import sys
from osgeo import gdal
a, b = gdal.Open(sys.argv[1]), gdal.Open(sys.argv[2])
def info(d):
    band = d.GetRasterBand(1)
    return {"size": (d.RasterXSize, d.RasterYSize), "geotransform": d.GetGeoTransform(), "crs": d.GetProjection(),
            "metadata": d.GetMetadata(), "band metadata": band.GetMetadata(), "description": band.GetDescription(),
            "nodata": band.GetNoDataValue(), "image structure": d.GetMetadata("IMAGE_STRUCTURE")}
ia, ib = info(a), info(b)
for k in ia:
    if ia[k] != ib[k]:
        print(f"  {k}: reference {ia[k]!r} != plugin {ib[k]!r}")
if ia["size"] == ib["size"]:
    import numpy as np
    x, y = a.GetRasterBand(1).ReadAsArray(), b.GetRasterBand(1).ReadAsArray()
    d = x != y
    if d.any():
        print(f"  pixels: {int(d.sum())} of {d.size} differ, largest abs difference {float(np.nanmax(np.abs(x - y)))}")
    else:
        print("  pixels: all equal (the difference is in the file's structure or metadata)")
"""
    r = subprocess.run([qgis_python, "-c", code, str(ref), str(got)], env=env, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, text=True)
    return f"{name}: {ref.stat().st_size} bytes (reference) vs {got.stat().st_size} bytes (plugin)\n" + r.stdout


def scenario_differences(ref_record: Path, got_record: Path) -> list[str]:
    """The resolved scenarios of both run records, field by field (the inputs' paths differ)."""
    def flat(v, pre=""):
        if isinstance(v, dict):
            for k, w in v.items():
                yield from flat(w, f"{pre}.{k}" if pre else k)
        elif isinstance(v, list):
            for i, w in enumerate(v):
                yield from flat(w, f"{pre}[{i}]")
        else:
            yield pre, v
    try:
        a = dict(flat(json.loads(ref_record.read_text())["scenario"]))
        b = dict(flat(json.loads(got_record.read_text())["scenario"]))
    except (OSError, ValueError, KeyError) as e:
        return [f"cannot compare the run records' scenarios: {e}"]
    return [f"  scenario.{k}: reference {a.get(k)!r} != plugin {b.get(k)!r}" for k in sorted(set(a) | set(b))
            if a.get(k) != b.get(k)]


GUI_CHECK = r"""
import json, math, os, sys
from qgis.core import (QgsApplication, QgsProcessingContext, QgsProcessingFeedback, QgsProcessingUtils, QgsProject,
                       QgsRasterLayer, QgsVectorLayer, QgsMeshLayer, QgsMeshDatasetIndex, QgsDateTimeRange,
                       QgsTemporalNavigationObject)
from qgis.gui import QgsMapCanvas
import qgis.utils
app = QgsApplication([], True)
app.initQgis()
# The GUI's map canvas with its temporal controller, as qgis.utils.iface offers them in QGIS.
canvas = QgsMapCanvas()
controller = QgsTemporalNavigationObject()
canvas.setTemporalController(controller)
class Iface:
    def mapCanvas(self):
        return canvas
qgis.utils.iface = Iface()
sys.path.insert(0, sys.argv[1])
from runout_provider import results
res = sys.argv[2]
ctx = QgsProcessingContext()
ctx.setProject(QgsProject.instance())
fb = QgsProcessingFeedback()
n = results.load_on_completion(res, ctx, fb, "test")
out = {"queued": n, "layers": {}}
for src, details in ctx.layersToLoadOnCompletion().items():
    layer = QgsProcessingUtils.mapLayerFromString(src, ctx, True, details.layerTypeHint)
    e = {"valid": bool(layer and layer.isValid()), "name": details.name}
    if layer is not None and layer.isValid():
        if details.postProcessor():
            details.postProcessor().postProcessLayer(layer, ctx, fb)
        if isinstance(layer, QgsRasterLayer):
            e["kind"] = "raster"
            e["renderer"] = layer.renderer().type()
        elif isinstance(layer, QgsVectorLayer):
            e["kind"] = "vector"
            e["renderer"] = layer.renderer().type()
            e["features"] = layer.featureCount()
            e["source"] = src
            qml = details.postProcessor().qml if details.postProcessor() else None
            if qml:  # the style file's renderer, which the post-processor applied
                import xml.etree.ElementTree as ET
                r = ET.parse(qml).getroot().find("renderer-v2")
                e["qml_renderer"] = r.get("type") if r is not None else None
        elif isinstance(layer, QgsMeshLayer):
            e["kind"] = "mesh"
            e["provider"] = layer.providerType()
            groups = {}
            for g in layer.datasetGroupsIndexes():
                idx = QgsMeshDatasetIndex(g)
                groups[layer.datasetGroupMetadata(idx).name()] = {
                    "frames": layer.datasetCount(idx), "temporal": layer.datasetGroupMetadata(idx).isTemporal()}
            e["groups"] = groups
            tp = layer.temporalProperties()
            ref = tp.referenceTime()
            e["temporal_active"] = tp.isActive()
            e["time_span_s"] = ref.secsTo(tp.timeExtent().end()) if tp.timeExtent().end().isValid() else None
            rs = layer.rendererSettings()
            active = rs.activeScalarDatasetGroup()
            e["active_group"] = layer.datasetGroupMetadata(QgsMeshDatasetIndex(active)).name()
            e["active_classes"] = len(rs.scalarSettings(active).colorRampShader().colorRampItemList())
            pr = QgsProject.instance().timeSettings().temporalRange()
            e["project_range_s"] = [ref.msecsTo(pr.begin()) / 1000, ref.msecsTo(pr.end()) / 1000]
            # The temporal controller as the post-processor set it up, stepped frame by frame: the
            # mesh's dataset the map shows at each step.
            ce = controller.temporalExtents()
            e["controller"] = {"extent_s": [ref.msecsTo(ce.begin()) / 1000, ref.msecsTo(ce.end()) / 1000],
                               "step_s": controller.frameDuration().seconds(), "mode": int(controller.navigationMode()),
                               "animated": controller.navigationMode() == QgsTemporalNavigationObject.Animated,
                               "frames": controller.totalFrameCount()}
            e["shown"] = [layer.activeScalarDatasetAtTime(controller.dateTimeRangeForFrameNumber(k)).dataset()
                          for k in range(controller.totalFrameCount())]
    out["layers"][os.path.basename(src.split("|")[0])] = e
print("RESULT " + json.dumps(out))
app.exitQgis()
"""


def gui_check(tmp: Path, source: Path, results: Path, qgis_python: str, env: dict, verbose: bool) -> list[str]:
    """The results as the GUI loads them; a list of problems (empty: all well)."""
    problems = []
    if subprocess.run([qgis_python, "-c", "import qgis.core"], env=env, stdout=subprocess.DEVNULL,
                      stderr=subprocess.DEVNULL).returncode != 0:
        log(f"gui check: skipped ({qgis_python} cannot import qgis.core)")
        return problems
    if not (results / "timeseries.nc").exists():
        return ["the run wrote no timeseries.nc"]
    times = []
    r = run([qgis_python, "-c", "import sys\nfrom osgeo import gdal\nd=gdal.Open(sys.argv[1])\n"
             "print(','.join(d.GetRasterBand(b+1).GetMetadataItem('TIME_S') for b in range(d.RasterCount)))",
             results / "timeseries_depth.tif"], env=env)
    if r.returncode == 0:
        times = [float(t) for t in r.stdout.strip().split(",") if t]
    if not times:
        return ["gui: no frame times in timeseries_depth.tif"]
    interval = float(json.loads((results / "run.json").read_text())["scenario"]["outputs"]["timeseries_interval_s"])
    r = run([qgis_python, "-c", GUI_CHECK, source / "clients" / "qgis", results], env=env, timeout=120)
    line = next((ln for ln in r.stdout.splitlines() if ln.startswith("RESULT ")), None)
    if r.returncode != 0 or line is None:
        return [f"gui check failed (exit {r.returncode}):\n{r.stdout}\n{r.stderr}"]
    got = json.loads(line[len("RESULT "):])
    L = got["layers"]
    if verbose:
        log(json.dumps(got, indent=1))
    for f in HAZARD_RASTERS + ["pressure_zones.tif"]:
        e = L.get(f)
        if not e or not e["valid"]:
            problems.append(f"gui: {f} not loaded")
        elif e["renderer"] not in ("singlebandpseudocolor", "paletted"):
            problems.append(f"gui: {f} not styled by its .qml (renderer {e['renderer']})")
    for f in ("outline.gpkg", "pressure_zones.gpkg"):
        e = L.get(f)
        if not e or not e["valid"] or e.get("features", 0) < 1:
            problems.append(f"gui: {f} not loaded or empty ({e})")
        elif e.get("qml_renderer") and e["qml_renderer"] != e["renderer"]:
            problems.append(f"gui: {f}: its style's renderer {e['qml_renderer']} not applied (renderer {e['renderer']})")
    e = L.get("timeseries.nc")
    if not e or not e["valid"] or e.get("kind") != "mesh":
        problems.append(f"gui: timeseries.nc not loaded as a mesh layer ({e})")
    else:
        frames = {k: v["frames"] for k, v in e["groups"].items()}
        if len(e["groups"]) != 2 or any(v["frames"] != len(times) or not v["temporal"] for v in e["groups"].values()):
            problems.append(f"gui: the mesh's dataset groups {e['groups']} are not depth and speed with {len(times)} temporal frames")
        if not e["temporal_active"]:
            problems.append("gui: the mesh layer's temporal properties are not active")
        if e["time_span_s"] is None or abs(e["time_span_s"] - times[-1]) > 1:
            problems.append(f"gui: the mesh's time span {e['time_span_s']} s is not the last frame's {times[-1]} s")
        shown, c = e["shown"], e["controller"]
        if times and abs(e["project_range_s"][1] - times[-1]) > 0.01:
            problems.append(f"gui: the project's time range {e['project_range_s']} s is not the series' 0-{times[-1]} s")
        if not c["animated"] or abs(c["extent_s"][1] - times[-1]) > 0.01 or abs(c["step_s"] - interval) > 1e-9:
            problems.append(f"gui: the temporal controller {c} does not step through 0-{times[-1]} s by {interval} s")
        # Every frame once, in order (the end state, written a fraction of a step after the last
        # interval's frame, may share its step).
        if not shown or shown[0] != 0 or shown != list(range(len(shown))) or shown[-1] < len(times) - 2:
            problems.append(f"gui: the temporal controller's {len(shown)} steps show the frames {shown} "
                            f"of {len(times)}")
        if "depth" not in e["active_group"].lower() or e["active_classes"] < 2:
            problems.append(f"gui: the mesh's active group {e['active_group']!r} with {e['active_classes']} classes "
                            "is not the styled depth")
        log(f"gui check: {len(L)} layers loaded and styled; time series: "
            f"mesh (mdal), groups {frames}, temporal over {e['time_span_s']} s; the temporal controller's "
            f"{c['frames']} steps of {c['step_s']:g} s show the frames {shown[0]}..{shown[-1]} in order")
    return problems


def service_check(tmp: Path, qp: str, runout: Path, scenario: Path, env: dict, qgis_python: str, verbose: bool) -> list[str]:
    """runout:run_file with EXECUTION=service against a `runout serve` started here (127.0.0.1, a
    free port, a token); its hazard rasters must equal those of the local run_file (tmp/file).
    Skipped when QGIS's Python lacks grpc or protobuf, or protoc or grpc_python_plugin is missing
    (the plugin generates runout_client's modules from the checkout)."""
    if subprocess.run([qgis_python, "-c", "import grpc, google.protobuf"], env=env, stdout=subprocess.DEVNULL,
                      stderr=subprocess.DEVNULL).returncode != 0 or not shutil.which("protoc") or \
            not shutil.which("grpc_python_plugin"):
        log("service: skipped (needs python3-grpcio, python3-protobuf, protobuf-compiler, protobuf-compiler-grpc)")
        return []
    if not (tmp / "file" / "max_depth.tif").is_file():
        return ["service: no local run_file results to compare with"]
    root = tmp / "server"
    root.mkdir()
    (root / "tokens").write_text("qgis-test-token\n")
    with (root / "server.err").open("wb") as err:
        proc = subprocess.Popen([str(runout), "serve", "--listen", "127.0.0.1:0", "--state-dir", str(root / "state"),
                                 "--tokens", str(root / "tokens"), "--workers", "1", "--log-file", str(root / "server.log")],
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=err, start_new_session=True)
    try:
        info = root / "state" / "server.json"
        deadline = time.monotonic() + 30
        while not info.exists():
            if proc.poll() is not None or time.monotonic() > deadline:
                return [f"service: runout serve did not start:\n{(root / 'server.err').read_text(errors='replace')}"]
            time.sleep(0.05)
        address = json.loads(info.read_text())["listen"]
        out = tmp / "service"
        r = run([qp, "--json", "run", "runout:run_file", "--", f"SCENARIO={scenario}", "EXECUTION=service",
                 f"SERVER={address}", "TOKEN=qgis-test-token", f"OUTPUT={out}"], env=env, verbose=verbose)
        if r.returncode != 0:
            return [f"service: runout:run_file on {address} failed (exit {r.returncode}):\n{r.stdout}\n{r.stderr}"]
        job = json.loads(r.stdout[r.stdout.index("{"):])["results"].get("JOB")
        differ = [f for f in HAZARD_RASTERS if (out / f).read_bytes() != (tmp / "file" / f).read_bytes()]
        if not job or differ:
            return [f"service: job {job!r}; rasters that differ from the local run's: {differ}"]
        log(f"service: job {job} on {address} succeeded, its hazard rasters byte for byte the local run's")
        return []
    finally:
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGTERM)
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()


def tree_files(source: Path) -> list[str]:
    """The files of the folders the test reads from (the scenarios' data, the clients)."""
    out = []
    for d in (source / "scenarios", source / "clients"):
        out += [str(p.relative_to(source)) for p in d.rglob("*") if p.is_file() or p.name == "__pycache__"]
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runout", required=True, help="the runout program under test")
    ap.add_argument("--source-dir", default=str(HERE.parent.parent), help="the repository (default: this file's)")
    ap.add_argument("--qgis-process", help="qgis_process (default $QGIS_PROCESS, else qgis_process.bin or qgis_process on PATH)")
    ap.add_argument("--qgis-python", default="/usr/bin/python3", help="the Python QGIS's bindings belong to")
    ap.add_argument("--scenario", default="scenarios/in-den-arelen.json", help="relative to the source dir")
    ap.add_argument("--keep", action="store_true", help="keep the temporary folder")
    ap.add_argument("-v", "--verbose", action="store_true")
    a = ap.parse_args(argv)
    qp = find_qgis_process(a.qgis_process)
    if not qp:
        log("SKIP: qgis_process not found (Debian: apt-get install qgis python3-qgis)")
        return SKIP
    source = Path(a.source_dir).resolve()
    runout = Path(a.runout).resolve()
    scen_path = source / a.scenario
    s = json.loads(scen_path.read_text(encoding="utf-8"))
    before = set(tree_files(source))
    tmp = Path(tempfile.mkdtemp(prefix="runout-qgis-test-"))
    t0 = time.monotonic()
    try:
        env = qgis_env(tmp, source)
        problems = []
        # The plugin, enabled in the throwaway profile.
        r = run([qp, "plugins", "enable", "runout_provider"], env=env, verbose=a.verbose)
        if r.returncode != 0 or "runout_provider" not in r.stdout:
            raise Failure(f"qgis_process plugins enable runout_provider failed (exit {r.returncode}):\n{r.stdout}\n{r.stderr}")
        # The reference: runout on the scenario file, in the background while QGIS runs.
        ref = tmp / "reference"
        ref_proc = subprocess.Popen([str(runout), "run", str(scen_path), "--out", str(ref), "--quiet", "--threads", "1"],
                                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        poi = tmp / "points_of_interest.geojson"
        if s.get("outputs", {}).get("points_of_interest"):
            write_points(poi, s["outputs"]["points_of_interest"])
        out = tmp / "qgis"
        args = algorithm_args(s, scen_path.parent, poi, out, runout) + ["THREADS=1"]
        t1 = time.monotonic()
        r = run([qp, "--json", "run", "runout:run", "--", *args], env=env, verbose=a.verbose)
        ref_out, _ = ref_proc.communicate(timeout=300)
        if ref_proc.returncode != 0:
            raise Failure(f"runout run {scen_path} failed (exit {ref_proc.returncode}):\n{ref_out}")
        if r.returncode != 0:
            raise Failure(f"qgis_process run runout:run failed (exit {r.returncode}):\n{r.stdout}\n{r.stderr}")
        try:
            res = json.loads(r.stdout[r.stdout.index("{"):])["results"]
        except (ValueError, KeyError) as e:
            raise Failure(f"qgis_process's JSON answer unreadable ({e}):\n{r.stdout}") from None
        log(f"runout:run through qgis_process: succeeded in {time.monotonic() - t1:.1f} s (the reference beside it)")
        results = Path(res["RESULTS"])
        for key, f in (("MAX_DEPTH", "max_depth.tif"), ("OUTLINE", "outline.gpkg"), ("RUN_RECORD", "run.json")):
            if Path(res.get(key) or "") != results / f:
                problems.append(f"output {key} = {res.get(key)!r}, expected {results / f}")
        scen = json.loads(Path(res["SCENARIO_FILE"]).read_text(encoding="utf-8"))
        if scen["dem"]["path"] != str(scen_path.parent / s["dem"]["path"]) or \
                scen["releases"][0]["path"] != str(scen_path.parent / s["releases"][0]["path"]):
            problems.append(f"the scenario does not name the layers' own files: dem {scen['dem']['path']}, "
                            f"release {scen['releases'][0]['path']}")
        # Byte for byte.
        differ = []
        for f in HAZARD_RASTERS:
            a_, b_ = ref / f, results / f
            if not a_.is_file() or not b_.is_file():
                problems.append(f"{f}: missing ({'reference' if not a_.is_file() else 'plugin'})")
            elif a_.read_bytes() != b_.read_bytes():
                differ.append(f)
        if differ:
            msg = [f"hazard rasters differ from runout run's: {', '.join(differ)}"]
            msg += [diagnose(ref / f, results / f, f, a.qgis_python, env) for f in differ]
            msg += ["resolved scenarios (run.json):"] + (scenario_differences(ref / "run.json", results / "run.json") or ["  no difference"])
            problems.append("\n".join(msg))
        else:
            log(f"byte for byte: {', '.join(HAZARD_RASTERS)} equal to runout run {a.scenario}'s")
        # A release layer without the thickness field.
        bad = tmp / "release_without_thickness.geojson"
        rel = json.loads((scen_path.parent / s["releases"][0]["path"]).read_text(encoding="utf-8"))
        field = s["releases"][0].get("thickness_attribute", "thickness_m")
        for feat in rel["features"]:
            feat["properties"]["depth_m"] = feat["properties"].pop(field, 1.0)
        bad.write_text(json.dumps(rel), encoding="utf-8")
        bad_args = [x if not x.startswith("RELEASE=") else f"RELEASE={bad}" for x in args]
        bad_args = [x if not x.startswith("OUTPUT=") else f"OUTPUT={tmp / 'bad'}" for x in bad_args]
        r = run([qp, "run", "runout:run", "--", *bad_args], env=env, verbose=a.verbose)
        said = r.stdout + r.stderr
        if r.returncode == 0:
            problems.append("a release layer without the thickness field: the run succeeded")
        elif f"no field '{field}'" not in said or "depth_m" not in said:
            problems.append(f"a release layer without the thickness field: the message does not name '{field}' "
                            f"and the layer's fields:\n{said}")
        else:
            msg = next((ln.strip() for ln in said.splitlines() if f"no field '{field}'" in ln), "")
            log(f"bad input: exit {r.returncode}: {msg}")
        # runout:run_file on the coarse variant: its results straight into OUTPUT.
        coarse = source / "scenarios" / "in-den-arelen-30m.json"
        r = run([qp, "--json", "run", "runout:run_file", "--", f"SCENARIO={coarse}", f"PROGRAM={runout}",
                 f"OUTPUT={tmp / 'file'}"], env=env, verbose=a.verbose)
        if r.returncode != 0:
            problems.append(f"runout:run_file {coarse} failed (exit {r.returncode}):\n{r.stdout}\n{r.stderr}")
        else:
            res_f = json.loads(r.stdout[r.stdout.index("{"):])["results"]
            rec = json.loads((tmp / "file" / "run.json").read_text(encoding="utf-8"))
            if res_f.get("RESULTS") != str(tmp / "file") or not (tmp / "file" / "max_depth.tif").is_file() or \
                    rec.get("scenario_file") != str(coarse):
                problems.append(f"runout:run_file: unexpected results {res_f}")
            else:
                log(f"runout:run_file {coarse.name}: succeeded, affected area {res_f.get('AFFECTED_AREA_M2')} m2")
        # The same scenario file as a job of a runout server: results equal the local run's.
        problems += service_check(tmp, qp, runout, coarse, env, a.qgis_python, a.verbose)
        # The results as the GUI loads them.
        problems += gui_check(tmp, source, results, a.qgis_python, env, a.verbose)
        # Nothing written into the source tree.
        added = sorted(set(tree_files(source)) - before)
        if added:
            problems.append(f"files written into the source tree: {added}")
        if problems:
            raise Failure("\n".join(problems))
        log(f"PASS ({time.monotonic() - t0:.1f} s)")
        return 0
    except (Failure, subprocess.TimeoutExpired) as e:
        log(f"FAIL: {e}")
        return 1
    finally:
        if a.keep:
            log(f"kept {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
