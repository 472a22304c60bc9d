"""Metal angles on noisy points (issue 15's 0.005 deg): per section and end, the estimator's
bias and 1 sigma (measured - nominal over repeated scans) beside the Cramer-Rao lower bound
of that angle for the same points (core/metal_angle_bound.py: the nominal + a per-side
Legendre deviation field of degree 2 and 4, the kernel's rule as the estimand), and what
point count, spacing or noise the bound says would reach 0.005 deg.

1. The double-circular-arc section (camber line an exact ellipse, tests/airfoil_shapes.py), at
   sigma = 2 um normal noise, 0.02 mm and 0.1 mm spacing, over metal_angle_window_pct; with the
   closed-form bound of the definition's own model (each side a quartic in x over the window,
   tests/test_airfoil_metal_angle_bound.py) beside the module's.
2. The demo blade and NASA Rotor 67, the CAD-planned sections (measurement.planning, the
   rig's sensor model and the default edge-density rule, as bench_airfoil_loop_edges.py and
   `inspect` plan them) read at the part's true pose; the stage (inspection.airfoil_stage) measures.

    scripts/fcpython bench/bench_airfoil_metal_angle.py [--scans 20] [--windows 50,90]
        [--blades demo,rotor67] [--degrees 2,4] [--no-dca] [--no-planned]
"""
import argparse
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
sys.path.insert(0, HERE)              # bench_airfoil_loop_edges
from BladeInspect.core import airfoil, metal_angle_bound  # noqa: E402
from tests.airfoil_shapes import ArcSection  # noqa: E402

KEYS = (("inlet", "inlet_angle_deg"), ("outlet", "outlet_angle_deg"))


def row(label, end, errs, nominal, bounds, extra=""):
    e = 1e3 * np.asarray(errs)
    read = np.isfinite(e)
    if not read.all():
        extra += "; measured in %d of %d scans" % (read.sum(), len(e))
    e = e[read]
    cells = " ".join("%6.2f" % (1e3 * b[end]["crb_deg"]) for b in bounds)
    need = bounds[-1][end]
    print("  %-10s %-6s %9.4f %7.2f %7.2f %7.2f  %s  %6d %7.1f um %5.2f um%s"
          % (label, end, nominal, e.mean() if len(e) else np.nan,
             e.std(ddof=1) if len(e) > 1 else np.nan, np.abs(e).max() if len(e) else np.nan,
             cells, need["n_points"], 1e3 * need["spacing_for_target_mm"],
             1e3 * need["sigma_for_target_mm"], extra))


def header(degrees):
    print("  %-10s %-6s %9s %7s %7s %7s  %s  %6s %10s %8s"
          % ("section", "end", "nominal", "bias", "1sd", "max|e|",
             " ".join("CRB q%d" % d for d in degrees), "n pts", "h for 5md", "s for 5md"))
    print("  (angles in deg, errors and bounds in mdeg; n pts: points informing the last "
          "degree's bound; h/s for 5md: spacing / noise at which that bound is 0.005 deg)")


def dca(args, degrees):
    from tests.test_airfoil_metal_angle_bound import closed_form_crb
    sec = ArcSection(x_le=-24.0, x_te=27.0)
    rng = np.random.default_rng(11)
    for spacing in (0.02, 0.1):
        pts = sec.points(spacing)
        prof = airfoil.Profile(pts)
        normal = prof.outward_normal(prof.point_params)
        scans = [pts + rng.normal(0.0, args.sigma, len(pts))[:, None] * normal
                 for _ in range(args.scans)]
        for w in args.windows:
            truth = airfoil.characteristics(prof, metal_angle_window_pct=w)
            print("\ndouble circular arc, spacing %g mm, sigma %g um, window %g %%, %d scans "
                  "(bias against the exact nominal's angle at the same window; the exact "
                  "tangent: inlet %.4f outlet %.4f deg)"
                  % (spacing, 1e3 * args.sigma, w, args.scans, angle_of(sec.inlet_dir()),
                     angle_of(sec.outlet_dir())))
            header(degrees)
            errs = {k: [] for k, _ in KEYS}
            for p in scans:
                c = airfoil.characteristics(p, noise_mm=args.sigma, metal_angle_window_pct=w)
                for end, key in KEYS:
                    errs[end].append(getattr(c, key) - getattr(truth, key))
            bounds = [metal_angle_bound.metal_angle_bound(pts, truth, pts, args.sigma, d,
                                                          window_pct=w) for d in degrees]
            for end, key in KEYS:
                cf = closed_form_crb(sec, spacing, args.sigma, w, end=end)
                row("DCA", end, errs[end], getattr(truth, key), bounds,
                    "; closed-form q4 %.2f" % (1e3 * cf))


