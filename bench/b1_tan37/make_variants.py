#!/usr/bin/python3
"""Writes the B1 tan-37 variants (scenarios/lab/b1-rotating-box.json with lab.phi_deg 37, frames
every 0.05 s, to 3 s) as scen/NAME.json, one option changed per file."""
import json, os, sys
here = os.path.dirname(os.path.abspath(__file__))
base = json.load(open(os.path.join(here, "../../scenarios/lab/b1-rotating-box.json")))
base["lab"].update(phi_deg=37, write_interval_s=0.05, end_time_s=3.0)
variants = {
    "base": {},
    "transpose_explicit": {"viscous_transpose": "explicit"},
    "transpose_off": {"viscous_transpose": "off"},
    "conv_limited_linear": {"momentum_convection": "limited_linear"},
    "p_excess": {"coulomb_pressure": "excess"},
    "wall_cell": {"wall_viscosity": "cell"},
    "consistent": {"pressure_coupling": "consistent"},
    "correctors9": {"correctors": 9},
    "outer3": {"outer_correctors": 3},
    "courant005": {"max_courant": 0.05},
    "fine2mm": {"nx": 100, "ny": 100},
    "fine2mm_limited_linear": {"nx": 100, "ny": 100, "momentum_convection": "limited_linear"},
    "coarse8mm": {"nx": 25, "ny": 25},
    "coarse8mm_limited_linear": {"nx": 25, "ny": 25, "momentum_convection": "limited_linear"},
    "ll_transpose_off": {"momentum_convection": "limited_linear", "viscous_transpose": "off"},
    "ll_p_excess": {"momentum_convection": "limited_linear", "coulomb_pressure": "excess"},
}
os.makedirs(os.path.join(here, "scen"), exist_ok=True)
for name, ch in variants.items():
    s = json.loads(json.dumps(base))
    s["name"] = "B1 tan 37: " + name
    for k, v in ch.items():
        if k == "vof":
            s.setdefault("vof", {}).update(v)
        else:
            s["lab"][k] = v
    json.dump(s, open(os.path.join(here, "scen", name + ".json"), "w"), indent=1)
print(" ".join(variants))
