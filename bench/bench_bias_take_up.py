"""How the fine registration takes up the sensor's reading bias (the systematic term of
inspection/uncertainty.py) on a recorded loop, against the linear take-up the model states.

The model (uncertainty.systematic_coefficients, the airfoil draws' bias) moves each point by
b s_i, s_i = beta_i - J_i (J^T W J)^-1 J^T W beta: the least-squares pose response to a bias b,
linear in b, with the fit's own weights W. This bench measures the fit's real response on
bench_uncertainty_mc.py's recorded scan: one noise stream, the same readings with a bias b
added, fitted as the loop fits (the sensor weights) and, for comparison, with the paper's SNR
weights and with core.icp's neighbourhood defect test switched off (defect_neighbours = 0).
It prints the pose's error against the true pose (translation um, rotation mdeg, in the CAD
frame), the inliers, and the model's linear prediction (b times the response at b = 0).

Defect test "on" is core.icp's as the loop runs it: since the beams' allowance (docs/fits.md,
"The defect test and the sensor's bias") each neighbourhood is granted the field a bias of the
stated accuracy leaves there, accuracy |s_i| sqrt(a_i). "bias out" is an earlier prototype, kept
for comparison, here only: core.icp's rule as it was before that allowance, its neighbourhood
means judged after removing the best-fitting multiple b^ of the bias's own signature (the means
of s_i sqrt(a_i), s_i at the true pose), |b^| <= the sensor's accuracy.

    scripts/fcpython bench/bench_bias_take_up.py [--blade rotor67|demo] [--noise-seed 5]
"""
import argparse
import dataclasses
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import bench_uncertainty_mc as mc  # noqa: E402
from BladeInspect.core import icp as icp_mod  # noqa: E402
from BladeInspect.inspection import pipeline, weighting  # noqa: E402

BIASES_UM = (0.0, 2.0, 4.0, 6.0, -6.0)


def pose_error(T, truth):
    """(translation um, rotation mdeg) of T against the true pose, in the CAD frame."""
    D = T @ np.linalg.inv(truth)
    R = D[:3, :3]
    w = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return np.r_[1e3 * D[:3, 3], 1e3 * np.degrees(w)]


def linear_take_up(fit, xyz, nominal, beams_measured):
    """The model's pose response per unit bias at this fit: (J^T W J)^-1 J^T W beta as
    (translation, rotation) of the CAD-frame points; the fit's correction is its negative."""
    points = xyz @ fit.transform[:3, :3].T + fit.transform[:3, 3]
    dist = nominal.signed_distance(points)
    normal = dist.normal
    beta = np.einsum("ij,ij->i", beams_measured @ fit.transform[:3, :3].T, normal)
    w = np.asarray(fit.weights, dtype=float) * np.asarray(fit.inlier, dtype=bool)
    J = np.hstack([normal, np.cross(points - fit.center, normal)])
    JW = J.T * w
    return np.linalg.lstsq(JW @ J, JW @ beta, rcond=1e-12)[0], fit.center


original_robust_selection = icp_mod.robust_selection


def bias_signature(chain, xyz, snr, angles, beams, truth):
    """s_i of the readings at the true pose: beta_i less the linear take-up, sensor weights."""
    points = xyz @ truth[:3, :3].T + truth[:3, 3]
    normal = chain.nominal.signed_distance(points).normal
    beta = np.einsum("ij,ij->i", beams @ truth[:3, :3].T, normal)
    model = weighting.weights_for_rows(xyz, snr, angles, "sensor", chain.believed)[0]
    w = np.nan_to_num(np.asarray(model(truth, normal), dtype=float))
    J = np.hstack([normal, np.cross(points - points.mean(axis=0), normal)])
    JW = J.T * w
    return beta - J @ np.linalg.lstsq(JW @ J, JW @ beta, rcond=None)[0]


