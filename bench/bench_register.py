"""Registration at the statistical limit (issue 3; the criterion as restated in issue 13, item 6).

    scripts/fcpython bench/bench_register.py \
        [--cad CAD] [--trials 200] [--points 20000] [--scatter 30] [--full]

1. Trials of the paper's simulation protocol (both sides, uniform +-6 um, 2 % gross outliers at
   low SNR, rotation anywhere, translation up to 100 mm): pose error against the truth and
   against the pose's own bound; residual RMS against the injected noise RMS. Three verdicts:
   every trial converges (within 10x the bound); the count beyond 3x is what an estimator
   exactly at the bound would leave (binomial test, p > 0.01); the RMS of error/bound is within
   5 % of that estimator's own (above 1: the error is the worst of eight corners'). An
   overstated covariance fails the last (error/bound falls), an understated one the last two.
   Beside them, plain least squares at the truth on each trial's own noise draw: the efficient
   estimator's error for that very draw.
2. The reported covariance against the scatter of the pose over repeated noisy trials at one
   pose (`--scatter N` trials).
3. `--full`: a 269,158-point cloud: the whole registration's time and the exact deviations'
   time, and FreeCAD's Inspection feature on a sample for the ratio.
"""
import argparse
import sys
import time

import numpy as np
from scipy.stats import binomtest

from BladeInspect.core import transforms as tf
from BladeInspect.inspection import pipeline
from BladeInspect.inspection.simulate import pose_error, simulate_measurement

# The accuracy criterion (issue 13, item 6).
CONVERGED_FACTOR = 10.0   # a trial within 10x its bound has converged to the right pose
TAIL_FACTOR = 3.0         # count beyond 3x, compared with an estimator exactly at the bound
TAIL_P_MIN = 0.01         # binomial test of that count
SCALE_TOLERANCE = 0.05    # RMS error/bound within 5 % of that estimator's own


def trials(nominal, n_trials, n_points, seed0=1000):
    """The paper's protocol, judged against an estimator exactly at the bound: for each trial
    the reported covariance C gives, by drawing motions from N(0, C), that estimator's chance of
    leaving 3x the bound and its mean squared error/bound; the run is compared with both."""
    rows = []
    t_start = time.perf_counter()
    for k in range(n_trials):
        seed = seed0 + k
        ps, truth, info, good = simulate_measurement(nominal, n_points=n_points,
                                                     outlier_fraction=0.02, seed=seed)
        t0 = time.perf_counter()
        res = pipeline.register(nominal, ps, seed=seed)
        dt = time.perf_counter() - t0
        err = pose_error(res.measured_to_cad, truth, nominal.bbox_corners)
        rms_good = float(np.sqrt(np.mean(res.deviation[good] ** 2)))
        efficient = efficient_ratios(res.pose_covariance, res.center, nominal.bbox_corners,
                                     res.pose_uncertainty_mm, np.random.default_rng(seed))
        rows.append(dict(seed=seed, error=err, bound=res.pose_uncertainty_mm, rms_good=rms_good,
                         rms_injected=info["noise_rms_injected_mm"], seconds=dt,
                         outliers_kept=int(np.count_nonzero(res.inlier[~good])),
                         efficient=efficient,
                         oracle=oracle_error(nominal, tf.apply_transform(truth, ps.xyz[good]))))
        if (k + 1) % 10 == 0 or k + 1 == n_trials:
            ratio = np.array([r["error"] / r["bound"] for r in rows])
            print("  %3d trials: %d within 3x bound, worst %.2fx, %.0f s"
                  % (k + 1, np.sum(ratio < 3), ratio.max(), time.perf_counter() - t_start),
                  flush=True)
    report_trials(rows)


