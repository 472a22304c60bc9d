"""Run inside the throw-away engeom venv by bench/bench_airfoil_engeom.py (not part of
BladeInspect): reads sections as .npy files listed in a JSON job, writes engeom's figures as
JSON. Each section names the direction towards its LE (engeom's ``fwd`` orientation) and its
suction side (``upper``)."""
import json
import sys
import time

import numpy as np
from engeom import airfoil2 as af
from engeom.geom2 import Curve2


def xy(p):
    return [float(p.x), float(p.y)]


def analyse(points, edge, fwd, upper):
    curve = Curve2(points, hull_ccw=True, force_closed=True)
    t0 = time.process_time()
    g = af.AfGeometry.from_geometric_analysis(curve, 1e-4, af.OrientFwdAft.fwd(*fwd),
                                              af.OrientUpperLower.upper(*upper), edge, edge)
    mt = g.max_thickness()
    cpu = time.process_time() - t0
    camber = np.asarray(g.camber.points, dtype=float)
    return {"le_point": xy(g.leading.point), "te_point": xy(g.trailing.point),
            "le_radius": g.leading.geometry.radius, "te_radius": g.trailing.geometry.radius,
            "le_kind": g.leading.geometry.kind, "te_kind": g.trailing.geometry.kind,
            "max_thickness": float(mt.value), "camber": camber.tolist(), "cpu_s": cpu}


def main():
    job = json.load(open(sys.argv[1]))
    out = {}
    for name, spec in job.items():
        try:
            out[name] = analyse(np.load(spec["npy"]), spec["edge"], spec["fwd"],
                                spec["upper"])
        except Exception as exc:  # engeom's refusal is a figure of the comparison
            out[name] = {"error": "%s: %s" % (type(exc).__name__, exc)}
    json.dump(out, open(sys.argv[2], "w"))


if __name__ == "__main__":
    main()
