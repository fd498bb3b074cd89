#!/usr/bin/env python3
"""The wall-impact case on 2.5 mm cells (label full; about 5 minutes on 2 cores): the force on the wall,
median over 0.2-0.3 s, within 10 % of rho b h (u^2 + g h / 2) (docs/validation/verification.md,
"Loads on structures"). Usage: wall_impact_full.py RUNOUT SCENARIO WORKDIR"""
import json
import statistics
import subprocess
import sys

runout, scenario, work = sys.argv[1:4]
s = json.load(open(scenario))
lab = s["lab"]
lab["nx"], lab["ny"], lab["nz"] = 2 * lab["nx"], 2 * lab["ny"], 2 * lab["nz"]
lab["end_time_s"], lab["write_interval_s"] = 0.3, 0
fine = work + "/wall-impact-2.5mm.json"
json.dump(s, open(fine, "w"))
subprocess.run([runout, "run", fine, "--out", work + "/wall-impact-2.5mm"], check=True)
rec = json.load(open(work + "/wall-impact-2.5mm/run.json"))
mon = rec["monitors"]
load = mon["obstacle_load"]
window = [f for t, f in zip(mon["t_s"], load["force_x_n"]) if 0.2 <= t <= 0.3]
rho, b, h, u = 936.17, 0.1, 0.02, 1.0
expected = rho * b * h * (u * u + 0.5 * 9.81 * h)
plateau = statistics.median(window)
print(f"force on the wall {plateau:.3f} N, expected {expected:.3f} N, ratio {plateau / expected:.3f}")
sys.exit(0 if abs(plateau / expected - 1) <= 0.10 else 1)
