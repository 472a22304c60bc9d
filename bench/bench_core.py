"""Figures for the numerical core (no FreeCAD): ICP at the statistical limit on an analytic
surface, its convergence basin, its own cost, the point reader's speed, the statistics' speed.

    scripts/fcpython bench/bench_core.py [--trials 200] [--points 2000]

The surface is the triaxial ellipsoid patch of tests/test_icp.py with exact closest points, so
every figure is about the numerics alone (the CAD distance is measured elsewhere).
"""
import argparse
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from BladeInspect.core import icp, pointio, stats  # noqa: E402
from BladeInspect.core import transforms as tf  # noqa: E402
from tests.test_icp import (CORNERS, ellipsoid_closest, measured_cloud, pose_error,  # noqa: E402
                            start_near)


def statistical_limit(n_trials, n_points):
    """Pose error against the pose's own bound, with 2 % gross outliers at low SNR."""
    rng = np.random.default_rng(100)
    ratios, scatter, predicted, rms_excess, flagged, iters, times = [], [], [], [], 0, [], []
    for _ in range(n_trials):
        noise = rng.uniform(-0.006, 0.006, n_points)
        snr = rng.uniform(60.0, 95.0, n_points)
        gross = rng.choice(n_points, n_points // 50, replace=False)
        noise_good = noise.copy()
        noise[gross] = rng.choice([-1.0, 1.0], len(gross)) * rng.uniform(0.1, 0.5, len(gross))
        snr[gross] = rng.uniform(2.0, 10.0, len(gross))
        pts, truth, _, _ = measured_cloud(rng, n_points, noise)
        t0 = time.perf_counter()
        res = icp.icp(pts, snr, ellipsoid_closest, start_near(rng, truth))
        times.append(time.perf_counter() - t0)
        bound = icp.pose_uncertainty(res.covariance, res.center, CORNERS)
        ratios.append(pose_error(res.transform, truth) / bound)
        delta = res.transform @ tf.invert_transform(truth)
        scatter.append(tf.apply_transform(delta, CORNERS) - CORNERS)
        predicted.append(bound)
        good = np.setdiff1d(np.arange(n_points), gross)
        rms_excess.append(np.sqrt(np.mean(res.distances[good] ** 2))
                          - np.sqrt(np.mean(noise_good[good] ** 2)))
        flagged += np.count_nonzero(~res.inlier[gross])
        iters.append(res.iterations)
    ratios = np.array(ratios)
    worst_rms = np.max(np.sqrt(np.mean(np.sum(np.array(scatter) ** 2, axis=2), axis=0)))
    print("ICP, %d trials x %d points, uniform +-6 um, 2 %% outliers 0.1-0.5 mm at SNR 2-10, "
          "start 3 deg / 2 mm off:" % (n_trials, n_points))
    print("  pose error / own bound: median %.2f, 95 %% %.2f, max %.2f; within 3x: %d of %d"
          % (np.median(ratios), np.quantile(ratios, 0.95), ratios.max(),
             np.count_nonzero(ratios < 3), n_trials))
    print("  worst-corner RMS scatter %.3f um vs mean predicted 1 sigma %.3f um (ratio %.2f)"
          % (worst_rms * 1e3, np.mean(predicted) * 1e3, worst_rms / np.mean(predicted)))
    print("  residual RMS of good points minus injected noise RMS: mean %+.4f um, max |.| "
          "%.4f um" % (np.mean(rms_excess) * 1e3, np.max(np.abs(rms_excess)) * 1e3))
    print("  gross outliers flagged: %d of %d; iterations median %d, max %d; %.1f ms per fit"
          % (flagged, n_trials * (n_points // 50), np.median(iters), max(iters),
             1e3 * np.median(times)))


def basin(n_points=1000, trials=20):
    rng = np.random.default_rng(200)
    print("Convergence from a start off by a rotation (and 5 mm), %d points, noise +-6 um:"
          % n_points)
    for angle in (5.0, 10.0, 20.0, 30.0, 45.0, 60.0):
        ok = 0
        for _ in range(trials):
            pts, truth, _, _ = measured_cloud(rng, n_points, rng.uniform(-0.006, 0.006,
                                                                         n_points))
            res = icp.icp(pts, None, ellipsoid_closest, start_near(rng, truth, angle, 5.0))
            bound = icp.pose_uncertainty(res.covariance, res.center, CORNERS)
            ok += pose_error(res.transform, truth) < 3 * bound
        print("  %4.0f deg: %d of %d reach 3x their bound" % (angle, ok, trials))


def cost(n_points=269158):
    rng = np.random.default_rng(300)
    pts, truth, _, _ = measured_cloud(rng, n_points, rng.uniform(-0.006, 0.006, n_points))
    spent = []

    def timed_closest(p):
        t0 = time.perf_counter()
        out = ellipsoid_closest(p)
        spent.append(time.perf_counter() - t0)
        return out
    t0 = time.perf_counter()
    res = icp.icp(pts, rng.uniform(50, 100, n_points), timed_closest,
                  start_near(rng, truth, 0.01, 0.01), icp.ICPOptions(horn_iters=0))
    total = time.perf_counter() - t0
    print("ICP on %d points from 0.01 deg / 0.01 mm off: %d closest-point calls, %.2f s in "
          "ICP itself (%.3f s per iteration), %.2f s in closest points"
          % (n_points, len(spent), total - sum(spent), (total - sum(spent)) / len(spent),
             sum(spent)))
    t0 = time.perf_counter()
    stats.deviation_statistics(res.distances)
    print("deviation_statistics of %d values: %.3f s" % (n_points, time.perf_counter() - t0))


def reader(n_rows=300000):
    rng = np.random.default_rng(400)
    xyz = rng.normal(size=(n_rows, 3)) * 30
    folder = tempfile.mkdtemp(prefix="bench-pointio-")
    csv_full = os.path.join(folder, "full.csv")
    csv_xyz = os.path.join(folder, "xyz.csv")
    txt = os.path.join(folder, "points.xyz")
    snr = rng.uniform(0, 100, n_rows)
    pointio.write_points_csv(csv_xyz, xyz, {"snr": snr})
    t0 = time.perf_counter()
    pointio.write_points_csv(csv_full, xyz, {
        "snr": snr, "section": rng.integers(0, 5, n_rows),
        "angle_deg": rng.uniform(0, 360, n_rows),
        "phase": np.where(rng.uniform(size=n_rows) < 0.5, "blind", "planned")})
    t_write = time.perf_counter() - t0
    np.savetxt(txt, np.c_[xyz, snr], fmt="%.6f")
    for label, path in (("csv x,y,z,snr", csv_xyz),
                        ("csv x,y,z,snr,section,angle_deg,phase", csv_full),
                        ("xyz x y z snr", txt)):
        best = min(_timed(pointio.read_points, path) for _ in range(3))
        print("read_points %d rows, %s: %.2f s (best of 3)" % (n_rows, label, best))
    print("write_points_csv %d rows, 7 columns: %.2f s" % (n_rows, t_write))
    for name in os.listdir(folder):
        os.remove(os.path.join(folder, name))
    os.rmdir(folder)


def _timed(fn, *args):
    t0 = time.perf_counter()
    fn(*args)
    return time.perf_counter() - t0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=200)
    parser.add_argument("--points", type=int, default=2000)
    args = parser.parse_args()
    print("load average at start: %.2f" % os.getloadavg()[0])
    reader()
    cost()
    statistical_limit(args.trials, args.points)
    basin()


if __name__ == "__main__":
    main()
