"""Edge radii and chord of a perfect part measured through the CAD-planned sections (issue 15
item 7): bias (measured - nominal) and 1 sigma over several simulated scans, per section, on the
demo blade and NASA Rotor 67, with the planner's edge-density rule off and on.

Each scan: the sections planned from the CAD at the part's TRUE pose on the simulated rig
(measurement.planning.plan_sections), every planned path read by the rig (exact rays, the
sensor model's noise, incidence-dependent SNR and missing readings), the readings mapped into
the CAD by the true pose -- or, with --loop, the whole `inspect` loop (blind scan,
registration, plan, scan, ICP) -- then Table 2's section assignment and the airfoil stage
(inspection.airfoil_stage.run_stage), as `inspect --airfoil` runs it. Also printed per edge: planned
points in the +-45 deg edge zone, how many of them returned a reading, and their incidence.

    scripts/fcpython bench/bench_airfoil_loop_edges.py [--scans 5] [--blades demo,rotor67]
        [--edge-sigma off,0.002] [--spacing 0.1] [--accuracy 0.006] [--loop]
"""
import argparse
import os
import shutil
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from BladeInspect.inspection import airfoil_stage as stage_mod  # noqa: E402
from BladeInspect.inspection import sections as sections_mod  # noqa: E402
from BladeInspect.measurement.planning import plan_sections  # noqa: E402
from BladeInspect.rig.sensor import SensorModel  # noqa: E402
from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose_of  # noqa: E402
from tests.helpers import planned_readings_result  # noqa: E402

HEIGHTS = (10.0, 50.0, 90.0)
ROTOR67 = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "..",
                       "shared", "data", "blades", "nasa_rotor67")
KEYS = ("le_radius_mm", "te_radius_mm", "chord_mm")


def load(blade):
    from BladeInspect.cad.load import load_nominal
    if blade == "demo":
        return load_nominal(None)
    from tests.test_rotor67_loop import rotor67_nominal
    return rotor67_nominal()


def truth_pose(nominal, seed):
    axis, _ = sections_mod.span_axis_of(nominal)
    return random_fixture_pose_of(nominal, np.random.default_rng(seed), axis)


def loop_result(nominal, rig, heights, edge_sigma, seed):
    from BladeInspect.inspection.closed_loop import run_inspect
    from BladeInspect.inspection.run_options import RunOptions
    tmp = tempfile.mkdtemp(prefix="bi-edges-")
    try:
        summary = run_inspect(None, tmp + "/out",
                              RunOptions.of(section_heights=heights, seed=seed,
                                            edge_radius_sigma_mm=edge_sigma), rig=rig,
                              nominal=nominal, document=False)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return summary["result"], summary["plan"], summary["sections"]