def angle_of(v):
    return float(np.degrees(np.arctan2(v[1], v[0])))


def planned(args, degrees):
    from bench_airfoil_loop_edges import load, truth_pose
    from BladeInspect.inspection import airfoil_stage as stage_mod
    from BladeInspect.inspection import sections as sections_mod
    from BladeInspect.measurement.planning import DEFAULT_EDGE_RADIUS_SIGMA_MM, plan_sections
    from BladeInspect.rig.simulated import SimulatedRig
    from tests.helpers import planned_readings_result
    opts = stage_mod.Options(draws=0)
    for blade in args.blades:
        nominal = load(blade)
        truth = truth_pose(nominal, args.seed)
        values, first, t0 = {}, None, time.perf_counter()
        for k in range(args.scans):
            rig = SimulatedRig(nominal, truth, seed=args.seed * 100 + k)
            plan = plan_sections(nominal, truth, args.heights, rig.sensor, rig.limits,
                                 span_axis=sections_mod.span_axis_of(nominal)[0],
                                 spacing=args.spacing, kinematics=rig.kinematics,
                                 edge_radius_sigma_mm=DEFAULT_EDGE_RADIUS_SIGMA_MM)
            result, _ = planned_readings_result(nominal, rig, plan)
            table = sections_mod.section_table(result, nominal, heights_pct=args.heights)
            stage = stage_mod.run_stage(nominal, stage_mod.planes_of_table(table), opts,
                                        result, table.span_axis)
            if first is None:
                first = stage
            for b in stage.blocks:
                for _, key in KEYS:
                    m = (b["measured"] or {}).get(key)
                    values.setdefault((b["label"], key), []).append(
                        np.nan if m is None else m - b["nominal"][key])
        print("\n%s, planned sections (spacing %g mm, edge rule %g um), true pose, %d scans, "
              "%.0f s" % (blade, args.spacing, 1e3 * DEFAULT_EDGE_RADIUS_SIGMA_MM, args.scans,
                          time.perf_counter() - t0))
        header(degrees)
        for b, sr in zip(first.blocks, first.sections):
            if sr.measured is None:
                print("  %-10s not measured: %s" % (b["label"], "; ".join(sr.notes)))
                continue
            nom = sr.nominal
            bounds = [metal_angle_bound.metal_angle_bound(
                nom.profile.points, nom, sr.points_2d, sr.noise_mm, d, le_hint=nom.le_point)
                for d in degrees]
            for end, key in KEYS:
                row(b["label"], end, values[(b["label"], key)], b["nominal"][key], bounds,
                    "; %d pts, noise %.2f um" % (len(sr.points_2d), 1e3 * sr.noise_mm))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scans", type=int, default=20)
    ap.add_argument("--windows", default="50,90")
    ap.add_argument("--degrees", default="2,4")
    ap.add_argument("--sigma", type=float, default=0.002)
    ap.add_argument("--blades", default="demo,rotor67")
    ap.add_argument("--heights", default="10,50,90")
    ap.add_argument("--spacing", type=float, default=0.1)
    ap.add_argument("--seed", type=int, default=41)
    ap.add_argument("--no-dca", action="store_true")
    ap.add_argument("--no-planned", action="store_true")
    args = ap.parse_args()
    args.windows = [float(x) for x in args.windows.split(",")]
    args.blades = [b for b in args.blades.split(",") if b]
    args.heights = [float(h) for h in args.heights.split(",")]
    degrees = [int(d) for d in args.degrees.split(",")]
    if not args.no_dca:
        dca(args, degrees)
    if not args.no_planned:
        planned(args, degrees)


if __name__ == "__main__":
    main()
