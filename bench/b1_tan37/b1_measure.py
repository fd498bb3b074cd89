#!/usr/bin/python3
"""B1 (rotating box, 50 x 50 cells of 4 mm, gravity turning in the box frame): the same measures on
a runout run (fields.h5) and on an OpenFOAM interRotGFoam case (time directories).

usage: b1_measure.py runout RUN_DIR [--from T0] [--to T1]
       b1_measure.py openfoam CASE_DIR [--from T0] [--to T1]

Per written frame: the surface angle as runout's monitor measures it (alpha = 0.5 crossings within
5 cm of the box centre, principal axis, folded to 0-90 deg against the plane normal to gravity), the
top-surface fit (topmost alpha = 0.5 point on each vertical line within 5 cm of the centre), the
flowing layer's thickness at the centre (deepest sand cell within 2 cm of the centre line moving
faster than 10 % of that line's maximum and 5 mm/s), the mean speed of the top 1 cm and of the bulk
(> 2 cm deep), and the pressure in the top 3 cm against the hydrostatic rho g cos(theta) depth
(least-squares slope of p - p_air over depth, p_air the mean over cells with alpha < 0.01, divided
by rho g cos(theta)). The summary averages from the onset (first frame at 90 % of the peak angle)
plus T/16 (runout's monitor and tools/b1_post.py) or over [--from, --to].

Needs h5py and numpy for runout's fields.h5 (Debian: python3-h5py); the OpenFOAM reader is the
reference's own (tools/b1_post.py, found through B1_POST_DIR, default /work/of-ref/tools)."""
import math, os, sys

sys.path.insert(0, os.environ.get("B1_POST_DIR", "/work/of-ref/tools"))
import b1_post as P  # noqa: E402

T, OM, NX, NY, D, O = P.T, P.OM, P.NX, P.NY, P.D, P.O
RHO, G = 1855.0, 9.81


def set_grid(nx, ny):
    """the reference's helpers work on module-level NX, NY, D (0.2 m box)"""
    global NX, NY, D
    NX, NY, D = nx, ny, 0.2 / nx
    P.NX, P.NY, P.D = NX, NY, D


def frames_runout(run):
    import h5py
    import numpy as np
    f = h5py.File(os.path.join(run, "fields.h5"), "r")
    # layout: one group per frame with its time as attribute, or datasets with a leading time axis
    out = []

    def grab(g):
        return {k: np.asarray(g[k]).reshape(-1) for k in ("alpha", "ux", "uy", "p") if k in g}

    names = list(f.keys())
    times = None
    if "time" in f:
        times = list(np.asarray(f["time"]).reshape(-1))
    for k, name in enumerate(names):
        g = f[name]
        if not isinstance(g, h5py.Group) or "alpha" not in g:
            continue
        t = g.attrs.get("t", g.attrs.get("time"))
        if t is None:
            t = times[len(out)] if times is not None else float(name.split("_")[-1])
        d = grab(g)
        ny, nx = g["alpha"].shape[-2:]
        set_grid(nx, ny)
        out.append((float(np.asarray(t).reshape(-1)[0]), d))
    out.sort(key=lambda x: x[0])
    for t, d in out:
        yield t, list(map(float, d["alpha"])), [(float(a), float(b)) for a, b in zip(d["ux"], d["uy"])], list(map(float, d["p"]))


def frames_openfoam(case):
    import re
    cells = int(re.search(r"cells:\s+(\d+)", open(os.path.join(case, "log.checkMesh")).read()).group(1))
    n = int(round(math.sqrt(cells)))
    set_grid(n, n)
    for t, name in P.times(case):
        if t == 0:
            continue
        a = P.read_internal(os.path.join(case, name, "alpha.granular"))
        U = P.read_internal(os.path.join(case, name, "U"))
        p = P.read_internal(os.path.join(case, name, "p"))
        yield t, a, [(u[0], u[1]) for u in U], p