def edge_zone_counts(plan, nominal, stage):
    """Per section and edge: planned points in the nominal's +-45 deg edge zone, the share of
    them read, and their largest incidence (deg)."""
    out = []
    for sec, sr in zip(plan.sections, stage.sections):
        row = {}
        for name, circle in (("LE", sr.nominal.le_circle), ("TE", sr.nominal.te_circle)):
            xy = sr.frame.to_2d(sec.target_cad)
            v = xy - circle.center
            r = np.linalg.norm(v, axis=1)
            near = np.abs(r - circle.radius) < 0.5 * circle.radius
            edge_pt = (sr.nominal.le_point if name == "LE" else sr.nominal.te_point)
            outward = edge_pt - circle.center
            cosang = (v @ outward) / (r * np.linalg.norm(outward) + 1e-300)
            zone = near & (cosang >= np.cos(np.radians(circle.zone_deg)))
            row[name] = (int(zone.sum()), sec.incidence_deg[zone].max() if zone.any() else 0)
        out.append(row)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scans", type=int, default=5)
    ap.add_argument("--blades", default="demo,rotor67")
    ap.add_argument("--edge-sigma", default="off,0.002")
    ap.add_argument("--spacing", type=float, default=0.1)
    ap.add_argument("--accuracy", type=float, default=0.006)
    ap.add_argument("--heights", default=",".join("%g" % h for h in HEIGHTS))
    ap.add_argument("--loop", action="store_true", help="the whole inspect loop per scan")
    ap.add_argument("--seed", type=int, default=41)
    args = ap.parse_args()
    heights = [float(h) for h in args.heights.split(",")]
    opts = stage_mod.Options(draws=0)
    for blade in args.blades.split(","):
        nominal = load(blade)
        truth = truth_pose(nominal, args.seed)
        for es in args.edge_sigma.split(","):
            edge_sigma = None if es == "off" else float(es)
            values, counts, read, t0 = {}, None, [], time.perf_counter()
            for k in range(args.scans):
                sensor = SensorModel(accuracy=args.accuracy) if args.accuracy > 0 else \
                    SensorModel(accuracy=1e-9, resolution=1e-9)
                rig = SimulatedRig(nominal, truth, sensor=sensor, seed=args.seed * 100 + k)
                if args.loop:
                    result, plan, table = loop_result(nominal, rig, heights, edge_sigma, k)
                    stage = stage_mod.run_stage(nominal, stage_mod.planes_of_table(table),
                                                opts, result, table.span_axis)
                else:
                    plan = plan_sections(nominal, truth, heights, rig.sensor, rig.limits,
                                         span_axis=sections_mod.span_axis_of(nominal)[0],
                                         spacing=args.spacing, kinematics=rig.kinematics,
                                         edge_radius_sigma_mm=edge_sigma)
                    result, _ = planned_readings_result(nominal, rig, plan)
                    table = sections_mod.section_table(result, nominal, heights_pct=heights)
                    stage = stage_mod.run_stage(nominal, stage_mod.planes_of_table(table),
                                                opts, result, table.span_axis)
                read.append((len(result.points_cad), plan.n_points))
                if counts is None:
                    counts = edge_zone_counts(plan, nominal, stage)
                for b in stage.blocks:
                    for key in KEYS:
                        m = (b["measured"] or {}).get(key)
                        values.setdefault((b["label"], key), []).append(
                            np.nan if m is None else m - b["nominal"][key])
                    values.setdefault((b["label"], "notes"), []).append(
                        len(b.get("withheld") or {}))
            wall = time.perf_counter() - t0
            print("\n%s, edge rule %s, spacing %g mm, sensor accuracy %g mm (sigma_ref %.2f "
                  "um), %s, %d scans, %.0f s; planned %d points, read %d"
                  % (blade, es, args.spacing, args.accuracy, 1e3 * sensor.sigma_ref,
                     "whole loop" if args.loop else "true pose", args.scans, wall,
                     read[0][1], read[0][0]))
            info = plan.info.get("edge_density")
            if info:
                print("edge rule: n = %d points per +-%g deg zone (x %.2f), noise %.2f um, "
                      "sigma_R %.1f um" % (info["points_per_zone"], info["zone_deg"],
                                           info["margin"], 1e3 * info["noise_mm"],
                                           1e3 * info["radius_sigma_mm"]))
                for sec, edges in zip(plan.sections, info["sections"]):
                    print("  %g %%: %s" % (sec.height_pct, "; ".join(
                        "%s r %.3f mm spacing %.2f um" % (e["edge"], e["radius_mm"],
                                                          1e3 * e["spacing_mm"])
                        for e in edges)))
            print("%-6s %-14s %10s %10s %10s  %s" % ("sect", "char", "bias um", "1sd um",
                                                    "max|d| um", "nominal / zone pts, inc"))
            for b, c in zip(stage.blocks, counts):
                for key in KEYS:
                    d = 1e3 * np.asarray(values[(b["label"], key)])
                    zone = c["LE"] if key.startswith("le") else c["TE"] if \
                        key.startswith("te") else None
                    print("%-6s %-14s %10.2f %10.2f %10.2f  %.4f mm%s"
                          % (b["label"], key, np.mean(d), np.std(d, ddof=1) if len(d) > 1
                             else np.nan, np.max(np.abs(d)), b["nominal"][key],
                             "" if zone is None else " / %d pts, <= %.0f deg" % zone))
                print("%-6s values withheld at a sparse edge in %d of %d scans"
                      % (b["label"], int(np.sum(np.asarray(values[(b["label"], "notes")]) > 0)),
                         args.scans))


if __name__ == "__main__":
    main()
