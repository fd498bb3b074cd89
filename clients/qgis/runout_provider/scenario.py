"""The scenario JSON (runout.v1.Scenario, docs/user/scenario-reference.md) from the algorithm's values.

No QGIS here: the algorithm resolves its layers to file paths and points, and this module puts
them, the material, the numerics and the outputs into the scenario's JSON form.
"""
from __future__ import annotations

import copy
import json
import math
from typing import Any, Iterable, Mapping

#: The valid names of the scenario's enumerations, in the order the algorithm offers them (the
#: first is the default unless said otherwise).
RHEOLOGIES = ["coulomb", "voellmy", "pouliquen_forterre", "mu_i"]
THICKNESS_MEASURED = ["normal", "vertical"]
RESAMPLINGS = ["cubic", "near", "bilinear", "cubicspline", "lanczos", "average"]
EARTH_PRESSURES = ["unity", "active-passive"]
LIMITERS = ["minmod", "vanleer", "superbee"]
BOUNDARIES = ["outflow", "wall"]

#: material.* numbers the algorithm takes: (parameter name, scenario key, description, min, max).
#: Each is left out of the scenario when not given (the scenario's default, or its check naming it
#: when the rheology needs it).
MATERIAL_NUMBERS = [
    ("DENSITY", "density_kg_m3", "Density [kg/m3]", 0.0, 10000.0),
    ("BED_FRICTION", "bed_friction_deg", "Bed friction angle delta [deg] (coulomb)", 0.0, 89.999),
    ("INTERNAL_FRICTION", "internal_friction_deg", "Internal friction angle phi [deg] (earth pressure active-passive)", 0.0, 89.999),
    ("VOELLMY_MU", "voellmy_mu", "Voellmy mu, dry-friction coefficient (voellmy)", 0.0, 4.999),
    ("VOELLMY_XI", "voellmy_xi", "Voellmy xi, turbulent-friction coefficient [m/s2] (voellmy)", 0.0, 100000.0),
    ("BED_FRICTION_1", "bed_friction_1_deg", "delta_1, lowest friction angle of steady flow [deg] (pouliquen_forterre)", 0.0, 89.999),
    ("BED_FRICTION_2", "bed_friction_2_deg", "delta_2, friction angle of thin layers [deg] (pouliquen_forterre)", 0.0, 89.999),
    ("BED_FRICTION_3", "bed_friction_3_deg", "delta_3, friction angle of mu_start [deg] (pouliquen_forterre; unset: delta_1)", 0.0, 89.999),
    ("PF_BETA", "pf_beta", "beta of the flow rule (pouliquen_forterre)", 0.0, 10.0),
    ("PF_LENGTH", "pf_length_m", "L, length of h_stop [m] (pouliquen_forterre)", 0.0, 100.0),
    ("PF_GAMMA", "pf_gamma", "gamma, offset of the flow rule (pouliquen_forterre)", 0.0, 10.0),
    ("MU_S", "mu_s", "mu_s, friction coefficient as I -> 0 (mu_i)", 0.0, 4.999),
    ("MU_2", "mu_2", "mu_2, friction coefficient as I -> infinity (mu_i)", 0.0, 4.999),
    ("MU_I0", "mu_i0", "I_0 (mu_i)", 0.0, 10.0),
    ("GRAIN_DIAMETER", "grain_diameter_m", "Grain diameter d [m] (mu_i)", 0.0, 100.0),
    ("GRAIN_DENSITY", "grain_density_kg_m3", "Grain density rho_s [kg/m3] (mu_i)", 0.0, 10000.0),
]
#: The material parameters shown without "advanced" (the rest are advanced parameters).
MATERIAL_BASIC = {"DENSITY", "BED_FRICTION", "INTERNAL_FRICTION", "VOELLMY_MU", "VOELLMY_XI"}


class ScenarioInputError(ValueError):
    """A value the scenario cannot take; the message names the parameter."""


def number(v: Any) -> float | int:
    """A JSON number: integral floats as ints (10.0 -> 10), as a person writes them."""
    f = float(v)
    if not math.isfinite(f):
        raise ScenarioInputError(f"not a finite number: {v!r}")
    return int(f) if f.is_integer() and abs(f) < 2 ** 53 else f


