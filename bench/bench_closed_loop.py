"""Figures for closing the loop (docs/contracts.md): rotary-axis calibration against injected truth,
CAD-planned sections measured by the simulated rig, and (when the inspect workflow is
available) the whole loop.

Run: scripts/fcpython bench/bench_closed_loop.py [--trials N] [--skip-plan] [--inspect-seeds N]"""

import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))


def calibration_figures(trials):
    from BladeInspect.core import transforms as tf
    from BladeInspect.measurement import calibration as cal
    from BladeInspect.rig.kinematics import RigKinematics
    from BladeInspect.rig.simulated import SimulatedRig
    print("== calibration: injected axis offset 0.2 mm, tilt 0.1 deg, random directions")
    print("   sphere D=25 mm at %s (table), %d angles, %dx%d raster per cap"
          % (cal.DEFAULT_SPHERE_POSITION, len(cal.DEFAULT_ANGLES), cal.RASTER_LINES,
             cal.RASTER_LINES))
    point_err, dir_err, wall = [], [], []
    before, after = [], []
    for seed in range(trials):
        rng = np.random.default_rng(1000 + seed)
        lean, shift = rng.uniform(0, 2 * np.pi, 2)
        tilt = np.radians(0.1)
        direction = np.array([np.sin(tilt) * np.cos(lean), np.cos(tilt),
                              np.sin(tilt) * np.sin(lean)])
        point = 0.2 * np.array([np.cos(shift), 0.0, np.sin(shift)])
        truth = RigKinematics(axis_point=point, axis_direction=direction)
        mount = np.asarray(cal.DEFAULT_SPHERE_POSITION) + rng.uniform(-2, 2, 3)
        rig = SimulatedRig(cal.SpherePart(12.5), tf.make_transform(np.eye(3), -mount),
                           kinematics=truth, seed=seed)
        t0 = time.perf_counter()
        res = cal.calibrate(rig, 25.0)
        wall.append(time.perf_counter() - t0)
        point_err.append(np.linalg.norm(np.subtract(res["axis_point"], point)) * 1000.0)
        dir_err.append(np.degrees(np.arccos(min(1.0, float(np.dot(res["axis_direction"],
                                                                  direction))))))
        if seed < 3:
            angles = (0.0, 60.0, 120.0, 180.0, 240.0, 300.0)
            before.append(cal.sphere_residual(rig, RigKinematics(), angles=angles)["rms_mm"])
            after.append(cal.sphere_residual(rig, res["kinematics"], angles=angles)["rms_mm"])
    print("   axis point error: max %.3f um, mean %.3f um (limit 2 um)"
          % (max(point_err), np.mean(point_err)))
    print("   axis direction error: max %.5f deg, mean %.5f deg (limit 0.001 deg)"
          % (max(dir_err), np.mean(dir_err)))
    print("   wall time per calibration %.2f s, simulated rig time %.0f s"
          % (np.mean(wall), res["simulated_s"]))
    print("   multi-angle sphere residual RMS: nominal axis %s um -> calibrated %s um"
          % (", ".join("%.1f" % (b * 1000) for b in before),
             ", ".join("%.2f" % (a * 1000) for a in after)))


