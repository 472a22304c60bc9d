"""Benchmark of the `report` command on a full-blade cloud (paper 4.3: 269,158 points).

Builds a cloud on the demo blade: sections every 0.1 mm of span, uniform error +-0.006 mm,
two defects (a +0.08 mm bump on the suction side, a -0.06 mm dent near the leading edge),
moved to a random pose; then times run_report (register, section table, verdict, report.html,
report.pdf, inspection.FCStd, result.json, deviations.csv) and prints the stage times.

    scripts/fcpython bench/bench_report.py [N] [OUT]
Target: the whole report under 30 s on two cores.
"""
import json
import os
import shutil
import sys
import tempfile
import time

import numpy as np

from BladeInspect.cad.demo_blade import BladeParams, section_points
from BladeInspect.core import transforms as tf
from BladeInspect.inspection.pipeline import load_nominal
from BladeInspect.inspection.report import run_report

N_POINTS = 269158


def blade_cloud(nominal, n_points, rng):
    params = BladeParams()
    levels = np.arange(0.05, params.span, 0.1)
    per_side = int(np.ceil(n_points / (2 * len(levels)))) + 4
    dense = BladeParams(n_profile=per_side)
    pts = []
    for z in levels:
        up, lo, _ = section_points(dense, z / params.span)
        pts.append(np.vstack([up[2:-2], lo[2:-2]]))
    pts = np.vstack(pts)
    pts = pts[np.sort(rng.choice(len(pts), n_points, replace=False))]
    base = nominal.signed_distance(pts)
    on = base.closest
    dev = rng.uniform(-0.006, 0.006, len(on))
    suction = np.isin(base.face, nominal.roles["suction"])
    centre = on[suction][np.argmin(np.linalg.norm(on[suction] - [5.0, 3.0, 40.0], axis=1))]
    dev += 0.08 * np.exp(-np.sum((on - centre) ** 2, axis=1) / 2.0 ** 2)
    dent = on[np.argmin(np.linalg.norm(on - [-18.0, 0.0, 20.0], axis=1))]
    dev += -0.06 * np.exp(-np.sum((on - dent) ** 2, axis=1) / 1.0 ** 2)
    return on + dev[:, None] * base.normal


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else N_POINTS
    out_root = sys.argv[2] if len(sys.argv) > 2 else tempfile.mkdtemp(prefix="bench_report_")
    rng = np.random.default_rng(2024)
    t0 = time.perf_counter()
    nominal = load_nominal(None)
    cloud = blade_cloud(nominal, n, rng)
    measured = tf.apply_transform(tf.random_transform(rng, 50.0), cloud)
    points = os.path.join(out_root, "blade.csv")
    np.savetxt(points, measured, delimiter=",", header="x,y,z", comments="", fmt="%.6f")
    print("cloud of %d points made in %.1f s" % (n, time.perf_counter() - t0))

    out = os.path.join(out_root, "report")
    shutil.rmtree(out, ignore_errors=True)
    t0 = time.perf_counter()
    cpu0 = time.process_time()
    summary = run_report(None, points, out)
    wall = time.perf_counter() - t0
    cpu = time.process_time() - cpu0
    with open(os.path.join(out, "result.json")) as fh:
        doc = json.load(fh)
    print("run_report: %.1f s wall, %.1f s CPU (target < 30 s)" % (wall, cpu))
    for stage, seconds in doc["timing_s"].items():
        print("  %-14s %6.2f s" % (stage, seconds))
    print("rms %.4f mm, pose uncertainty %.2f um, verdict: %s"
          % (doc["rms_mm"], 1000 * doc["pose_uncertainty_mm"], doc["verdict"]["summary"]))
    for name in sorted(os.listdir(out)):
        print("  %-18s %8.1f kB" % (name, os.path.getsize(os.path.join(out, name)) / 1024))
    print("pdf pages: %d; output in %s" % (summary["pdf_pages"], out))


if __name__ == "__main__":
    main()
