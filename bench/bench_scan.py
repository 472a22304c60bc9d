"""Simulated scan figures: how fast the simulated rig measures compared with the real sensor's
9000 points/s (the rig alone, and with the demo blade's exact ray cast: a raster over the
table, mostly beside the blade, and 100,000 setpoints all on the blade), and the blind section
scan of the demo blade at a random fixture pose: points, passes, simulated and estimated real
time, and how well the points lie on the CAD. Pass times are the better of two runs (other
jobs share the machine).

Run: scripts/fcpython bench/bench_scan.py [--sections 5] [--seed 0]
"""
import argparse
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from BladeInspect.core import transforms as tf  # noqa: E402
from BladeInspect.measurement.calibration import SpherePart  # noqa: E402
from BladeInspect.measurement.complete import plan_complete  # noqa: E402
from BladeInspect.measurement.scan import demo_nominal, open_rig, scan_to_dir  # noqa: E402
from BladeInspect.rig.simulated import SimulatedRig  # noqa: E402

SENSOR_RATE = 9000.0


def raster(n, z):
    per_line = 1000
    lines = n // per_line
    return np.column_stack([np.tile(np.linspace(-30, 30, per_line), lines),
                            np.repeat(np.linspace(30, 90, lines), per_line), np.full(n, z)])


def timed_pass(rig, path, angle=0.0, runs=2):
    best = np.inf
    for _ in range(runs):
        start = time.perf_counter()
        readings = rig.scan_path(path, angle)
        best = min(best, time.perf_counter() - start)
    return best, int(np.count_nonzero(np.isfinite(readings.reading_mm)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sections", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()

    n = 100000
    sphere = SimulatedRig(SpherePart(40.0, center=(0.0, 60.0, 0.0)), np.eye(4), seed=0)
    spent, valid = timed_pass(sphere, raster(n, 84.0))
    print("rig alone (sphere, closed-form ray cast): %d points in %.3f s = %.0f points/s "
          "= %.1f x the sensor (%d readings)" % (n, spent, n / spent, n / spent / SENSOR_RATE,
                                                 valid))

    t0 = time.perf_counter()
    nominal = demo_nominal()
    print("demo blade nominal built in %.1f s" % (time.perf_counter() - t0))
    rig = open_rig("sim", nominal=nominal, seed=args.seed)
    timed_pass(rig, raster(1000, 60.0))            # the first cast tessellates the CAD
    spent, valid = timed_pass(rig, raster(n, 60.0))
    print("demo blade, one pass of %d points: %.2f s = %.0f points/s = %.2f x the sensor "
          "(%d readings)" % (n, spent, n / spent, n / spent / SENSOR_RATE, valid))
    # Every setpoint on the blade: a complete-scan raster at one rotary angle, 0.05 mm pitch.
    plan = plan_complete(nominal, rig.table_to_cad, rig.sensor, rig.limits, pitch=0.05,
                         angles_deg=[0.0])
    on_blade = plan.stage_xyz[:n]
    timed_pass(rig, on_blade[:1000])           # the angle's grid is built once
    spent, valid = timed_pass(rig, on_blade)
    print("demo blade, one pass of %d points all on the blade: %.2f s = %.0f points/s = %.2f x "
          "the sensor (%d readings)" % (len(on_blade), spent, len(on_blade) / spent,
                                        len(on_blade) / spent / SENSOR_RATE, valid))
    small = np.column_stack([np.linspace(-30, 30, 300), np.full(300, 60.0), np.full(300, 60.0)])
    spent, _ = timed_pass(rig, small)
    print("demo blade, one pass of 300 points (a section pass): %.3f s" % spent)

    rig = open_rig("sim", nominal=nominal, seed=args.seed)
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        summary = scan_to_dir(out, rig, n_sections=args.sections, seed=args.seed)
        wall = time.perf_counter() - t0
        rows = np.loadtxt(os.path.join(out, "points.csv"), delimiter=",", skiprows=1)
    print("blind scan of the demo blade, seed %d, %d sections: %d points, %d passes"
          % (args.seed, args.sections, summary["points"], summary["passes"]))
    print("  simulated rig time %.0f s, estimated real time %.0f s (%.1f min); computed in "
          "%.1f s wall = %.0f points/s incl. probes and rescans"
          % (summary["simulated_s"], summary["real_time_s"], summary["real_time_s"] / 60.0,
             wall, summary["points"] / wall))
    for s in summary["sections"]:
        print("  section %d at Y=%.2f: %d points, %d passes, max |d - z_s| %.3f mm, %.0f s"
              % (s["index"], s["y"], s["points"], s["passes"], s["max_standoff_error_mm"],
                 s["simulated_s"]))
    dev = nominal.signed_distance(tf.apply_transform(rig.table_to_cad, rows[:, :3])).distance
    snr = rows[:, 3]
    bound = rig.sensor.accuracy * np.sqrt(rig.sensor.snr_ref / snr)
    print("  points on the CAD: deviation RMS %.4f mm, |max| %.3f mm, %.2f %% beyond the "
          "noise bound (gross errors), median SNR %.0f"
          % (np.sqrt(np.mean(dev ** 2)), np.abs(dev).max(),
             100.0 * np.mean(np.abs(dev) > bound + 1e-6), np.median(snr)))


if __name__ == "__main__":
    main()
