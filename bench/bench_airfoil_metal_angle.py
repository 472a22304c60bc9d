"""Metal angles on noisy points (issue 15): the bias and 1 sigma of the inlet and outlet metal
angles over the window of the camber line the end tangent is fitted to (core.airfoil's
metal_angle_window_pct), on the double-circular-arc section whose camber line is an exact
ellipse (tests/airfoil_shapes.py), at sigma = 2 um normal noise and 0.02 mm spacing.

    /usr/bin/python3 bench/bench_airfoil_metal_angle.py [--scans 20] [--windows 50,75,90,100]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from BladeInspect.core import airfoil  # noqa: E402
from tests.airfoil_shapes import ArcSection  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scans", type=int, default=20)
    ap.add_argument("--windows", default="50,75,90,100")
    args = ap.parse_args()
    sec = ArcSection(x_le=-24.0, x_te=27.0)
    pts = sec.points(0.02)
    prof = airfoil.Profile(pts)
    normal = prof.outward_normal(prof.point_params)
    rng = np.random.default_rng(11)
    scans = [pts + rng.normal(0.0, 0.002, len(pts))[:, None] * normal for _ in range(args.scans)]
    print("double circular arc, sigma 2 um, %d scans: metal angle error (mdeg) against the "
          "exact nominal's at the same window: bias / 1 sigma / max" % args.scans)
    for w in [float(x) for x in args.windows.split(",")]:
        truth = airfoil.characteristics(prof, metal_angle_window_pct=w)
        err = {"inlet": [], "outlet": []}
        for p in scans:
            c = airfoil.characteristics(p, noise_mm=0.002, metal_angle_window_pct=w)
            err["inlet"].append(c.inlet_angle_deg - truth.inlet_angle_deg)
            err["outlet"].append(c.outlet_angle_deg - truth.outlet_angle_deg)
        cells = ["%s %+6.2f / %5.2f / %5.2f" % (k, 1e3 * np.mean(v), 1e3 * np.std(v, ddof=1),
                                                 1e3 * np.max(np.abs(v)))
                 for k, v in err.items()]
        print("  window %5.1f %%: nominal inlet %.4f outlet %.4f deg; %s"
              % (w, truth.inlet_angle_deg, truth.outlet_angle_deg, "; ".join(cells)))


if __name__ == "__main__":
    main()