def measure(t, alpha, U, p):
    th = -OM * t  # box-frame cells rotated by -a into the lab frame (gravity down)
    C0 = P.centres(t, box=True)
    c0, s0 = math.cos(th), math.sin(th)
    C = [(O[0] + c0 * (x - O[0]) - s0 * (y - O[1]), O[1] + s0 * (x - O[0]) + c0 * (y - O[1])) for x, y in C0]
    pts = P.crossings(alpha, C)
    dirn, n = P.axis_angle(pts)
    ang = math.degrees(P.fold(dirn)) if n >= 3 else float("nan")
    atop, _ = P.top_surface_angle(alpha, th)
    urel = [math.hypot(*u) for u in U]
    sand = [k for k in range(NX * NY) if alpha[k] > 0.5]
    res = dict(t=t, rot=math.degrees(OM * t), angle=ang, top=atop, thick=float("nan"), layer_u=float("nan"),
               bulk_u=float("nan"), p_ratio=float("nan"), p_base=float("nan"), vol=sum(alpha) * D * D)
    if n < 3:
        return res
    mx = sum(q[0] for q in pts) / n
    my = sum(q[1] for q in pts) / n
    nx, ny = -math.sin(dirn), math.cos(dirn)
    sgn = sum((alpha[k] - 0.5) * ((C[k][0] - mx) * nx + (C[k][1] - my) * ny) for k in range(NX * NY))
    if sgn > 0:
        nx, ny = -nx, -ny
    depth = lambda k: -((C[k][0] - mx) * nx + (C[k][1] - my) * ny)
    along = lambda k: abs((C[k][0] - mx) * ny - (C[k][1] - my) * nx)
    bulk = [urel[k] for k in sand if depth(k) > 0.02]
    layer = [urel[k] for k in sand if depth(k) < 0.01 and along(k) < 0.05]
    res["bulk_u"] = sum(bulk) / max(1, len(bulk))
    res["layer_u"] = sum(layer) / max(1, len(layer))
    col = [(depth(k), urel[k]) for k in sand if along(k) < 0.02 and depth(k) > -0.004]
    if col:
        um = max(u for _, u in col)
        fl = [d for d, u in col if u > 0.1 * um and u > 0.005]
        res["thick"] = (max(fl) + 0.5 * D) if fl else 0.0
    air = [p[k] for k in range(NX * NY) if alpha[k] < 0.01]
    pa = sum(air) / max(1, len(air))
    # pressure against depth in the top 3 cm near the centre line (sand cells): slope through the origin
    pr = [(depth(k), p[k] - pa) for k in sand if along(k) < 0.03 and 0.002 < depth(k) < 0.03]
    if pr:
        sxx = sum(d * d for d, _ in pr)
        sxp = sum(d * q for d, q in pr)
        cos_t = math.cos(math.radians(ang))
        res["p_ratio"] = sxp / sxx / (RHO * G * cos_t)
    if res["thick"] == res["thick"] and res["thick"] > 0:
        base = [p[k] - pa for k in sand if along(k) < 0.02 and abs(depth(k) - res["thick"]) < 0.5 * D + 1e-9]
        if base:
            res["p_base"] = sum(base) / len(base) / (RHO * G * math.cos(math.radians(ang)) * res["thick"])
    return res


def stats(rows, key):
    v = [r[key] for r in rows if r[key] == r[key]]
    if not v:
        return float("nan"), float("nan"), 0
    m = sum(v) / len(v)
    return m, math.sqrt(max(0.0, sum(x * x for x in v) / len(v) - m * m)), len(v)


def main():
    kind, path = sys.argv[1], sys.argv[2]
    t0 = float(sys.argv[sys.argv.index("--from") + 1]) if "--from" in sys.argv else None
    t1 = float(sys.argv[sys.argv.index("--to") + 1]) if "--to" in sys.argv else 1e9
    src = frames_runout(path) if kind == "runout" else frames_openfoam(path)
    rows = [measure(*fr) for fr in src]
    csv = os.path.join(path, "b1_measure.csv") if os.access(path, os.W_OK) else "/dev/null"
    keys = list(rows[0].keys())
    with open(csv, "w") as f:
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join("%.6g" % r[k] for k in keys) + "\n")
    peak = max(r["angle"] for r in rows if r["angle"] == r["angle"])
    onset = next(r["t"] for r in rows if r["angle"] == r["angle"] and r["angle"] >= 0.9 * peak)
    start = onset + T / 16 if t0 is None else t0
    use = [r for r in rows if start <= r["t"] <= t1]
    # failure: the last frame at which the surface is within 2 deg of the rigid turn
    fail = next((r["rot"] for r in rows if r["angle"] == r["angle"] and abs(r["angle"] - r["rot"]) > 2 and r["rot"] < 90), float("nan"))
    print("%s: frames %d, peak %.1f deg, onset %.3f s, failure (2 deg behind the rigid turn) at %.1f deg rotation, window %.3f-%.3f s (n = %d)"
          % (path, len(rows), peak, onset, fail, start, min(t1, rows[-1]["t"]), len(use)))
    for key, label in [("angle", "angle (crossings)"), ("top", "angle (top fit)"), ("thick", "layer thickness [m]"),
                       ("layer_u", "top 1 cm speed [m/s]"), ("bulk_u", "bulk speed [m/s]"),
                       ("p_ratio", "p slope / rho g cos"), ("p_base", "p at layer base / hydrostatic")]:
        m, s, k = stats(use, key)
        print("  %-30s %9.4g +- %.3g" % (label, m, s))


if __name__ == "__main__":
    main()