def report_trials(rows):
    n = len(rows)
    err = np.array([r["error"] for r in rows])
    bound = np.array([r["bound"] for r in rows])
    ratio = err / bound
    print("pose error/bound: median %.2f, max %.2f; %d of %d within 3x"
          % (np.median(ratio), ratio.max(), np.sum(ratio < 3), n))
    for r, q in zip(rows, ratio):
        if q >= TAIL_FACTOR:
            print("  seed %d: error %.3f um, bound %.3f um, %.2fx"
                  % (r["seed"], 1e3 * r["error"], 1e3 * r["bound"], q))
    d = 1e3 * (np.array([r["rms_good"] for r in rows]) - [r["rms_injected"] for r in rows])
    print("residual RMS minus injected noise RMS: mean %+.4f um, worst %+.4f um "
          "(injected RMS %.4f mm)" % (d.mean(), d[np.argmax(np.abs(d))],
                                      np.mean([r["rms_injected"] for r in rows])))
    print("outliers kept as inliers: %d in all trials; registration time median %.2f s"
          % (sum(r["outliers_kept"] for r in rows), np.median([r["seconds"] for r in rows])))

    # 1. Convergence: every trial within CONVERGED_FACTOR x its bound.
    converged = int(np.sum(ratio < CONVERGED_FACTOR))
    print("VERDICT converge: %s - %d of %d trials within %gx the bound"
          % ("PASS" if converged == n else "FAIL", converged, n, CONVERGED_FACTOR))

    # 2. Tail: the count beyond TAIL_FACTOR x against the efficient estimator's expected count.
    eff = np.array([r["efficient"] for r in rows])           # (trials, draws) worst/bound
    p_beyond = np.mean(eff > TAIL_FACTOR, axis=1)
    beyond = int(np.sum(ratio >= TAIL_FACTOR))
    test = binomtest(beyond, n, float(p_beyond.mean()))
    print("VERDICT tail: %s - %d of %d beyond %gx; an estimator at the bound leaves it in "
          "%.2f %% of trials (%.2f expected); binomial test p = %.3f (required > %g)"
          % ("PASS" if test.pvalue > TAIL_P_MIN else "FAIL", beyond, n, TAIL_FACTOR,
             100 * p_beyond.mean(), p_beyond.sum(), test.pvalue, TAIL_P_MIN))

    # 3. Scale: RMS of error/bound against the efficient estimator's own RMS ratio.
    rms_observed = float(np.sqrt(np.mean(ratio ** 2)))
    rms_efficient = float(np.sqrt(np.mean(eff ** 2)))
    # How far an estimator exactly at the bound strays from its own RMS ratio in a run of this
    # many trials (one draw per trial, many runs): the criterion's own chance of failing.
    rng = np.random.default_rng(0)
    runs = eff[np.arange(n)[None, :], rng.integers(0, eff.shape[1], (2000, n))]
    run_rms = np.sqrt(np.mean(runs ** 2, axis=1)) / rms_efficient
    # The same comparison draw by draw: least squares at the truth on each trial's own noise.
    oracle = np.array([r["oracle"] for r in rows]) / bound
    print("least squares on the good points at the truth, same noise draws: RMS error/bound "
          "%.3f, %d of %d beyond %gx; registration/least squares RMS %.3f"
          % (np.sqrt(np.mean(oracle ** 2)), np.sum(oracle >= TAIL_FACTOR), n, TAIL_FACTOR,
             rms_observed / np.sqrt(np.mean(oracle ** 2))))
    print("VERDICT scale: %s - RMS error/bound %.3f against %.3f for an estimator at the bound: "
          "%+.1f %% (required within %.0f %%; a run of %d trials of that estimator strays "
          "%.1f %% RMS and misses the %.0f %% in %.0f %% of runs)"
          % ("PASS" if abs(rms_observed / rms_efficient - 1) <= SCALE_TOLERANCE else "FAIL",
             rms_observed, rms_efficient, 100 * (rms_observed / rms_efficient - 1),
             100 * SCALE_TOLERANCE, n, 100 * np.std(run_rms), 100 * SCALE_TOLERANCE,
             100 * np.mean(np.abs(run_rms - 1) > SCALE_TOLERANCE)))


def oracle_error(nominal, points_cad):
    """Worst-corner error of plain least squares on the good points, linearised at the truth
    (closest points and normals of the truly placed readings): what the efficient estimator
    makes of this trial's own noise draw."""
    true = nominal.signed_distance(points_cad)
    c = true.closest.mean(axis=0)
    J = np.hstack([true.normal, np.cross(true.closest - c, true.normal)])
    x = -np.linalg.solve(J.T @ J, J.T @ true.distance)
    v = np.asarray(nominal.bbox_corners, dtype=float) - c
    return float(np.linalg.norm(x[:3] + np.cross(x[3:], v), axis=1).max())


def efficient_ratios(cov, center, corners, bound, rng, draws=20000):
    """Worst-corner displacement / bound of small motions drawn from N(0, cov) (translation of
    `center`, rotation vector): the errors of an estimator exactly at the bound."""
    x = rng.multivariate_normal(np.zeros(6), cov, size=draws)
    v = np.asarray(corners, dtype=float) - center                    # (8, 3)
    # corner k moves by dt + dw x v_k
    disp = x[:, None, :3] + np.cross(x[:, None, 3:], v[None, :, :])
    return np.linalg.norm(disp, axis=2).max(axis=1) / bound