def release_block(path: str, *, thickness_attribute: str | None = None, thickness_m: float | None = None,
                  thickness_measured: str = "normal", min_slope_attribute: str | None = None,
                  max_slope_attribute: str | None = None, min_slope_deg: float | None = None,
                  max_slope_deg: float | None = None) -> dict:
    """One ``releases[]`` entry: polygons with a thickness field or a constant, a slope window."""
    if thickness_attribute and thickness_m is not None:
        raise ScenarioInputError("give the release thickness either as a field (THICKNESS_FIELD) or as a constant "
                                 "(THICKNESS), not both")
    if not thickness_attribute and thickness_m is None:
        raise ScenarioInputError("the release needs a thickness: a field of the release layer (THICKNESS_FIELD, e.g. "
                                 "thickness_m) or a constant in metres (THICKNESS)")
    r: dict[str, Any] = {"path": path}
    if thickness_attribute:
        r["thickness_attribute"] = thickness_attribute
    else:
        r["thickness_m"] = number(thickness_m)
    r["thickness_measured"] = thickness_measured
    if min_slope_attribute and min_slope_deg is not None:
        raise ScenarioInputError("give the minimum slope either as a field (MIN_SLOPE_FIELD) or a constant (MIN_SLOPE), not both")
    if max_slope_attribute and max_slope_deg is not None:
        raise ScenarioInputError("give the maximum slope either as a field (MAX_SLOPE_FIELD) or a constant (MAX_SLOPE), not both")
    if min_slope_attribute:
        r["min_slope_attribute"] = min_slope_attribute
    elif min_slope_deg is not None:
        r["min_slope_deg"] = number(min_slope_deg)
    if max_slope_attribute:
        r["max_slope_attribute"] = max_slope_attribute
    elif max_slope_deg is not None:
        r["max_slope_deg"] = number(max_slope_deg)
    return r


def build(*, name: str, dem: str, releases: Iterable[dict], area_of_interest: str | None = None,
          resolution_m: float | None = None, grid_crs: str | None = "utm", resampling: str = "cubic",
          material: Mapping[str, Any], numerics: Mapping[str, Any], outputs: Mapping[str, Any],
          points_of_interest: Iterable[Mapping[str, Any]] = (), path_line: str | None = None,
          observed_outline: str | None = None, extra: Mapping[str, Any] | None = None) -> dict:
    """The scenario as a dict in its JSON form (field names as in the .proto)."""
    s: dict[str, Any] = {"name": name, "engine": "depth-averaged", "dem": {"path": dem}}
    if area_of_interest:
        s["area_of_interest"] = {"path": area_of_interest}
    grid: dict[str, Any] = {}
    if resolution_m:
        grid["resolution_m"] = number(resolution_m)
    if grid_crs:
        grid["crs"] = grid_crs
    grid["resampling"] = resampling
    s["grid"] = grid
    s["releases"] = list(releases)
    s["material"] = {k: (number(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v)
                     for k, v in material.items() if v is not None}
    s["numerics"] = {k: (number(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v)
                     for k, v in numerics.items() if v is not None}
    out = {k: (number(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v)
           for k, v in outputs.items() if v is not None}
    pois = [dict(p) for p in points_of_interest]
    if pois:
        out = {"points_of_interest": pois, **out}
    s["outputs"] = out
    if observed_outline:
        s["observations"] = {"outline_path": observed_outline}
    if path_line:
        s["path"] = {"line_path": path_line}
    if extra:
        s = merge(s, extra)
    return s


def merge(base: Mapping[str, Any], extra: Mapping[str, Any]) -> dict:
    """``extra`` over ``base``: objects merged key by key, anything else (lists too) replaced."""
    out = copy.deepcopy(dict(base))
    for k, v in extra.items():
        if isinstance(v, Mapping) and isinstance(out.get(k), Mapping):
            out[k] = merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def parse_extra(text: str | None) -> dict:
    """The EXTRA parameter: a JSON object in the scenario's form, or nothing."""
    if not text or not text.strip():
        return {}
    try:
        v = json.loads(text)
    except ValueError as e:
        raise ScenarioInputError(f"EXTRA is not valid JSON: {e}") from None
    if not isinstance(v, dict):
        raise ScenarioInputError("EXTRA must be a JSON object in the scenario's form, e.g. "
                                 '{"outputs": {"pressure_zones_kpa": [{"name": "blue", "from_kpa": 3}]}}')
    return v


def write(scenario: Mapping[str, Any], path: str) -> None:
    """The scenario as an indented JSON file (UTF-8)."""
    with open(path, "w", encoding="utf-8") as f:
        json.dump(scenario, f, indent=2, ensure_ascii=False)
        f.write("\n")
