"""How far the readings of a blind scan lie from the reconstruction built from them, by OCC's
own distance (Part distToShape), not the fit's: every reading to the section curves and to the
lofted surfaces, and each reading's true distance to the blade (the simulator's pose).

scripts/fcpython bench/bench_reconstruct_follow.py [--seeds 2 3 4] [--spacing 1.0]
    [--sections 2] [--keep DIR]
"""
import argparse
import json
import os
import tempfile

import numpy as np

import FreeCAD
import Part

from BladeInspect.cad import loft
from BladeInspect.cad.demo_blade import make_demo_blade
from BladeInspect.core.pointio import PointSet
from BladeInspect.core.transforms import apply_transform
from BladeInspect.measurement.scan import demo_nominal, open_rig, scan_to_dir


def occ_distances(shape, points):
    return np.array([shape.distToShape(Part.Vertex(FreeCAD.Vector(*p)))[0] for p in points])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, nargs="+", default=[2, 3, 4])
    ap.add_argument("--spacing", type=float, default=1.0)
    ap.add_argument("--sections", type=int, default=2)
    ap.add_argument("--keep", help="directory for the scans (default: a temporary one)")
    args = ap.parse_args()
    root = args.keep or tempfile.mkdtemp(prefix="bi-recon-bench-")
    nominal, blade = demo_nominal(), make_demo_blade().shape
    for seed in args.seeds:
        out = os.path.join(root, "seed%d-%gmm" % (seed, args.spacing))
        if not os.path.exists(os.path.join(out, "points.csv")):
            rig = open_rig("sim", nominal, seed)
            scan_to_dir(out, rig, n_sections=args.sections, point_spacing=args.spacing)
            rig.close()
        rows = np.loadtxt(os.path.join(out, "points.csv"), delimiter=",", skiprows=1)
        xyz, snr = rows[:, :3], rows[:, 3]
        with open(os.path.join(out, "scan.json")) as fh:
            table_to_cad = np.array(json.load(fh)["table_to_cad"])
        truth = occ_distances(blade, apply_transform(table_to_cad, xyz))
        recon = loft.reconstruct(PointSet(xyz=xyz, snr=snr,
                                          columns={"section": rows[:, 4], "angle_deg": rows[:, 5]}))
        curves = Part.Compound([c.toShape() for c in recon.curves])
        to_curves = occ_distances(curves, xyz)
        n_rejected = sum(e.get("n_rejected", 0) for e in recon.fit_errors)
        print("seed %d, %g mm spacing, %d readings (true |d| to the blade: max %.4f mm; "
              "%d beyond 0.03 mm)" % (seed, args.spacing, len(xyz), truth.max(),
                                      np.count_nonzero(truth > 0.03)))
        print("  readings to curves (OCC): median %.4f  p90 %.4f  max %.4f mm; > 0.02 mm: %d"
              % (np.median(to_curves), np.percentile(to_curves, 90), to_curves.max(),
                 np.count_nonzero(to_curves > 0.02)))
        if recon.surfaces:
            sides = _lofted_sides(recon)
            surfaces = Part.Compound([s.toShape() for s in recon.surfaces])
            in_surface = np.zeros(len(xyz), dtype=bool)
            sec, ang = rows[:, 4], rows[:, 5]
            for g in recon.groups:
                if g["side"] in sides and g["curve"] is not None:
                    in_surface |= (sec == g["section"]) & (np.abs(
                        (ang - g["angle_deg"] + 180) % 360 - 180) < loft.ANGLE_CLUSTER_GAP_DEG)
            to_surfaces = occ_distances(surfaces, xyz[in_surface])
            print("  readings of lofted sides to their surfaces (OCC): %d, median %.4f  "
                  "max %.4f mm" % (in_surface.sum(), np.median(to_surfaces), to_surfaces.max()))
        # The reconstruction against the part itself: points of every curve to the blade.
        on_curves = np.vstack([[tuple(p) for p in c.discretize(200)] for c in recon.curves])
        off_part = occ_distances(blade, apply_transform(table_to_cad, on_curves))
        print("  curve points to the true blade (OCC): p99 %.4f  max %.4f mm"
              % (np.percentile(off_part, 99), off_part.max()))
        # getattr: the same command measures the code before the stated bounds existed.
        sigma_ref = getattr(recon, "sigma_ref", None)
        print("  stated: sigma_ref %s mm; readings left out as gross: %d; largest fit error "
              "%.4f mm; per lofted side, largest gap %s" % (
                  None if sigma_ref is None else "%.4f" % sigma_ref, n_rejected,
                  max(e["max"] for e in recon.fit_errors),
                  [(e["side"], round(e["max_gap_mm"], 4))
                   for e in getattr(recon, "surface_errors", [])]))
        print("  readings within 4 sigma_beam(SNR) of the curves (sigma_ref = the sensor's "
              "3.46 um): %d of %d" % (np.count_nonzero(
                  to_curves <= 4 * SENSOR_SIGMA_REF * np.sqrt(100.0 / snr)), len(xyz)))


SENSOR_SIGMA_REF = 0.006 / np.sqrt(3.0)   # the simulated sensor's uniform +-6 um at SNR 100


def _lofted_sides(recon):
    """The sides that have a surface: those on at least two sections (cad.loft's rule), minus
    any the notes say got none."""
    with_curves = {}
    for g in recon.groups:
        if g["curve"] is not None:
            with_curves.setdefault(g["side"], set()).add(g["section"])
    skipped = {int(n.split()[1].rstrip(":")) for n in recon.notes
               if n.startswith("side ") and "no surface" in n}
    return {side for side, secs in with_curves.items() if len(secs) >= 2} - skipped


if __name__ == "__main__":
    main()
