"""The provider's algorithms: ``runout:run`` (a scenario from layers) and ``runout:run_file``."""
from __future__ import annotations

import json
import os

from qgis.core import (
    QgsProcessing,
    QgsProcessingAlgorithm,
    QgsProcessingException,
    QgsProcessingOutputFile,
    QgsProcessingOutputFolder,
    QgsProcessingOutputNumber,
    QgsProcessingOutputRasterLayer,
    QgsProcessingOutputString,
    QgsProcessingOutputVectorLayer,
    QgsProcessingParameterDefinition,
    QgsProcessingParameterEnum,
    QgsProcessingParameterField,
    QgsProcessingParameterFile,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterRasterLayer,
    QgsProcessingParameterString,
    QgsProcessingParameterVectorLayer,
)

from . import layers, results, runner, scenario

EXECUTIONS = ["local", "service"]
#: QGIS's default file filter "All files (*.*)" refuses a name without a dot (the program "runout").
ANY_FILE = "All files (*)"

#: The hazard rasters and vectors a run may write, as algorithm outputs: (output name, file, kind, description).
RESULT_OUTPUTS = [
    ("MAX_DEPTH", "max_depth.tif", "raster", "Maximum flow depth [m]"),
    ("MAX_SPEED", "max_speed.tif", "raster", "Maximum flow speed [m/s]"),
    ("MAX_PRESSURE", "max_pressure.tif", "raster", "Maximum pressure [kPa]"),
    ("DEPOSIT", "deposit.tif", "raster", "Deposit depth [m]"),
    ("ARRIVAL_TIME", "arrival_time.tif", "raster", "Arrival time [s]"),
    ("PRESSURE_ZONES", "pressure_zones.tif", "raster", "Pressure zones"),
    ("OUTLINE", "outline.gpkg", "vector", "Runout outline"),
    ("PRESSURE_ZONES_POLYGONS", "pressure_zones.gpkg", "vector", "Pressure zones (polygons)"),
    ("TIMESERIES", "timeseries.nc", "file", "Time series of depth and speed (NetCDF)"),
    ("RUN_RECORD", "run.json", "file", "Run record (run.json)"),
]


def _advanced(p):
    p.setFlags(p.flags() | QgsProcessingParameterDefinition.FlagAdvanced)
    return p


