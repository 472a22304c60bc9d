"""Where one exact signed distance of the paper's 269,158 points goes, on one thread: a cold
evaluation (no warm start, as the first full-cloud step of the fine ICP for all but its
subsample) and a warm one after a 1 um move (as its second step), profiled by cProfile in
core.closest's real chunks (its two-thread pool replaced by a loop on this thread, so that the
profile sees the work).

    scripts/fcpython bench/profile_full_cloud_distance.py [demo|rotor67|step] [--top 25]

The blades are bench_register_stages.py's. Prints each evaluation's CPU seconds and the
points OpenCASCADE decided, then the functions by their own time.
"""
import argparse
import cProfile
import os
import pstats
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


class OnThisThread:
    """Stands in for ThreadPoolExecutor: map on the calling thread."""

    def __init__(self, max_workers=None):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def map(self, fn, items):
        return list(map(fn, items))


def profiled(label, fn, top):
    profile = cProfile.Profile()
    cpu = time.process_time()
    profile.enable()
    result = fn()
    profile.disable()
    print("%s: %.2f s CPU (profiled), %d points decided by OCC"
          % (label, time.process_time() - cpu, int(np.count_nonzero(result.fallback))))
    pstats.Stats(profile).sort_stats("tottime").print_stats(top)
    return result


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("blade", nargs="?", default="step", choices=("demo", "rotor67", "step"))
    ap.add_argument("--points", type=int, default=stages.PAPER_POINTS)
    ap.add_argument("--top", type=int, default=25)
    args = ap.parse_args(argv)
    tmp = tempfile.mkdtemp(prefix="bench-profile-")
    try:
        cad = {"demo": None, "rotor67": stages.ROTOR67}.get(args.blade)
        if args.blade == "step":
            cad = stages.write_revolved_cap_step(os.path.join(tmp, "blade.step"))
        nominal = pipeline.load_nominal(cad)
        ps, truth, _, _ = simulate_measurement(nominal, n_points=args.points, section_heights=(),
                                               outlier_fraction=0.02, seed=14)
        points = tf.apply_transform(truth, ps.xyz)
        closest.ThreadPoolExecutor = OnThisThread
        cold = profiled("cold", lambda: nominal.signed_distance(points), args.top)
        start = closest.FootStart.of(points, cold)
        moved = points + np.array([1e-3, -5e-4, 2e-4])
        profiled("warm after 1 um", lambda: nominal.signed_distance(moved, start), args.top)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
