"""The rigid take-up of a unit reading bias and the edge-foot readings, on the recorded scans of
bench_uncertainty_mc.py (demo blade, Rotor 67): one noise stream per seed, the loop's fine
registration with the sensor weights, started at the true pose.

Part "take-up": the two places that compute the take-up, at the fit's final pose,
core.icp._bias_response (the defect test's s_i: the fit's last normals, the sensor weights a_i
before the robust factor, their centroid) and inspection.uncertainty.bias_take_up /
systematic_coefficients (the result's exact normals, the fit's final weights a_i rho_i, about
result.center). ``--save FILE`` writes s and r of both (an .npz) so that two code versions can
be compared (``--compare FILE``: max |delta s|, |delta r|).

Part "edge feet": readings whose beam meets the CAD normal at their foot more obliquely than
the sensor reads (|beam . n| < cos(max_incidence)): their foot is on a face's edge (normal
p - c). core.weights floors cos(theta) there, so they get the model's largest weight. Printed:
their number, their share of the fit's weight and of its information H = sum w J^T J along each
eigen-direction of H, and the pose error against the simulator's truth, chi2 = x^T H_crb x
(x the error twist about the weighted centre, H_crb the information of the readings' true
noise at the true pose: 6 on average for an efficient fit), with the weights as they are
("floor"), edge feet at zero weight ("zero") and edge feet capped at the head-on weight
1 / sigma_beam^2 ("cap").

    scripts/fcpython bench/bench_edge_foot.py [--blade demo|rotor67|both] [--seeds 1,2,3]
        [--variants floor,zero,cap] [--save FILE | --compare FILE]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import bench_uncertainty_mc as mc  # noqa: E402
from BladeInspect.core import bias_take_up as take_up_mod  # noqa: E402
from BladeInspect.core import icp as icp_mod  # noqa: E402
from BladeInspect.core import weights as weights_mod  # noqa: E402
from BladeInspect.inspection import uncertainty as uncertainty_mod  # noqa: E402


class EdgeFootWeights(weights_mod.SensorWeights):
    """SensorWeights with the readings whose incidence exceeds max_incidence at this pose
    given zero weight ("zero") or at most the head-on weight 1 / sigma_beam^2 ("cap")."""

    def __init__(self, base, mode):
        super().__init__(base.snr, base.beam, base.sigma_ref, base.snr_ref,
                         base.max_incidence_rad)
        self.mode = mode

    def subset(self, index):
        return EdgeFootWeights(super().subset(index), self.mode)

    def __call__(self, transform, normals):
        w = super().__call__(transform, normals)
        beam_cad = self.beam @ np.asarray(transform, dtype=float)[:3, :3].T
        cos = np.abs(np.einsum("ij,ij->i", beam_cad, np.asarray(normals, dtype=float)))
        edge = cos < np.cos(self.max_incidence_rad)
        if self.mode == "zero":
            return np.where(edge, 0.0, w)
        with np.errstate(divide="ignore"):
            head_on = np.where(self.snr > 0, 1.0 / self.beam_sigma() ** 2, 0.0)
        return np.where(edge, np.minimum(w, head_on), w)


def twist_error(T, truth, center):
    """(6,) [t mm, w rad] of T against the truth as a motion of the CAD-frame points about
    ``center``."""
    D = T @ np.linalg.inv(truth)
    R = D[:3, :3]
    w = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    t = D[:3, 3] + R @ center - center
    return np.r_[t, w]


def info(points, normals, w, center):
    J = np.hstack([normals, np.cross(points - center, normals)])
    return (J.T * w) @ J


def run(chain, seed, variant, captured):
    rec = chain.rec
    reading, snr = chain.sensor.read(rec["distance"], rec["incidence"],
                                     np.random.default_rng(seed))
    ok = np.isfinite(reading)
    noise = np.where(ok, reading - rec["distance"], 0.0)
    machine = mc.by_angle(chain.believed.machine_point_of_table, rec["table"], rec["angle"])
    machine[:, 2] -= noise
    xyz = mc.by_angle(chain.believed.table_point, machine, rec["angle"])[ok]
    truth = rec["table_to_cad"]
    angles = rec["angle"][ok]
    captured.clear()
    original_weights_for_rows = mc.weighting.weights_for_rows

    def weights_for_rows(*args, **kw):
        model, record = original_weights_for_rows(*args, **kw)
        return (model if variant == "floor" else EdgeFootWeights(model, variant)), record
    mc.weighting.weights_for_rows = weights_for_rows
    try:
        result = mc.registered(chain.nominal, xyz, snr[ok], truth, np.random.default_rng(3),
                               angles, chain.believed)
    finally:
        mc.weighting.weights_for_rows = original_weights_for_rows
    fit, model = captured[-1]
    return result, fit, model, xyz, snr[ok], angles, truth, rec["incidence"][ok], ok


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--blade", choices=("demo", "rotor67", "both"), default="both")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--variants", default="floor,zero,cap")
    ap.add_argument("--save")
    ap.add_argument("--compare")
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    variants = args.variants.split(",")
    blades = ("demo", "rotor67") if args.blade == "both" else (args.blade,)
    captured = []
    original_icp = icp_mod.icp

    def capturing_icp(points, snr, closest_fn, init, options=None, weight_model=None,
                      beams=None):
        fit = original_icp(points, snr, closest_fn, init, options, weight_model, beams)
        captured.append((fit, weight_model))
        return fit
    icp_mod.icp = capturing_icp
    saved = {}
    old = dict(np.load(args.compare)) if args.compare else None
    for name in blades:
        chain = mc.Chain(name, 2026, 31)
        cos_max = np.cos(chain.sensor.max_incidence_rad)
        print("== %s" % name)
        for seed in seeds:
            for variant in variants:
                result, fit, model, xyz, snr, angles, truth, incidence, ok = \
                    run(chain, seed, variant, captured)
                T = fit.transform
                R = T[:3, :3]
                beams_cad = model.beam @ R.T
                moved = xyz @ R.T + T[:3, 3]
                normals = fit.normals
                cos = np.abs(np.einsum("ij,ij->i", beams_cad, normals))
                edge = cos < cos_max
                w = np.asarray(fit.weights, dtype=float)
                c = fit.center
                H = info(moved, normals, w, c)
                He = info(moved[edge], normals[edge], w[edge], c)
                lam, V = np.linalg.eigh(H)
                share = np.einsum("ij,jk,ki->i", V.T, He, V) / lam
                # The CRB: the true readings at the true pose with their true noise along the
                # normal (sigma_beam(SNR) cos(true incidence)).
                true_pts = xyz @ truth[:3, :3].T + truth[:3, 3]
                tn = chain.nominal.signed_distance(true_pts).normal
                sig = model.beam_sigma() * np.cos(incidence)
                w_crb = np.where(np.isfinite(sig) & (sig > 0), 1.0 / sig ** 2, 0.0)
                c_crb = w_crb @ true_pts / w_crb.sum()
                H_crb = info(true_pts, tn, w_crb, c_crb)
                x = twist_error(T, truth, c_crb)
                chi2 = float(x @ H_crb @ x)
                span_err = 1e3 * np.linalg.norm(x[:3])
                print("seed %d %-5s: %4d edge feet of %d (%d inliers), weight share %.3f; "
                      "H share per eigen-direction (weakest first) %s; pose error |t| %.2f um "
                      "|w| %.2f urad, chi2 %.2f"
                      % (seed, variant, int(edge.sum()), len(edge), int(result.inlier.sum()),
                         w[edge].sum() / w.sum(), np.array2string(share, precision=3),
                         span_err, 1e6 * np.linalg.norm(x[3:]), chi2))
                if variant != "floor":
                    continue
                # The take-up in its two places, at this pose.
                a = weights_mod.normalised_weights(model, T, normals, len(xyz))
                s_icp = icp_mod._bias_response(moved, normals, beams_cad, a,
                                               model.max_incidence_rad)
                beams_u, r_u = uncertainty_mod.bias_take_up(result, chain.sensor)
                s_u = uncertainty_mod.systematic_coefficients(result, chain.sensor)
                # what makes the two differ: the weights (a_i against a_i rho_i of the
                # inliers), then the points and normals (the fit's last evaluation against
                # the result's exact distances); the centre does not change s
                # (on the points core.icp states an s for: a_i > 0)
                w_rho = np.asarray(fit.weights) * fit.inlier
                r_rho = take_up_mod.take_up(moved, normals, beams_cad, w_rho, c,
                                            model.max_incidence_rad)
                s_rho = take_up_mod.left_over(moved, normals, beams_cad, r_rho, c)
                on = a > 0
                print("   weights a vs a rho: max |ds| %.3g; then normals/points: max |ds| "
                      "%.3g; beams: max |d beam| %.3g; %d points without weight"
                      % (np.max(np.abs(s_icp - s_rho)[on]), np.max(np.abs(s_rho - s_u)[on]),
                         np.max(np.abs(beams_cad - beams_u)), int((~on).sum())))
                key = "%s_%d_" % (name, seed)
                saved.update({key + "s_icp": s_icp, key + "s_u": s_u, key + "r_u": r_u})
                print("   take-up: max |s_icp - s_unc| %.3g (median |s| %.3g); r_unc %s"
                      % (np.max(np.abs(s_icp - s_u)[on]), np.median(np.abs(s_u)),
                         np.array2string(r_u, precision=4)))
                if old is not None and key + "s_icp" in old:
                    print("   against --compare: max |ds_icp| %.3g, max |ds_unc| %.3g, "
                          "|dr_unc| %.3g"
                          % (np.max(np.abs(s_icp - old[key + "s_icp"])),
                             np.max(np.abs(s_u - old[key + "s_u"])),
                             np.linalg.norm(r_u - old[key + "r_u"])))
    if args.save:
        np.savez(args.save, **saved)


if __name__ == "__main__":
    main()
