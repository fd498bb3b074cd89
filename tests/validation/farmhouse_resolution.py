#!/usr/bin/env python3
"""The farmhouse's 3D loads against the nest's column width (docs/validation/validation.md, D4):
In den Arelen with the farmhouse (scenarios/in-den-arelen-farmhouse.json) and square nests around
it, 100 m on 5 m and on 2.5 m columns (about 5 minutes on 2 cores, label bench), the layers as the
300 m nest's (first 0.097 m, band 4.71 m). Prints per nest the peak force,
the highest pressure and the verdict; passes when the loads grow as the columns shrink (no 5 m
figure is a converged one) and every run keeps its volume.
Usage: farmhouse_resolution.py RUNOUT SCENARIO WORKDIR"""
import json
import os
import subprocess
import sys
import time

runout, scenario, work = sys.argv[1:4]
base = json.load(open(scenario))
here = os.path.dirname(os.path.abspath(scenario))
lon0, lat0 = 9.8539, 46.8367  # the farmhouse (scenarios/data/arelen/farmhouse.geojson)
m_per_deg_lon, m_per_deg_lat = 76150.0, 111317.0


def box(path, half_m):
    dl, dp = half_m / m_per_deg_lon, half_m / m_per_deg_lat
    ring = [[lon0 - dl, lat0 - dp], [lon0 + dl, lat0 - dp], [lon0 + dl, lat0 + dp], [lon0 - dl, lat0 + dp], [lon0 - dl, lat0 - dp]]
    json.dump({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"name": "nest"},
               "geometry": {"type": "Polygon", "coordinates": [ring]}}]}, open(path, "w"))


def absolute(sc):
    sc["dem"]["path"] = os.path.join(here, sc["dem"]["path"])
    sc["area_of_interest"]["path"] = os.path.join(here, sc["area_of_interest"]["path"])
    for r in sc["releases"]:
        r["path"] = os.path.join(here, r["path"])
    for s in sc["structures"]:
        s["path"] = os.path.join(here, s["path"])


rows = []
for size, refinement in ((100, 2), (100, 4)):
    name = f"farmhouse-{size}m-r{refinement}"
    out = os.path.join(work, name)
    subprocess.run(["rm", "-rf", out], check=True)
    os.makedirs(out)
    sc = json.loads(json.dumps(base))
    absolute(sc)
    box(os.path.join(out, "nest.geojson"), size / 2)
    sc["nest"] = {"path": os.path.join(out, "nest.geojson"), "refinement": refinement, "first_layer_m": 0.097, "band_height_m": 4.71}
    sc["outputs"]["maps"] = False
    path = os.path.join(work, name + ".json")
    json.dump(sc, open(path, "w"), indent=1)
    t0 = time.monotonic()
    subprocess.run([runout, "run", path, "--out", os.path.join(out, "run")], check=True, stdout=subprocess.DEVNULL)
    wall = time.monotonic() - t0
    rec = json.load(open(os.path.join(out, "run", "run.json")))
    n = rec["nest"]
    fh = n["structures"][0]
    rows.append((size, n["column_width_m"], n["mesh_cells"], wall, fh["peak_force_kn"], fh["max_pressure_kpa"], fh["impulse_kn_s"],
                 fh["max_depth_next_m"], fh["loads_resolved"], n["volume_error_3d"], n["inflow_relative_difference"]))
    print(f"nest {size} m, columns {n['column_width_m']:.2f} m, {n['mesh_cells']} cells, {wall:.0f} s: peak force {fh['peak_force_kn']:.1f} kN, "
          f"highest pressure {fh['max_pressure_kpa']:.1f} kPa, impulse {fh['impulse_kn_s']:.1f} kN s, flow next {fh['max_depth_next_m']:.2f} m, "
          f"resolved {fh['loads_resolved']}; balance {n['volume_error_3d']:.1e}, inflow difference {n['inflow_relative_difference']:.1e}",
          flush=True)
growing = all(b[4] > a[4] and b[5] > a[5] for a, b in zip(rows, rows[1:]))
kept = all(r[9] < 1e-9 and r[10] < 0.01 for r in rows)
print(f"loads grow as the columns shrink: {growing}; volumes kept: {kept}")
sys.exit(0 if growing and kept else 1)
