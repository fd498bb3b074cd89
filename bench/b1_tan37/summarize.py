#!/usr/bin/python3
"""One row per B1 tan-37 run: b1_measure.py's figures as a markdown table.
usage: summarize.py [--from T0 --to T1] runout:RUN_DIR[=LABEL] openfoam:CASE_DIR[=LABEL] ..."""
import io, json, os, re, sys, contextlib
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import b1_measure as M

args = sys.argv[1:]
win = []
if "--from" in args:
    i = args.index("--from"); win += args[i:i + 2]; del args[i:i + 2]
if "--to" in args:
    i = args.index("--to"); win += args[i:i + 2]; del args[i:i + 2]
print("| run | peak angle (failure) [deg] | mean +- sd after failure [deg] | top-surface fit [deg] | layer at centre [cm] | top 1 cm speed [m/s] | p at layer base / hydrostatic | steps | wall [s] |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
for a in args:
    kind, rest = a.split(":", 1)
    path, label = (rest.split("=", 1) + [None])[:2]
    label = label or os.path.basename(path.rstrip("/"))
    buf = io.StringIO()
    sys.argv = ["b1_measure.py", kind, path] + win
    with contextlib.redirect_stdout(buf):
        M.main()
    out = buf.getvalue()
    g = lambda key: re.search(re.escape(key) + r"\s+(\S+) \+- (\S+)", out).groups()
    peak = re.search(r"peak (\S+) deg", out).group(1)
    steps = wall = "-"
    if kind == "runout":
        r = json.load(open(os.path.join(path, "run.json")))
        steps = "{:,}".format(r["solver"]["steps"])
        wall = "%.0f" % r["timings_s"]["run"]
    else:
        log = open(os.path.join(path, "log.interFoam")).read()
        steps = "{:,}".format(len(re.findall(r"^Time = ", log, re.M)))
        m = re.findall(r"ClockTime = (\S+) s", log)
        wall = m[-1] if m else "-"
    ang, top, th, lu, pb = g("angle (crossings)"), g("angle (top fit)"), g("layer thickness [m]"), g("top 1 cm speed [m/s]"), g("p at layer base / hydrostatic")
    print("| %s | %.1f | %.1f +- %.1f | %.1f +- %.1f | %.2f | %.2f | %.2f | %s | %s |" % (
        label, float(peak), float(ang[0]), float(ang[1]), float(top[0]), float(top[1]), 100 * float(th[0]), float(lu[0]), float(pb[0]), steps, wall))
