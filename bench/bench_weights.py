"""Efficient weights for the conoscopic sensor (issue 16 item 3): the paper's SNR weights
against the sensor model's 1 / (sigma_beam cos theta)^2 on a planned-section scan.

    scripts/fcpython bench/bench_weights.py [--cad rotor67|demo] [--scans 200] \
        [--seed 31] [--heights 10,30,50,70,90] [--blind 0] [--accuracy 0.0005]

One fixture pose (the truth, random_fixture_pose_of(nominal, seed)), the sections planned from it
(measurement.planning.plan_sections, as `inspect` plans them after its blind scan; with
``--blind N`` the kept readings of an N-section blind scan too, as inspect's final fit has
them) and their rays cast once onto the CAD; then ``--scans`` scans of fresh sensor noise (rig.sensor.read:
noise along the beam, SNR falling with incidence, gross errors at low SNR), each registered by
the pipeline's fine stage from the truth with ``snr`` and with ``sensor`` weights. Reported at
the worst corner of the CAD's bounding box (1 sigma, um):

- the true scatter of each estimator's pose (RMS over the scans, per corner; the worst corner);
- each estimator's stated bound (mean of its pose_uncertainty);
- the Cramer-Rao bound of the true 1 / sigma_n^2 weights, sigma_n = sigma_beam cos theta at the
  truth (the readings the robust weights keep in the first scan);
- the criterion, as bench/bench_register.py states it: the RMS over the scans of the pose error
  (largest corner displacement) against the RMS an estimator exactly at its stated covariance
  would have (each scan's pose drawn from N(0, C) of that scan); must be within 5 %;
- beside it the same RMS against an estimator exactly at the Cramer-Rao bound of the truth
  (poses drawn from N(0, C_CR)): the efficiency itself, free of how well the fit states its
  own covariance.
"""
import argparse
import sys
import time

import numpy as np

from BladeInspect.core import icp as icp_mod
from BladeInspect.core import transforms as tf
from BladeInspect.inspection import pipeline
from BladeInspect.inspection.sections import span_axis_of
from BladeInspect.inspection.weighting import sensor_weights
from BladeInspect.measurement.planning import plan_sections
from BladeInspect.rig.sensor import SensorModel
from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose_of


def load(cad):
    if cad == "rotor67":
        from tests.test_rotor67_loop import rotor67_nominal
        return rotor67_nominal()
    if cad == "demo":
        from BladeInspect.measurement.scan import demo_nominal
        return demo_nominal()
    return pipeline.load_nominal(cad)


class Rays:
    """Readings' rays cast once at the truth (what SimulatedRig.measure casts each pass), so
    each scan only draws new sensor noise: ``passes`` of (sensor positions (K,3) in the
    machine frame, rotary angle)."""

    def __init__(self, rig, passes):
        self.rig = rig
        self.passes = []
        for origins_machine, angle in passes:
            T = rig.cad_from_machine(angle)
            origins = tf.apply_transform(T, origins_machine)
            beam = T[:3, :3] @ np.array([0.0, 0.0, -1.0])
            t, _, normal = rig.part.raycast(origins, np.tile(beam, (len(origins), 1)))
            t = np.asarray(t, dtype=float)
            cos_inc = -(np.asarray(normal, dtype=float) @ beam)
            hit = np.isfinite(t) & (cos_inc > 0)
            incidence = np.where(hit, np.arccos(np.clip(cos_inc, -1.0, 1.0)), np.pi)
            self.passes.append((origins_machine, angle, np.where(hit, t, np.nan), incidence))

    def scan(self, seed):
        """(table-frame xyz, snr, angle_deg, incidence) of one scan's readings."""
        xyz, snr, angle, incidence = [], [], [], []
        kin = self.rig.kinematics
        for k, (origins, a, t, inc) in enumerate(self.passes):
            d, s = self.rig.sensor.read(t, inc, np.random.default_rng([seed, k]))
            ok = np.isfinite(d)
            xyz.append(kin.table_point(origins[ok] - d[ok, None] * [0.0, 0.0, 1.0], a))
            snr.append(s[ok])
            angle.append(np.full(int(ok.sum()), a))
            incidence.append(inc[ok])
        return tuple(np.concatenate(v) for v in (xyz, snr, angle, incidence))


