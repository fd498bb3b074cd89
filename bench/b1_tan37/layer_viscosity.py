#!/usr/bin/python3
"""The Coulomb viscosity in B1's flowing layer against upwind's numerical viscosity |u| dx / 2.
usage: layer_viscosity.py RUN_DIR T0 T1  (runout fields.h5; cells with alpha > 0.5 moving faster than
10 % of the frame's fastest sand cell, within 3 cm of the box centre)"""
import math, sys
import h5py, numpy as np
f = h5py.File(sys.argv[1] + "/fields.h5", "r")
t0, t1 = float(sys.argv[2]), float(sys.argv[3])
r_nu, r_num, ratios = [], [], []
for name in f:
    g = f[name]
    t = float(g.attrs["t"])
    if not t0 <= t <= t1:
        continue
    a, ux, uy, nu = (np.asarray(g[k], dtype=float) for k in ("alpha", "ux", "uy", "nu"))
    ny, nx = a.shape
    dx = 0.2 / nx
    yc, xc = np.mgrid[0:ny, 0:nx]
    xc, yc = (xc + 0.5) * dx, (yc + 0.5) * dx
    sp = np.hypot(ux, uy)
    sand = a > 0.5
    um = sp[sand].max()
    sel = sand & (sp > 0.1 * um) & (np.hypot(xc - 0.1, yc - 0.1) < 0.03)
    if sel.sum() == 0:
        continue
    num = 0.25 * (np.abs(ux) + np.abs(uy)) * dx  # upwind: |u_x| dx/2 along x, |u_y| dy/2 along y; their mean
    r_nu.append(np.median(nu[sel])); r_num.append(np.median(num[sel])); ratios.append(np.median(num[sel] / nu[sel]))
print("%s: frames %d, Coulomb nu in the layer (median) %.3g m2/s, upwind (|u_x| + |u_y|) dx / 4 %.3g m2/s, ratio of the two %.2f"
      % (sys.argv[1], len(r_nu), np.mean(r_nu), np.mean(r_num), np.mean(r_num) / np.mean(r_nu)))
