"""Blind section scans on the simulated rig, registered back through the pipeline and judged
against the rig's own fixture pose (issue 4: within 3x the pose's Cramér-Rao bound).

    scripts/fcpython bench/bench_scan_register.py \
        [--cad CAD] [--seeds 0,1] [--sections 5]
"""
import argparse
import json
import shutil
import sys
import tempfile
import time

import numpy as np

from BladeInspect.cad.load import load_nominal
from BladeInspect.core import transforms as tf
from BladeInspect.inspection.pipeline import load_points, register
from BladeInspect.measurement.scan import open_rig, scan_to_dir


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cad", default=None)
    ap.add_argument("--seeds", default="0,1")
    ap.add_argument("--sections", type=int, default=5)
    args = ap.parse_args()
    nominal = load_nominal(args.cad)
    for seed in [int(s) for s in args.seeds.split(",")]:
        tmp = tempfile.mkdtemp(prefix="bi-scan-reg-")
        try:
            rig = open_rig("sim", nominal, seed)
            angles = set()
            scan_path = rig.scan_path

            def counting(path, angle_deg, scan_path=scan_path, angles=angles):
                angles.add(round(float(angle_deg), 9))
                return scan_path(path, angle_deg)
            rig.scan_path = counting
            t0 = time.perf_counter()
            scan_to_dir(tmp + "/scan", rig, n_sections=args.sections, seed=seed)
            t_scan = time.perf_counter() - t0
            points = load_points(tmp + "/scan/points.csv")
            with open(tmp + "/scan/scan.json") as fh:
                record = json.load(fh)
            truth = np.array(record["table_to_cad"])
            t0 = time.perf_counter()
            result = register(nominal, points, seed=seed)
            t_reg = time.perf_counter() - t0
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        err = tf.corner_displacement(result.measured_to_cad, truth, nominal.bbox_corners)
        print("seed %d: %d points, %d passes (%d in the views, %d probing the span and "
              "levelling), %d rotary angles; scan %.0f s (real rig ~%.0f s), register %.1f s; "
              "pose error %.2f um = %.2fx its bound %.2f um; residual RMS %.4f mm"
              % (seed, len(points.xyz), rig.pass_index, record["passes"],
                 rig.pass_index - record["passes"], len(angles), t_scan,
                 record.get("real_time_s", float("nan")), t_reg, 1e3 * err,
                 err / result.pose_uncertainty_mm, 1e3 * result.pose_uncertainty_mm,
                 result.rms_mm), flush=True)


if __name__ == "__main__":
    sys.exit(main())