def signature_removed_weights(signature, accuracy):
    """core.icp.robust_selection with the defect test's neighbourhood means judged after the
    best-fitting b^ signature (|b^| <= accuracy) is taken out; the whole cloud's fits only
    (the subsample levels keep the test as it is). No InlierCut: this rule has none."""
    def robust_selection(distances, a, options, neighbourhoods=None, bias_response=None):
        # bias_response (core.icp's allowance) left unused: the prototype is the rule before it
        if neighbourhoods is None or len(distances) != len(signature):
            return original_robust_selection(distances, a, options, neighbourhoods)
        usable = (a > 0) & np.isfinite(distances)
        root = np.sqrt(np.maximum(a, options.max_noise_ratio ** -2))
        z = np.where(usable, distances * root, np.inf)
        u, scale = icp_mod._robust_deviation(z, usable, options)
        rho = icp_mod._taper(u, options)
        limit = options.k_full * scale
        local = neighbourhoods.means(np.clip(z, -limit, limit), usable)
        g = neighbourhoods.means(np.where(usable, signature * root, 0.0), usable)
        f = np.isfinite(local) & np.isfinite(g)
        b = float(np.clip(local[f] @ g[f] / (g[f] @ g[f]), -accuracy, accuracy))
        local = local - b * g
        return rho * icp_mod._taper(icp_mod._robust_deviation(
            local, np.isfinite(local), options)[0], options), scale, None
    return robust_selection


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--blade", choices=("rotor67", "demo"), default="rotor67")
    ap.add_argument("--noise-seed", type=int, default=5)
    args = ap.parse_args()
    chain = mc.Chain(args.blade, 2026, 31)
    rec = chain.rec
    reading, snr = chain.sensor.read(rec["distance"], rec["incidence"],
                                     np.random.default_rng(args.noise_seed))
    ok = np.isfinite(reading)
    noise = np.where(ok, reading - rec["distance"], 0.0)
    machine0 = mc.by_angle(chain.believed.machine_point_of_table, rec["table"], rec["angle"])
    truth = rec["table_to_cad"]
    angles = rec["angle"][ok]
    from BladeInspect.core.weights import beam_in_table
    from BladeInspect.rig.simulated import BEAM_MACHINE
    beams = beam_in_table(angles, chain.believed.axis_direction, BEAM_MACHINE)

    def cloud(b):
        machine = machine0.copy()
        machine[:, 2] -= noise + b
        return mc.by_angle(chain.believed.table_point, machine, rec["angle"])[ok]

    original = icp_mod.icp

    def without_defect_test(points, snr_, closest, init, options=None, weight_model=None):
        options = dataclasses.replace(options or icp_mod.ICPOptions(), defect_neighbours=0)
        return original(points, snr_, closest, init, options, weight_model)

    signature = bias_signature(chain, cloud(0.0), snr[ok], angles, beams, truth)
    with_signature_removed = signature_removed_weights(signature, chain.sensor.accuracy)

    print("%s: %d readings, noise stream %d; pose error against the truth: translation (um), "
          "rotation (mdeg), CAD frame" % (args.blade, int(ok.sum()), args.noise_seed))
    print("%-8s %-13s %7s %8s  %-46s  %s" % ("weights", "defect test", "b (um)", "inliers",
                                            "fit: tx ty tz | rx ry rz", "model (linear)"))
    for weights in ("sensor", "snr"):
        for defect in ("on", "off", "bias out")[:3 if weights == "sensor" else 2]:
            icp_mod.icp = original if defect != "off" else without_defect_test
            icp_mod.robust_selection = (with_signature_removed if defect == "bias out"
                                        else original_robust_selection)
            response = None
            for b_um in (BIASES_UM if weights == "sensor" else (0.0, 6.0)):
                xyz = cloud(1e-3 * b_um)
                model = (weighting.weights_for_rows(xyz, snr[ok], angles, weights,
                                                    chain.believed)[0])
                fit = pipeline.fine_register(xyz, snr[ok], chain.nominal, truth,
                                             rng=np.random.default_rng(3), weight_model=model)
                err = pose_error(fit.transform, truth)
                if response is None:
                    base = err
                    r, centre = linear_take_up(fit, xyz, chain.nominal, beams)
                    # the fit moves the points by -b r about the centre: the pose error it adds
                    dw = -r[3:]
                    dt = -r[:3] - np.cross(dw, centre)
                    response = np.r_[1e3 * dt, 1e3 * np.degrees(dw)]
                predicted = base + 1e-3 * b_um * response
                print("%-8s %-13s %+7.1f %8d  %s | %s  %s" % (
                    weights, defect, b_um, int(fit.inlier.sum()),
                    " ".join("%+6.2f" % x for x in err[:3]),
                    " ".join("%+6.2f" % x for x in err[3:]),
                    " ".join("%+6.2f" % x for x in predicted)), flush=True)
    icp_mod.icp = original
    icp_mod.robust_selection = original_robust_selection


if __name__ == "__main__":
    main()
