"""How the end rules behave on edges that are not circles (issue 15): the demo blade's and
Rotor 67's CAD cuts at 10/50/90 % span.

    scripts/fcpython bench/bench_airfoil_edge_rules.py

Prints per section: the LE rule that decides by default and with ``le_upstream`` = -engine axis
(the shared data's +X points downstream), the fitted edge radii and their stated 1-sigma, and
the metal angles' spread over the cut's point spacing (0.01, 0.02 mm) and the metal-angle window
(25, 50, 75 % of the camber line; default 50 %).
"""
import os
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import FreeCAD  # noqa: E402,F401
from BladeInspect.cad.airfoil_sections import airfoil_section  # noqa: E402
from BladeInspect.core import airfoil  # noqa: E402
from bench.airfoil_planes import cad_planes, each_blade  # noqa: E402

HEIGHTS_PCT = (10, 50, 90)
SPACINGS = (0.01, 0.02)
WINDOWS = (25.0, 50.0, 75.0)
UPSTREAM = (-1.0, 0.0)


def blade(name, path):
    nominal, span, planes = cad_planes(path, HEIGHTS_PCT)
    print(name)
    for pct, origin in planes:
        cuts = {h: airfoil_section(nominal.shape, origin, span, spacing=h)[0] for h in SPACINGS}
        xy = cuts[0.02]
        default = airfoil.characteristics(xy)
        given = airfoil.characteristics(xy, le_upstream=UPSTREAM)
        s_le = airfoil.edge_radius_sigma(default.le_circle)
        s_te = airfoil.edge_radius_sigma(default.te_circle)
        print("  %2d %%: default LE rule %-31s stagger %8.3f deg | le_upstream -X: %s, "
              "stagger %8.3f deg" % (pct, '"%s"' % default.le_rule, default.stagger_deg,
                                    '"%s"' % given.le_rule, given.stagger_deg))
        print("        edge radii %.4f +- %.4f and %.4f +- %.4f mm (1 sigma incl. form)"
              % (default.le_radius_mm, s_le, default.te_radius_mm, s_te))
        for w in WINDOWS:
            inl, out = [], []
            for h in SPACINGS:
                ch = airfoil.characteristics(cuts[h], le_upstream=UPSTREAM,
                                             metal_angle_window_pct=w)
                inl.append(ch.inlet_angle_deg)
                out.append(ch.outlet_angle_deg)
            print("        window %3.0f %%: inlet %9.4f deg (spread over spacing %.4f), "
                  "outlet %9.4f deg (spread %.4f)" % (w, inl[-1], np.ptp(inl), out[-1],
                                                      np.ptp(out)))


def main():
    each_blade(blade)


if __name__ == "__main__":
    main()