class _RunBase(QgsProcessingAlgorithm):
    """What both algorithms share: where the run goes (local or a server), the outputs."""

    def group(self):
        return ""

    def groupId(self):  # noqa: N802 - QGIS's name
        return ""

    def flags(self):
        return super().flags() | QgsProcessingAlgorithm.FlagCanCancel

    def _add_execution_parameters(self):
        self.addParameter(QgsProcessingParameterEnum(
            "EXECUTION", "Where to run", options=EXECUTIONS, defaultValue="local", usesStaticStrings=True))
        self.addParameter(QgsProcessingParameterFile(
            "PROGRAM", "runout program (local; default: runout on PATH, else $RUNOUT_PROGRAM)",
            behavior=QgsProcessingParameterFile.File, optional=True, fileFilter=ANY_FILE))
        self.addParameter(_advanced(QgsProcessingParameterNumber(
            "THREADS", "Threads (local; default: all cores)", type=QgsProcessingParameterNumber.Integer,
            optional=True, minValue=1)))
        self.addParameter(QgsProcessingParameterString(
            "SERVER", "runout server HOST:PORT (service; default: $RUNOUT_SERVER, else 127.0.0.1:50051)", optional=True))
        self.addParameter(QgsProcessingParameterString(
            "TOKEN", "Token (service; default: $RUNOUT_TOKEN)", optional=True))
        self.addParameter(_advanced(QgsProcessingParameterFile(
            "TLS_CA", "TLS CA certificate of the server (service, PEM)", behavior=QgsProcessingParameterFile.File,
            optional=True, fileFilter=ANY_FILE)))

    def _add_outputs(self):
        self.addOutput(QgsProcessingOutputFolder("RESULTS", "Results folder"))
        self.addOutput(QgsProcessingOutputFile("SCENARIO_FILE", "Scenario file"))
        for name, _, kind, desc in RESULT_OUTPUTS:
            if kind == "raster":
                self.addOutput(QgsProcessingOutputRasterLayer(name, desc))
            elif kind == "vector":
                self.addOutput(QgsProcessingOutputVectorLayer(name, desc, QgsProcessing.TypeVectorPolygon))
            else:
                self.addOutput(QgsProcessingOutputFile(name, desc))
        self.addOutput(QgsProcessingOutputString("JOB", "Job id (service)"))
        self.addOutput(QgsProcessingOutputNumber("AFFECTED_AREA_M2", "Affected area [m2]"))
        self.addOutput(QgsProcessingOutputNumber("MAX_DEPTH_M", "Largest flow depth [m]"))

    def _execute(self, parameters, context, feedback, scenario_path, results_dir, title, end_time_s):
        """Run the scenario file into results_dir (local or service); the outputs' dict."""
        execution = self.parameterAsEnumString(parameters, "EXECUTION", context) or "local"
        job = ""
        try:
            if execution == "service":
                res = runner.run_service(
                    scenario_path, results_dir, feedback,
                    server=self.parameterAsString(parameters, "SERVER", context) or None,
                    token=self.parameterAsString(parameters, "TOKEN", context) or None,
                    tls_ca=self.parameterAsFile(parameters, "TLS_CA", context) or None)
                job = res["job"]
            else:
                threads = None
                if parameters.get("THREADS") not in (None, ""):
                    threads = self.parameterAsInt(parameters, "THREADS", context)
                runner.run_local(scenario_path, results_dir, feedback,
                                 program=self.parameterAsFile(parameters, "PROGRAM", context) or None,
                                 threads=threads, end_time_s=end_time_s)
        except runner.RunCancelled as e:
            feedback.reportError(str(e))
            raise QgsProcessingException(str(e)) from None
        except runner.RunError as e:
            raise QgsProcessingException(str(e)) from None
        out = {"RESULTS": results_dir, "SCENARIO_FILE": scenario_path, "JOB": job}
        for name, fname, _, _ in RESULT_OUTPUTS:
            p = os.path.join(results_dir, fname)
            out[name] = p if os.path.exists(p) else None
        record = {}
        try:
            with open(os.path.join(results_dir, "run.json"), encoding="utf-8") as f:
                record = json.load(f)
        except (OSError, ValueError):
            feedback.reportError(f"no readable run record in {results_dir}")
        res = record.get("results") or {}
        out["AFFECTED_AREA_M2"] = res.get("affected_area_m2")
        out["MAX_DEPTH_M"] = res.get("max_depth_m")
        for p in res.get("points_of_interest") or []:
            feedback.pushInfo("point of interest '{}': max depth {} m, max speed {} m/s, max pressure {} kPa, zone '{}'".format(
                p.get("name"), p.get("max_depth_m"), p.get("max_speed_m_s"), p.get("max_pressure_kpa"), p.get("zone", "")))
        results.load_on_completion(results_dir, context, feedback, title)
        return out