def scatter(nominal, n_trials, n_points):
    """Same pose, new noise each trial: does the reported covariance match the scatter?"""
    pose = tf.random_transform(np.random.default_rng(7), 100.0)
    deltas, covs, bounds, errs = [], [], [], []
    for k in range(n_trials):
        ps, truth, info, good = simulate_measurement(nominal, n_points=n_points, seed=500 + k,
                                                     pose=pose, outlier_fraction=0.02)
        res = pipeline.register(nominal, ps, seed=k)
        delta = res.measured_to_cad @ tf.invert_transform(truth)   # CAD frame error motion
        c = res.center
        # Small motion about the covariance's centre: translation of c, rotation vector.
        R = delta[:3, :3]
        rot = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / 2.0
        trans = delta[:3, :3] @ c + delta[:3, 3] - c
        deltas.append(np.concatenate([trans, rot]))
        covs.append(res.pose_covariance)
        bounds.append(res.pose_uncertainty_mm)
        errs.append(pose_error(res.measured_to_cad, truth, nominal.bbox_corners))
    D = np.array(deltas)
    emp = np.cov(D.T)
    pred = np.mean(covs, axis=0)
    sd_emp, sd_pred = np.sqrt(np.diag(emp)), np.sqrt(np.diag(pred))
    names = ["tx", "ty", "tz", "rx", "ry", "rz"]
    print("pose scatter over %d noisy trials vs reported covariance (1 sigma):" % n_trials)
    for n, e, p in zip(names, sd_emp, sd_pred):
        unit, f = ("um", 1e3) if n[0] == "t" else ("urad", 1e6)
        print("  %s: scatter %.3f %s, reported %.3f %s, ratio %.2f" % (n, e * f, unit, p * f,
                                                                       unit, e / p))
    # The direction that matters: the worst corner's displacement.
    print("  corner error RMS %.3f um vs reported bound %.3f um: ratio %.2f"
          % (1e3 * np.sqrt(np.mean(np.square(errs))), 1e3 * np.mean(bounds),
             np.sqrt(np.mean(np.square(errs))) / np.mean(bounds)))
    # Variance along the covariance's principal direction, the weakly constrained screw.
    w, V = np.linalg.eigh(pred)
    # scale-free comparison in whitened coordinates
    white = D @ V / np.sqrt(w)
    print("  whitened scatter variance per principal direction (1.0 = exact): %s"
          % np.array2string(np.var(white, axis=0, ddof=1), precision=2))


def full_cloud(nominal):
    n = 269158
    ps, truth, info, good = simulate_measurement(nominal, n_points=n, outlier_fraction=0.02,
                                                 seed=3, section_heights=())
    t0 = time.perf_counter()
    res = pipeline.register(nominal, ps, seed=3)
    t_reg = time.perf_counter() - t0
    err = pose_error(res.measured_to_cad, truth, nominal.bbox_corners)
    print("register of %d points: %.2f s (%s); pose error %.3f um, bound %.3f um"
          % (len(ps.xyz), t_reg, ", ".join("%s %.2f" % kv for kv in res.timing_s.items()),
             err * 1e3, res.pose_uncertainty_mm * 1e3))
    t0 = time.perf_counter()
    nominal.signed_distance(res.points_cad)
    t_dev = time.perf_counter() - t0
    print("exact signed deviations of %d points: %.2f s" % (len(ps.xyz), t_dev))
    try:
        t_insp, m = inspection_feature(nominal, res.points_cad[:200])
        print("FreeCAD Inspection feature: %.2f ms a point on %d points -> %.0f s for the cloud; "
              "ratio %.0fx" % (1e3 * t_insp, m, t_insp * n, t_insp * n / t_dev))
    except Exception as exc:  # the comparison is informative only
        print("FreeCAD Inspection feature not measured: %s" % exc)


def inspection_feature(nominal, points):
    import FreeCAD
    import Points
    doc = FreeCAD.newDocument("bench")
    part = doc.addObject("Part::Feature", "Blade")
    part.Shape = nominal.shape
    cloud = doc.addObject("Points::Feature", "Cloud")
    cloud.Points = Points.Points([FreeCAD.Vector(*p) for p in points])
    insp = doc.addObject("Inspection::Feature", "Inspection")
    insp.Actual = cloud
    insp.Nominals = [part]
    t0 = time.perf_counter()
    doc.recompute()
    dt = time.perf_counter() - t0
    FreeCAD.closeDocument(doc.Name)
    return dt / len(points), len(points)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cad", default=None)
    ap.add_argument("--trials", type=int, default=200)
    ap.add_argument("--points", type=int, default=20000)
    ap.add_argument("--scatter", type=int, default=30)
    ap.add_argument("--full", action="store_true")
    args = ap.parse_args()
    nominal = pipeline.load_nominal(args.cad)
    print("CAD: %s, %d faces" % (args.cad or "demo blade", len(nominal.faces)), flush=True)
    if args.trials:
        trials(nominal, args.trials, args.points)
    if args.scatter:
        scatter(nominal, args.scatter, args.points)
    if args.full:
        full_cloud(nominal)


if __name__ == "__main__":
    sys.exit(main())
