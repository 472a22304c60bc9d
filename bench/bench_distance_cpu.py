"""CPU seconds on one thread of what `register` spends most of its time in, per blade of
bench_register_stages.py (demo, Rotor 67, the third-party STEP): loading the CAD
(pipeline.load_nominal), one cold exact distance of the paper's 269,158 points at the true pose
(core.closest's chunks on this thread) and one warm one after a 1 um move. The best of a few
runs: on a shared machine the wall time measures the neighbours, one thread's CPU time less so.

    scripts/fcpython bench/bench_distance_cpu.py [--repeat 2]

Run it from two checkouts back to back to compare revisions.
"""
import argparse
import os
import shutil
import sys
import tempfile
import time

import numpy as np

from BladeInspect.core import closest
from BladeInspect.core import transforms as tf
from BladeInspect.inspection import pipeline
from BladeInspect.inspection.simulate import simulate_measurement

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_register_stages as stages   # noqa: E402  (its blades)
from profile_full_cloud_distance import OnThisThread   # noqa: E402

# The warm evaluation's move (mm), as the fine fit's last steps.
WARM_MOVE_MM = np.array([1e-3, -5e-4, 2e-4])


def best_cpu(fn, repeat):
    times = []
    for _ in range(repeat):
        cpu = time.process_time()
        fn()
        times.append(time.process_time() - cpu)
    return min(times)


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--points", type=int, default=stages.PAPER_POINTS)
    args = ap.parse_args(argv)
    print("load average %.2f %.2f %.2f on %d cores" % (os.getloadavg() + (os.cpu_count(),)))
    tmp = tempfile.mkdtemp(prefix="bench-cpu-")
    try:
        blades = [("demo blade", None), ("Rotor 67", stages.ROTOR67),
                  ("third-party STEP", stages.write_revolved_cap_step(
                      os.path.join(tmp, "blade.step")))]
        for name, cad in blades:
            if cad is not None and not os.path.exists(cad):
                print("%s skipped: %s not found" % (name, cad))
                continue
            nominal = pipeline.load_nominal(cad)
            load = best_cpu(lambda: pipeline.load_nominal(cad), args.repeat + 1)
            ps, truth, _, _ = simulate_measurement(nominal, n_points=args.points,
                                                   section_heights=(), outlier_fraction=0.02,
                                                   seed=14)
            points = tf.apply_transform(truth, ps.xyz)
            pool, closest.ThreadPoolExecutor = closest.ThreadPoolExecutor, OnThisThread
            try:
                last = {}
                cold = best_cpu(lambda: last.update(r=nominal.signed_distance(points)),
                                args.repeat)
                start = closest.FootStart.of(points, last["r"])
                warm = best_cpu(lambda: nominal.signed_distance(points + WARM_MOVE_MM, start),
                                args.repeat)
            finally:
                closest.ThreadPoolExecutor = pool
            print("%-17s CPU s on one thread: load_nominal %.3f, cold distance %.3f, warm "
                  "distance %.3f (%d points, %d to OCC cold)"
                  % (name, load, cold, warm, len(points), int(last["r"].fallback.sum())),
                  flush=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