class RunScenarioAlgorithm(_RunBase):
    """runout:run: a scenario from a DEM, release polygons and the run's settings."""

    def name(self):
        return "run"

    def displayName(self):  # noqa: N802 - QGIS's name
        return "Run a runout scenario"

    def shortHelpString(self):  # noqa: N802 - QGIS's name
        return (
            "Runs a depth-averaged runout scenario (Savage-Hutter) on a DEM from release polygons and writes the hazard "
            "maps: maximum flow depth, speed and pressure, deposit, arrival time, pressure zones, the runout outline and "
            "the time series, styled as runout's maps.<br><br>"
            "The algorithm writes OUTPUT/scenario.json (runout.v1.Scenario; docs/user/scenario-reference.md has every "
            "field) and runs it into OUTPUT/results, with the runout program on this machine (Where to run: local) or on a "
            "runout server (service). Layers backed by a plain file (GeoTIFF, GeoJSON, Shapefile, a GeoPackage of one layer) "
            "are named by their path; other layers are written to OUTPUT/inputs first.<br><br>"
            "Release thickness: a field of the release layer (e.g. thickness_m) or a constant; an optional slope window "
            "per polygon (fields) or for all. Empty material values are left to the scenario's defaults; the rheology "
            "names the values it needs (coulomb: bed friction; voellmy: mu and xi). EXTRA takes any further scenario "
            "fields as a JSON object (e.g. pressure zones, resistance areas).")

    def createInstance(self):  # noqa: N802 - QGIS's name
        return RunScenarioAlgorithm()

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS's name
        P = QgsProcessingParameterNumber
        self.addParameter(QgsProcessingParameterRasterLayer("DEM", "DEM (terrain)"))
        self.addParameter(QgsProcessingParameterVectorLayer(
            "RELEASE", "Release polygons", types=[QgsProcessing.TypeVectorPolygon]))
        self.addParameter(QgsProcessingParameterField(
            "THICKNESS_FIELD", "Release thickness field [m] (e.g. thickness_m)", parentLayerParameterName="RELEASE",
            type=QgsProcessingParameterField.Numeric, optional=True))
        self.addParameter(P("THICKNESS", "Release thickness for every polygon [m] (instead of a field)", type=P.Double,
                            optional=True, minValue=0.0, maxValue=500.0))
        self.addParameter(QgsProcessingParameterEnum(
            "THICKNESS_MEASURED", "Thickness measured", options=scenario.THICKNESS_MEASURED, defaultValue="normal",
            usesStaticStrings=True))
        self.addParameter(QgsProcessingParameterField(
            "MIN_SLOPE_FIELD", "Minimum slope field [deg] (slope window)", parentLayerParameterName="RELEASE",
            type=QgsProcessingParameterField.Numeric, optional=True))
        self.addParameter(QgsProcessingParameterField(
            "MAX_SLOPE_FIELD", "Maximum slope field [deg] (slope window)", parentLayerParameterName="RELEASE",
            type=QgsProcessingParameterField.Numeric, optional=True))
        self.addParameter(_advanced(P("MIN_SLOPE", "Minimum slope for every polygon [deg]", type=P.Double, optional=True,
                                      minValue=0.0, maxValue=89.999)))
        self.addParameter(_advanced(P("MAX_SLOPE", "Maximum slope for every polygon [deg]", type=P.Double, optional=True,
                                      minValue=0.001, maxValue=90.0)))
        self.addParameter(QgsProcessingParameterVectorLayer(
            "AOI", "Area of interest (polygons; default: the whole DEM)", types=[QgsProcessing.TypeVectorPolygon],
            optional=True))
        self.addParameter(QgsProcessingParameterVectorLayer(
            "PATH", "Avalanche path (line, from the top down; default: steepest descent)",
            types=[QgsProcessing.TypeVectorLine], optional=True))
        self.addParameter(QgsProcessingParameterVectorLayer(
            "POINTS", "Points of interest", types=[QgsProcessing.TypeVectorPoint], optional=True))
        self.addParameter(QgsProcessingParameterField(
            "POINTS_NAME_FIELD", "Points of interest: name field", parentLayerParameterName="POINTS",
            type=QgsProcessingParameterField.Any, optional=True))
        self.addParameter(QgsProcessingParameterVectorLayer(
            "OBSERVED", "Observed outline (polygons; the run is scored against it)",
            types=[QgsProcessing.TypeVectorPolygon], optional=True))
        # Grid.
        self.addParameter(P("RESOLUTION", "Grid resolution [m] (0: the DEM's)", type=P.Double, defaultValue=0.0,
                            minValue=0.0, maxValue=10000.0))
        self.addParameter(QgsProcessingParameterString(
            "GRID_CRS", "Grid CRS: utm (the UTM zone of the area), dem, or EPSG:<code>", defaultValue="utm"))
        self.addParameter(QgsProcessingParameterEnum(
            "RESAMPLING", "DEM resampling", options=scenario.RESAMPLINGS, defaultValue="cubic", usesStaticStrings=True))
        # Material.
        self.addParameter(QgsProcessingParameterEnum(
            "RHEOLOGY", "Rheology (basal friction law)", options=scenario.RHEOLOGIES, defaultValue="coulomb",
            usesStaticStrings=True))
        for pname, key, desc, lo, hi in scenario.MATERIAL_NUMBERS:
            p = P(pname, desc, type=P.Double, optional=True, minValue=lo, maxValue=hi,
                  defaultValue=300.0 if pname == "DENSITY" else None)
            self.addParameter(p if pname in scenario.MATERIAL_BASIC else _advanced(p))
        self.addParameter(QgsProcessingParameterEnum(
            "EARTH_PRESSURE", "Earth pressure", options=scenario.EARTH_PRESSURES, defaultValue="unity",
            usesStaticStrings=True))
        # Numerics.
        self.addParameter(P("END_TIME", "End time [s] (simulated time at most)", type=P.Double, defaultValue=600.0,
                            minValue=0.001, maxValue=100000.0))
        self.addParameter(_advanced(P("CFL", "CFL number", type=P.Double, defaultValue=0.45, minValue=0.01, maxValue=0.5)))
        self.addParameter(_advanced(QgsProcessingParameterEnum(
            "LIMITER", "Slope limiter", options=scenario.LIMITERS, defaultValue="minmod", usesStaticStrings=True)))
        self.addParameter(_advanced(P("STOP_FRACTION", "Stop when the kinetic energy falls below this fraction of its peak",
                                      type=P.Double, defaultValue=0.01, minValue=0.0, maxValue=0.999999)))
        self.addParameter(_advanced(QgsProcessingParameterEnum(
            "BOUNDARY", "At the grid's edges", options=scenario.BOUNDARIES, defaultValue="outflow", usesStaticStrings=True)))
        # Outputs.
        self.addParameter(P("OUTLINE_THRESHOLD", "Outline threshold: max depth above [m]", type=P.Double, defaultValue=0.1,
                            minValue=0.000001, maxValue=100.0))
        self.addParameter(_advanced(P("FLOW_THRESHOLD", "Flow threshold: depth that counts as flowing [m]", type=P.Double,
                                      defaultValue=0.01, minValue=0.000001, maxValue=100.0)))
        self.addParameter(P("TIMESERIES_INTERVAL", "Time series: a frame every [s] (0: none)", type=P.Double,
                            defaultValue=10.0, minValue=0.0, maxValue=100000.0))
        self.addParameter(QgsProcessingParameterString("NAME", "Scenario name (the maps' titles)", defaultValue="runout scenario"))
        self.addParameter(_advanced(QgsProcessingParameterString(
            "EXTRA", "Further scenario fields (a JSON object merged into the scenario)", multiLine=True, optional=True)))
        self._add_execution_parameters()
        self.addParameter(QgsProcessingParameterFolderDestination("OUTPUT", "Output folder"))
        self._add_outputs()

    # -- helpers ---------------------------------------------------------------------------

    @staticmethod
    def _given(parameters, name):
        v = parameters.get(name)
        return v is not None and v != "" and not (isinstance(v, str) and not v.strip())

    def _number(self, parameters, name, context):
        return self.parameterAsDouble(parameters, name, context) if self._given(parameters, name) else None

    def _field(self, parameters, name, context):
        v = self.parameterAsFields(parameters, name, context) if self._given(parameters, name) else []
        return v[0] if v else None

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS's name
        out_dir = self.parameterAsString(parameters, "OUTPUT", context)
        if not out_dir:
            raise QgsProcessingException("no output folder (OUTPUT)")
        out_dir = os.path.abspath(out_dir)
        inputs_dir = os.path.join(out_dir, "inputs")
        results_dir = os.path.join(out_dir, "results")
        os.makedirs(out_dir, exist_ok=True)

        dem = self.parameterAsRasterLayer(parameters, "DEM", context)
        if dem is None:
            raise QgsProcessingException("DEM: not a raster layer")
        release = self.parameterAsVectorLayer(parameters, "RELEASE", context)
        if release is None:
            raise QgsProcessingException("RELEASE: not a vector layer")

        thickness_field = self._field(parameters, "THICKNESS_FIELD", context)
        thickness = self._number(parameters, "THICKNESS", context)
        min_field = self._field(parameters, "MIN_SLOPE_FIELD", context)
        max_field = self._field(parameters, "MAX_SLOPE_FIELD", context)
        for f, what in ((thickness_field, "release thickness field (THICKNESS_FIELD)"),
                        (min_field, "release minimum slope field (MIN_SLOPE_FIELD)"),
                        (max_field, "release maximum slope field (MAX_SLOPE_FIELD)")):
            if f:
                layers.require_field(release, f, what)
        try:
            rel = scenario.release_block(
                "", thickness_attribute=thickness_field, thickness_m=thickness,
                thickness_measured=self.parameterAsEnumString(parameters, "THICKNESS_MEASURED", context) or "normal",
                min_slope_attribute=min_field, max_slope_attribute=max_field,
                min_slope_deg=self._number(parameters, "MIN_SLOPE", context),
                max_slope_deg=self._number(parameters, "MAX_SLOPE", context))
            extra = scenario.parse_extra(self.parameterAsString(parameters, "EXTRA", context))
        except scenario.ScenarioInputError as e:
            raise QgsProcessingException(str(e)) from None
        if release.featureCount() == 0:
            raise QgsProcessingException(f"release: the layer '{release.name()}' has no polygons")

        rel["path"] = layers.vector_input(release, "release", inputs_dir, context, feedback)
        dem_path = layers.raster_input(dem, "dem", inputs_dir, context, feedback)
        aoi = self.parameterAsVectorLayer(parameters, "AOI", context) if self._given(parameters, "AOI") else None
        path_line = self.parameterAsVectorLayer(parameters, "PATH", context) if self._given(parameters, "PATH") else None
        observed = self.parameterAsVectorLayer(parameters, "OBSERVED", context) if self._given(parameters, "OBSERVED") else None
        points = self.parameterAsVectorLayer(parameters, "POINTS", context) if self._given(parameters, "POINTS") else None
        pois = layers.points_of_interest(points, self._field(parameters, "POINTS_NAME_FIELD", context)) if points else []

        material = {"rheology": self.parameterAsEnumString(parameters, "RHEOLOGY", context) or "coulomb"}
        for pname, key, _, _, _ in scenario.MATERIAL_NUMBERS:
            material[key] = self._number(parameters, pname, context)
        material["earth_pressure"] = self.parameterAsEnumString(parameters, "EARTH_PRESSURE", context) or "unity"
        end_time = self.parameterAsDouble(parameters, "END_TIME", context)
        numerics = {
            "limiter": self.parameterAsEnumString(parameters, "LIMITER", context) or "minmod",
            "cfl": self.parameterAsDouble(parameters, "CFL", context),
            "end_time_s": end_time,
            "stop_fraction": self.parameterAsDouble(parameters, "STOP_FRACTION", context),
            "boundary": self.parameterAsEnumString(parameters, "BOUNDARY", context) or "outflow",
        }
        outputs = {
            "outline_threshold_m": self.parameterAsDouble(parameters, "OUTLINE_THRESHOLD", context),
            "flow_threshold_m": self.parameterAsDouble(parameters, "FLOW_THRESHOLD", context),
        }
        interval = self.parameterAsDouble(parameters, "TIMESERIES_INTERVAL", context)
        if interval > 0:
            outputs["timeseries_interval_s"] = interval
        name = self.parameterAsString(parameters, "NAME", context) or "runout scenario"
        try:
            s = scenario.build(
                name=name, dem=dem_path, releases=[rel],
                area_of_interest=layers.vector_input(aoi, "area_of_interest", inputs_dir, context, feedback) if aoi else None,
                resolution_m=self.parameterAsDouble(parameters, "RESOLUTION", context) or None,
                grid_crs=(self.parameterAsString(parameters, "GRID_CRS", context) or "utm").strip(),
                resampling=self.parameterAsEnumString(parameters, "RESAMPLING", context) or "cubic",
                material=material, numerics=numerics, outputs=outputs, points_of_interest=pois,
                path_line=layers.vector_input(path_line, "path", inputs_dir, context, feedback) if path_line else None,
                observed_outline=(layers.vector_input(observed, "observed_outline", inputs_dir, context, feedback)
                                  if observed else None),
                extra=extra)
        except scenario.ScenarioInputError as e:
            raise QgsProcessingException(str(e)) from None
        scenario_path = os.path.join(out_dir, "scenario.json")
        scenario.write(s, scenario_path)
        feedback.pushInfo(f"Scenario written to {scenario_path}")
        if feedback.isCanceled():
            raise QgsProcessingException("cancelled before the run started")
        return self._execute(parameters, context, feedback, scenario_path, results_dir, name,
                             runner.end_time_of(s))


