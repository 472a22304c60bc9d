"""Figures for the complete scan (docs/contracts.md loop 3; paper 4.3) on the demo blade at a random
fixture pose: points, the simulated scan's wall time against the real sensor's acquisition
time at its rate (must be >= 10x faster), the real rig's estimated time, and the whole
`inspect --complete` wall time (must be < 60 s on two cores).

Run: scripts/fcpython bench/bench_complete.py [--pitch 0.1] [--seed 0] [--skip-inspect]"""

import argparse
import os
import shutil
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pitch", type=float, default=0.1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--skip-inspect", action="store_true")
    args = ap.parse_args()
    from BladeInspect.cad.demo_blade import make_demo_blade
    from BladeInspect.cad.nominal import nominal_from_shape
    from BladeInspect.core import transforms as tf
    from BladeInspect.measurement.complete import plan_complete, scan_complete
    from BladeInspect.rig.simulated import simulated_rig_for

    t0 = time.perf_counter()
    model = make_demo_blade()
    nominal = nominal_from_shape(model.shape, roles=model.roles)
    print("demo blade loaded in %.1f s" % (time.perf_counter() - t0))

    rig = simulated_rig_for(nominal, seed=args.seed)
    t0 = time.perf_counter()
    plan = plan_complete(nominal, rig.table_to_cad, rig.sensor, rig.limits, pitch=args.pitch)
    t_plan = time.perf_counter() - t0
    t0 = time.perf_counter()
    xyz, _, _, _, _, reading, _ = scan_complete(rig, plan)
    t_scan = time.perf_counter() - t0
    sensor_s = len(xyz) / rig.sensor.rate_hz
    dist = nominal.signed_distance(tf.apply_transform(rig.table_to_cad, xyz)).distance
    print("== complete scan at the true pose, pitch %g mm, spacing %g mm"
          % (plan.pitch_mm, plan.spacing_mm))
    print("   %d lines, angles %s, %d planned points, %d read, %d passes"
          % (len(plan.line_y), plan.angles_deg.tolist(), plan.n_points, len(xyz),
             len(plan.passes)))
    print("   plan %.2f s wall (%d rays cast)" % (t_plan, plan.info["rays_cast"]))
    print("   scan %.2f s wall; the sensor alone at %g points/s needs %.1f s: %.1fx faster"
          % (t_scan, rig.sensor.rate_hz, sensor_s, sensor_s / t_scan))
    print("   plan + scan %.2f s wall: %.1fx faster than the sensor"
          % (t_plan + t_scan, sensor_s / (t_plan + t_scan)))
    print("   real rig's estimated time (motion at feed and acquisition) %.0f s = %.1f min"
          % (rig.elapsed_s, rig.elapsed_s / 60.0))
    print("   truth: |CAD distance| max %.4f mm, RMS %.4f mm; |reading - standoff| max %.4f mm"
          % (np.abs(dist).max(), np.sqrt(np.mean(dist ** 2)),
             np.abs(reading - plan.standoff_mm).max()))

    if args.skip_inspect:
        return
    from BladeInspect.inspection.closed_loop import run_inspect
    from BladeInspect.inspection.run_options import RunOptions
    rig = simulated_rig_for(nominal, seed=args.seed)
    out = tempfile.mkdtemp(prefix="bench-complete-")
    try:
        t0 = time.perf_counter()
        summary = run_inspect(None, os.path.join(out, "run"),
                              RunOptions.of(complete=True, pitch=args.pitch, seed=args.seed),
                              rig=rig, nominal=nominal)
        wall = time.perf_counter() - t0
        timing = summary["result"].timing_s
        truth_err = np.abs(np.asarray(summary["result"].measured_to_cad)
                           - rig.table_to_cad).max()
        print("== inspect --complete end to end (nominal already loaded): %.1f s wall "
              "(limit 60 s)" % wall)
        print("   stages: %s" % ", ".join("%s %.1f" % kv for kv in timing.items()))
        print("   %d points; pose uncertainty after blind %.4f mm, after complete %.5f mm; "
              "max |pose matrix - truth| %.2e" % (len(summary["result"].points_cad),
                                                  summary["uncertainty_after_blind_mm"],
                                                  summary["pose_uncertainty_mm"], truth_err))
    finally:
        shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    main()