def planned_passes(rig, plan):
    return [(rig.kinematics.sensor_position(plan.path_stage_xyz(p)), p.angle_deg)
            for p in plan.paths]


def blind_passes(rig, n_sections, seed):
    """The blind section scan's kept readings (measurement.scan.scan_to_dir, as `scan` and
    `inspect` run it) as rays: each point's machine position at its rotary angle, the sensor
    a standoff up the beam from it."""
    import shutil
    import tempfile
    from BladeInspect.core.pointio import read_points
    from BladeInspect.measurement.scan import scan_to_dir
    tmp = tempfile.mkdtemp(prefix="bi-weights-")
    try:
        scan_to_dir(tmp + "/scan", rig, n_sections=n_sections, seed=seed)
        points = read_points(tmp + "/scan/points.csv")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    angle = np.asarray(points.columns["angle_deg"], dtype=float)
    out = []
    for a in np.unique(angle):
        m = rig.kinematics.machine_point_of_table(points.xyz[angle == a], a)
        out.append((m + [0.0, 0.0, rig.sensor.standoff], float(a)))
    return out


def corner_errors(T, truth, corners):
    """Displacement vectors (8, 3) of the CAD box's corners under the pose error."""
    pts_true = tf.apply_transform(tf.invert_transform(truth), corners)
    return tf.apply_transform(T, pts_true) - corners


def efficient_rms(covs, centers, corners, rng, draws=4000):
    """RMS over scans of the worst-corner displacement of poses drawn from N(0, C_scan)."""
    out = []
    for cov, c in zip(covs, centers):
        x = rng.multivariate_normal(np.zeros(6), cov, size=draws)
        v = corners - c
        disp = x[:, None, :3] + np.cross(x[:, None, 3:], v[None, :, :])
        out.append(np.mean(np.linalg.norm(disp, axis=2).max(axis=1) ** 2))
    return float(np.sqrt(np.mean(out)))