class RunScenarioFileAlgorithm(_RunBase):
    """runout:run_file: an existing scenario JSON, run the same way."""

    def name(self):
        return "run_file"

    def displayName(self):  # noqa: N802 - QGIS's name
        return "Run a scenario file"

    def shortHelpString(self):  # noqa: N802 - QGIS's name
        return ("Runs an existing runout scenario file (JSON, runout.v1.Scenario; its relative paths start in its "
                "folder) with the runout program on this machine or on a runout server, into the output folder "
                "(replaced when it holds a previous result), and loads the results styled.")

    def createInstance(self):  # noqa: N802 - QGIS's name
        return RunScenarioFileAlgorithm()

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS's name
        self.addParameter(QgsProcessingParameterFile(
            "SCENARIO", "Scenario file (JSON)", behavior=QgsProcessingParameterFile.File, extension="json"))
        self._add_execution_parameters()
        self.addParameter(QgsProcessingParameterFolderDestination("OUTPUT", "Results folder"))
        self._add_outputs()

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS's name
        path = self.parameterAsFile(parameters, "SCENARIO", context)
        if not path or not os.path.isfile(path):
            raise QgsProcessingException(f"scenario file '{path}' does not exist")
        path = os.path.abspath(path)
        try:
            with open(path, encoding="utf-8") as f:
                s = json.load(f)
        except (OSError, ValueError) as e:
            raise QgsProcessingException(f"scenario file '{path}': {e}") from None
        if not isinstance(s, dict):
            raise QgsProcessingException(f"scenario file '{path}': not a JSON object")
        out_dir = os.path.abspath(self.parameterAsString(parameters, "OUTPUT", context))
        title = s.get("name") or os.path.splitext(os.path.basename(path))[0]
        return self._execute(parameters, context, feedback, path, out_dir, title, runner.end_time_of(s))
