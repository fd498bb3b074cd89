#!/usr/bin/env python3
"""In den Arelen with the farmhouse as a building and a 3D nest of 300 x 300 m around it on 5 m columns
(scenarios/in-den-arelen-farmhouse.json; label bench, about 4 minutes on 2 cores): the whole run's
wall time (target: under 15 minutes), the nest's conservation, the farmhouse's load against the
depth-averaged pressure next to it (docs/validation/validation.md, D4).
Usage: farmhouse_nest.py RUNOUT SCENARIO WORKDIR"""
import json
import subprocess
import sys
import time

runout, scenario, work = sys.argv[1:4]
out = work + "/in-den-arelen-farmhouse"
subprocess.run(["rm", "-rf", out], check=True)
t0 = time.monotonic()
subprocess.run([runout, "run", scenario, "--out", out], check=True, stdout=subprocess.DEVNULL)
wall = time.monotonic() - t0
rec = json.load(open(out + "/run.json"))
nest = rec["nest"]
inner = json.load(open(out + "/nest/run.json"))
da = rec["structures"][0]
fh = inner["structures"][0]
same = nest["structures"][0] == fh  # the parent's run.json carries the nest's loads
print(f"whole run {wall:.0f} s wall (3D nest {nest['seconds_3d']:.0f} s, {nest['mesh_cells']} cells of "
      f"{nest['column_width_m']:.1f} m columns, from t = {nest['start_time_s']:.1f} s)")
print(f"nest inflow: depth-averaged {nest['inflow_depth_averaged_m3']:.1f} m3, 3D {nest['inflow_3d_m3']:.1f} m3 "
      f"(difference {nest['inflow_relative_difference']:.1e}); 3D balance {nest['volume_error_3d']:.1e}")
print(f"farmhouse: peak force {fh.get('peak_force_kn', 0):.1f} kN at {fh.get('peak_force_time_s', 0):.1f} s, "
      f"impulse {fh.get('impulse_kn_s', 0):.1f} kN s, highest pressure {fh.get('max_pressure_kpa', 0):.1f} kPa "
      f"at {fh.get('max_pressure_height_m', 0):.2f} m; depth-averaged next to it: rho u^2 {da['max_pressure_next_kpa']:.0f} kPa, "
      f"depth {da['max_depth_next_m']:.2f} m")
print(f"loads resolved: {fh.get('loads_resolved')}: {fh.get('loads_note')}")
ok = (wall < 900 and nest["inflow_relative_difference"] < 0.01 and nest["volume_error_3d"] < 1e-9 and fh.get("peak_force_kn", 0) > 0
      and same and fh.get("loads_resolved") is False)
sys.exit(0 if ok else 1)