def planning_figures(seeds):
    from BladeInspect.cad.demo_blade import make_demo_blade
    from BladeInspect.cad.nominal import nominal_from_shape
    from BladeInspect.measurement import planning
    from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose
    print("== planning: demo blade at random fixture poses, sections 10/30/50/70/90 %")
    model = make_demo_blade()
    nominal = nominal_from_shape(model.shape, roles=model.roles)
    for seed in seeds:
        pose = random_fixture_pose(np.random.default_rng(seed))
        rig = SimulatedRig(nominal, pose, seed=seed)
        t0 = time.perf_counter()
        plan = planning.plan_sections(nominal, pose, (10, 30, 50, 70, 90), rig.sensor,
                                      rig.limits)
        t_plan = time.perf_counter() - t0
        plane_err, standoff_err, n_missing = 0.0, 0.0, 0
        t0 = time.perf_counter()
        for path in plan.paths:
            sec = plan.sections[path.section]
            stage = plan.path_stage_xyz(path)
            r = rig.scan_path(stage, path.angle_deg)
            ok = np.isfinite(r.reading_mm)
            n_missing += int(np.count_nonzero(~ok))
            standoff_err = max(standoff_err,
                               float(np.max(np.abs(r.reading_mm[ok] - rig.sensor.standoff))))
            spot = stage[ok] - np.outer(r.reading_mm[ok], [0, 0, 1])
            from BladeInspect.core import transforms as tf
            cad = tf.apply_transform(rig.cad_from_machine(path.angle_deg), spot)
            plane_err = max(plane_err, float(np.max(np.abs((cad - sec.plane_point)
                                                           @ sec.plane_normal))))
        t_scan = time.perf_counter() - t0
        print("   seed %d: %d points, %d paths, angles/section %s, plan %.1f s, scan %.1f s "
              "wall (%.0f s rig time); max |plane dist| %.4f mm, max |d - standoff| %.4f mm, "
              "missing readings %d"
              % (seed, plan.n_points, len(plan.paths), plan.info["angles_per_section"], t_plan,
                 t_scan, rig.elapsed_s, plane_err, standoff_err, n_missing))


def inspect_figures(seeds):
    import tempfile
    from BladeInspect.core import transforms as tf
    from BladeInspect.inspection.closed_loop import run_inspect
    from BladeInspect.inspection.run_options import RunOptions
    from BladeInspect.inspection.pipeline import load_nominal
    from BladeInspect.rig.simulated import SimulatedRig, make_bump, random_fixture_pose
    print("== inspect loop: demo blade, random fixture pose, 30 um bump, sections 10..90 %")
    nominal = load_nominal(None)
    centre = nominal.samples.xyz[np.argmin(np.linalg.norm(
        nominal.samples.xyz - [0.0, 5.0, 35.0], axis=1))]
    for seed in seeds:
        truth = random_fixture_pose(np.random.default_rng(seed))
        rig = SimulatedRig(nominal, truth, error_field=make_bump(centre, 6.0, 0.03), seed=seed)
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            out = run_inspect(None, os.path.join(tmp, "out"), RunOptions.of(seed=seed), rig=rig,
                              nominal=nominal, document=False)
            wall = time.perf_counter() - t0
        res = out["result"]
        err = tf.corner_displacement(res.measured_to_cad, truth, nominal.bbox_corners)
        planned = res.columns["phase"] == "planned"
        # Planned points as measured (table frame) put into the CAD by the simulator's truth.
        cad_true = tf.apply_transform(truth, tf.apply_transform(
            tf.invert_transform(res.measured_to_cad), res.points_cad[planned]))
        dists = np.min([np.abs((cad_true - s.plane_point) @ s.plane_normal)
                        for s in out["plan"].sections], axis=0)
        print("   seed %d: pose error %.2f um, bound %.2f um (ratio %.2f); bound after blind "
              "%.2f um; planned points %d, max |plane dist| by truth %.4f mm; re-plans %d; "
              "wall %.1f s"
              % (seed, err * 1e3, res.pose_uncertainty_mm * 1e3,
                 err / res.pose_uncertainty_mm, out["uncertainty_after_blind_mm"] * 1e3,
                 int(planned.sum()), dists.max(), len(out["replans"]) - 1, wall))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--skip-plan", action="store_true")
    parser.add_argument("--inspect-seeds", type=int, default=3)
    args = parser.parse_args()
    calibration_figures(args.trials)
    if not args.skip_plan:
        planning_figures((21, 22, 23))
    inspect_figures(range(41, 41 + args.inspect_seeds))


if __name__ == "__main__":
    main()
