"""Fit objectives (core.fits): agreement with independent solutions and time per fit.

    scripts/fcpython bench/bench_fits.py [--points 20000] [--trials 2] [--no-demo]

1. A triaxial ellipsoid patch (blade-sized axes, exact closest points by Newton) with a 30 um
   bump and 2 um noise, every point judged: least squares with DOFs locked from a perturbed
   start; then from the least-squares pose least squares, minimax, tolerance (+-T between the
   two optima, and a zone too tight to fit) and minimax with DOFs locked. Minimax against the
   iterated full linear programme of tests/test_fits.py (every point, HiGHS interior point).
2. The demo blade (exact OCC-backed distance): the paper's simulated scan (uniform +-6 um,
   2 % gross outliers), registered by the pipeline's ICP from near the truth; the fits on
   its inliers and weights, all sharing one closest-point evaluation at the ICP pose.
"""
import argparse
import time

import numpy as np

from BladeInspect.core import fits
from BladeInspect.core import transforms as tf
from tests.test_fits import bumped_ellipsoid, iterated_lp_minimax
from tests.test_icp import ellipsoid_closest

UM = 1e-3


def timed(fn, *args, **kwargs):
    t0 = time.perf_counter()
    out = fn(*args, **kwargs)
    return out, time.perf_counter() - t0


def report(name, result, seconds, extra=""):
    print("  %-26s %6.3f s  %3d evals  max|d| %8.3f um  rms %7.3f um  %s%s"
          % (name, seconds, result.iterations, result.max_abs_deviation / UM, result.rms / UM,
             "converged" if result.converged else "NOT CONVERGED", extra))


def run_fits(points, closest, init, weights, independent=True):
    """Every fit from ``init`` (a least-squares pose), sharing one evaluation there."""
    (_, normals, distances), t = timed(closest, tf.apply_transform(init, points))
    print("  closest points at the start %6.3f s (shared by the fits below: at_init)" % t)
    known = (distances, normals)
    ls, t = timed(fits.least_squares_fit, points, closest, init, weights, at_init=known)
    report("least squares", ls, t)
    mm, t = timed(fits.minimax_fit, points, closest, init, weights, at_init=known)
    report("minimax", mm, t)
    if independent:
        start = tf.apply_transform(init, points[ls.inlier])
        best, t_ind = timed(iterated_lp_minimax, start, closest, mm.center)
        print("  independent iterated LP   %6.3f s  max|d| %8.3f um  |difference| %.2e um"
              % (t_ind, best / UM, abs(best - mm.max_abs_deviation) / UM))
    tol = 0.5 * (mm.max_abs_deviation + ls.max_abs_deviation)
    for label, T in (("passes", tol), ("cannot fit", 0.5 * mm.max_abs_deviation)):
        fit, t = timed(fits.tolerance_fit, points, closest, init, weights, -T, T,
                       at_init=known)
        report("tolerance +-%.1f um" % (T / UM), fit, t,
               "  fits %s margin %+.3f um (%s)" % (fit.fits, fit.margin / UM, label))
    for text in ("tx,ty,rz", "rz"):
        fit, t = timed(fits.minimax_fit, points, closest, init, weights,
                       free=fits.parse_free(text), at_init=known)
        report("minimax free %s" % text, fit, t)


def locked_least_squares(points, closest, init, weights):
    """Least squares with DOFs locked from a start off the optimum."""
    for text in ("rx,ry,rz", "rz", "tx,ty,tz"):
        fit, t = timed(fits.least_squares_fit, points, closest, init, weights,
                       free=fits.parse_free(text))
        report("least squares free %s" % text, fit, t)


def synthetic(n_points, trials):
    print("ellipsoid patch, %d points, 30 um bump, 2 um noise" % n_points)
    for k in range(trials):
        rng = np.random.default_rng(100 + k)
        measured, truth = bumped_ellipsoid(rng, n_points, 0.03, 0.002)
        init = tf.make_transform(tf.rotation_from_vector(rng.normal(0, 1e-3, 3)),
                                 rng.normal(0, 0.05, 3)) @ truth
        w = np.ones(len(measured))
        print(" trial %d, from a start 50 um / 1 mrad off" % k)
        locked_least_squares(measured, ellipsoid_closest, init, w)
        ls = fits.least_squares_fit(measured, ellipsoid_closest, init, w)
        print(" from the least-squares pose")
        run_fits(measured, ellipsoid_closest, ls.transform, w)


def demo(n_points, trials):
    from BladeInspect.inspection import pipeline
    from BladeInspect.inspection.closest_fn import exact_closest_fn
    from BladeInspect.inspection.simulate import simulate_measurement
    nominal = pipeline.load_nominal(None)
    closest = exact_closest_fn(nominal)
    print("demo blade, simulated scan of %d points (+-6 um uniform, 2 %% outliers), ICP "
          "inliers and weights" % n_points)
    for k in range(trials):
        ps, truth, _ = simulate_measurement(nominal, n_points=n_points, outlier_fraction=0.02,
                                            seed=200 + k)[:3]
        rng = np.random.default_rng(300 + k)
        start = tf.make_transform(tf.rotation_from_vector(rng.normal(0, 1e-3, 3)),
                                  rng.normal(0, 0.05, 3)) @ truth
        icp_fit, t = timed(pipeline.fine_register, ps.xyz, ps.snr, nominal, start)
        print(" trial %d: ICP %.2f s, %d of %d inliers" % (k, t, icp_fit.inlier.sum(),
                                                           len(ps.xyz)))
        run_fits(ps.xyz, closest, icp_fit.transform, icp_fit.weights)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--points", type=int, default=20000)
    parser.add_argument("--trials", type=int, default=2)
    parser.add_argument("--no-demo", action="store_true")
    args = parser.parse_args()
    synthetic(args.points, args.trials)
    if not args.no_demo:
        demo(args.points, args.trials)


if __name__ == "__main__":
    main()