def cramer_rao(nominal, truth, xyz, snr, angle, keep, sensor):
    """Worst-corner 1 sigma at the truth of the Cramer-Rao bound (sum J^T J / sigma_n^2)^-1
    and of the SNR-weighted least squares' true covariance A^-1 (sum a^2 sigma_n^2 J^T J) A^-1,
    A = sum a J^T J (a sandwich: its weights are not 1 / sigma_n^2), sigma_n from the sensor
    model and the true incidence on the CAD; and the incidences' quartiles, deg."""
    cad = tf.apply_transform(truth, xyz[keep])
    res = nominal.signed_distance(cad)
    model = sensor_weights(snr[keep], angle[keep], sensor)
    w = 1.0 / model.normal_sigma(truth, res.normal) ** 2
    center = w @ cad / w.sum()
    J = np.hstack([res.normal, np.cross(res.closest - center, res.normal)])
    C = np.linalg.inv((J * w[:, None]).T @ J)
    a = snr[keep]
    A = np.linalg.inv((J * a[:, None]).T @ J)
    sandwich = A @ ((J * (a * a / w)[:, None]).T @ J) @ A
    cos = model.cos_incidence(truth, res.normal)
    return (icp_mod.pose_uncertainty(C, center, nominal.bbox_corners),
            icp_mod.pose_uncertainty(sandwich, center, nominal.bbox_corners),
            np.degrees(np.arccos(np.percentile(cos, [75, 50, 25]))), C, center)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cad", default="rotor67")
    ap.add_argument("--scans", type=int, default=200)
    ap.add_argument("--seed", type=int, default=31)
    ap.add_argument("--heights", default="10,30,50,70,90")
    ap.add_argument("--blind", type=int, default=0,
                    help="add a blind scan of this many sections (inspect's final fit uses "
                    "the blind and the planned readings); default 0: planned only")
    ap.add_argument("--accuracy", type=float, default=0.0005,
                    help="sensor accuracy, mm (default 0.5 um, tests/test_rotor67_loop's)")
    args = ap.parse_args()
    nominal = load(args.cad)
    corners = nominal.bbox_corners
    axis, _ = span_axis_of(nominal)
    truth = random_fixture_pose_of(nominal, np.random.default_rng(args.seed), axis)
    sensor = SensorModel(accuracy=args.accuracy)
    rig = SimulatedRig(nominal, truth, sensor=sensor, seed=args.seed)
    heights = [float(h) for h in args.heights.split(",")]
    t0 = time.perf_counter()
    plan = plan_sections(nominal, truth, heights, sensor, rig.limits, span_axis=axis)
    passes = planned_passes(rig, plan)
    if args.blind:
        passes += blind_passes(rig, args.blind, args.seed)
    rays = Rays(rig, passes)
    print("%s: %d planned paths over %d sections%s, rays cast in %.0f s"
          % (args.cad, len(plan.paths), len(heights),
             " and a %d-section blind scan" % args.blind if args.blind else "",
             time.perf_counter() - t0), flush=True)

    rows = {"snr": [], "sensor": []}
    cr = None
    t_start = time.perf_counter()
    for k in range(args.scans):
        xyz, snr, angle, inc = rays.scan(1000 + k)
        for name in rows:
            model = sensor_weights(snr, angle, sensor) if name == "sensor" else None
            fit = pipeline.fine_register(xyz, snr, nominal, truth, weight_model=model)
            covariance, bound, _ = pipeline.pose_summary(fit, nominal)
            rows[name].append((corner_errors(fit.transform, truth, corners), bound,
                               covariance, fit.center))
            if cr is None and name == "snr":
                cr = cramer_rao(nominal, truth, xyz, snr, angle, fit.inlier, sensor)
        if k == 0:
            print("  %d readings a scan; %.1f s for the first scan's two fits"
                  % (len(xyz), time.perf_counter() - t_start), flush=True)
        if (k + 1) % 20 == 0:
            print("  %d scans, %.0f s" % (k + 1, time.perf_counter() - t_start), flush=True)

    print("worst corner, 1 sigma, over %d scans (one truth, fresh noise each scan):"
          % args.scans)
    cr, sandwich, quartiles, cr_cov, cr_center = cr
    rms_cr = efficient_rms([cr_cov], [cr_center], corners, np.random.default_rng(1), 200000)
    print("  incidence quartiles %s deg" % np.array2string(quartiles, precision=1))
    print("  Cramer-Rao bound, 1/sigma_n^2 weights: %.4f um; true covariance of the SNR "
          "weights (sandwich at the truth): %.4f um" % (1e3 * cr, 1e3 * sandwich))
    rng = np.random.default_rng(0)
    for name, r in rows.items():
        disp = np.array([e for e, _, _, _ in r])                 # (scans, 8, 3)
        scatter = np.sqrt(np.mean(np.sum(disp ** 2, axis=2), axis=0)).max()
        stated = np.mean([b for _, b, _, _ in r])
        err = np.linalg.norm(disp, axis=2).max(axis=1)
        rms_err = float(np.sqrt(np.mean(err ** 2)))
        rms_eff = efficient_rms([c for _, _, c, _ in r], [c for _, _, _, c in r], corners, rng)
        print("  %-6s true scatter %.4f um, stated bound %.4f um (%.2fx the Cramer-Rao "
              "bound); RMS pose error %.4f um vs %.4f um at the stated covariance: ratio %.3f "
              "(%s 5 %%)" % (name, 1e3 * scatter, 1e3 * stated, scatter / cr, 1e3 * rms_err,
                             1e3 * rms_eff, rms_err / rms_eff,
                             "within" if abs(rms_err / rms_eff - 1) <= 0.05 else "NOT within"))
        print("  %-6s RMS pose error / RMS at the Cramer-Rao bound (%.4f um): %.3f"
              % (name, 1e3 * rms_cr, rms_err / rms_cr))
    print("total %.0f s" % (time.perf_counter() - t_start))


if __name__ == "__main__":
    sys.exit(main())
