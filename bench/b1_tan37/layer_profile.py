#!/usr/bin/python3
"""Mean speed against depth below the free surface on the centre line (sand cells within 2 cm of it),
over the frames in [T0, T1]: B1's flowing layer on either code.
usage: layer_profile.py runout|openfoam DIR T0 T1"""
import math, sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import b1_measure as M
kind, path, t0, t1 = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
src = M.frames_runout(path) if kind == "runout" else M.frames_openfoam(path)
bins, nb = {}, {}
for t, alpha, U, p in src:
    if not t0 <= t <= t1:
        continue
    P = M.P
    th = -M.OM * t
    C0 = P.centres(t, box=True)
    c0, s0 = math.cos(th), math.sin(th)
    O = M.O
    C = [(O[0] + c0 * (x - O[0]) - s0 * (y - O[1]), O[1] + s0 * (x - O[0]) + c0 * (y - O[1])) for x, y in C0]
    pts = P.crossings(alpha, C)
    dirn, n = P.axis_angle(pts)
    if n < 3:
        continue
    mx = sum(q[0] for q in pts) / n; my = sum(q[1] for q in pts) / n
    nx, ny = -math.sin(dirn), math.cos(dirn)
    N = M.NX * M.NY
    if sum((alpha[k] - 0.5) * ((C[k][0] - mx) * nx + (C[k][1] - my) * ny) for k in range(N)) > 0:
        nx, ny = -nx, -ny
    for k in range(N):
        if alpha[k] <= 0.5:
            continue
        d = -((C[k][0] - mx) * nx + (C[k][1] - my) * ny)
        a = abs((C[k][0] - mx) * ny - (C[k][1] - my) * nx)
        if a < 0.02 and 0 <= d < 0.05:
            b = int(d / 0.002)
            bins[b] = bins.get(b, 0) + math.hypot(*U[k]); nb[b] = nb.get(b, 0) + 1
print("depth_mm," + path)
for b in sorted(bins):
    print("%d-%d,%.4f" % (2 * b, 2 * b + 2, bins[b] / nb[b]))
