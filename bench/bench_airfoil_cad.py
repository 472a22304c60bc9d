"""Airfoil characteristics of the CAD nominals: the demo blade and Rotor 67, five planes across
the span (10..90 %), cut by cad/airfoil_sections.py and measured by core.airfoil.

    PYTHONPATH=.:/usr/lib/freecad-python3/lib /usr/bin/python3 bench/bench_airfoil_cad.py

Prints each section's characteristics, the kernel's area and centroid against OCC's polygon
face of the same loop, any warnings, and the CPU time of cutting and of the characteristics.
"""
import os
import sys
import time

# The kernel's least-squares problems are tiny: BLAS threads would only spin, and their spinning
# counts as this process's CPU time (it doubled the figure on two cores).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import FreeCAD  # noqa: E402,F401  (before Part)
import Part  # noqa: E402

from BladeInspect.cad.airfoil_sections import airfoil_section  # noqa: E402
from BladeInspect.core import airfoil  # noqa: E402
from bench.airfoil_planes import cad_planes, each_blade  # noqa: E402

HEIGHTS_PCT = (10, 30, 50, 70, 90)


def blade(name, path):
    nominal, span, planes = cad_planes(path, HEIGHTS_PCT)
    print("%s: span axis %s, engine axis +X" % (name, np.round(span, 4).tolist()))
    cut_cpu = kernel_cpu = 0.0
    for pct, origin in planes:
        t0 = time.process_time()
        xy, frame = airfoil_section(nominal.shape, origin, span)
        cut_cpu += time.process_time() - t0
        if pct == HEIGHTS_PCT[0]:
            airfoil.characteristics(xy)      # first-call set-up, not timed
        t1 = time.process_time()
        ch = airfoil.characteristics(xy)
        t2 = time.process_time()
        kernel_cpu += t2 - t1
        loop = frame.to_3d(xy)
        face = Part.Face(Part.makePolygon([FreeCAD.Vector(*p) for p in
                                           np.vstack([loop, loop[:1]])]))
        com = frame.to_2d(np.array(face.CenterOfMass))[0]
        print("  %2d %%: %5d pts; chord %.4f (caliper %.4f, tangent %s) axial %.4f mm; "
              "stagger %.3f, inlet %.3f, outlet %.3f deg; max t %.4f mm at %.1f %%; "
              "r LE %.4f, r TE %.4f mm; area %.4f mm^2 (OCC %+.2e), centroid vs OCC %.3f um"
              % (pct, len(xy), ch.chord_mm, ch.caliper_chord_mm,
                 "%.4f" % ch.tangent_chord_mm if ch.tangent_chord_mm else "none",
                 ch.axial_chord_mm, ch.stagger_deg, ch.inlet_angle_deg, ch.outlet_angle_deg,
                 ch.max_thickness_mm, ch.max_thickness_pos_pct, ch.le_radius_mm,
                 ch.te_radius_mm, ch.area_mm2, ch.area_mm2 - face.Area,
                 1000 * np.linalg.norm(com - ch.centroid_mm)))
        for w in ch.warnings:
            print("        warning: %s" % w)
    print("  CPU: cutting five sections %.2f s, their characteristics %.2f s"
          % (cut_cpu, kernel_cpu))


def main():
    each_blade(blade)


if __name__ == "__main__":
    main()
