"""The paper's simulation test bed (4.1, Fig. 6): surfaces and section lines taken from the CAD,
moved by a random known rotation and translation, given measurement error, then registered with
no knowledge of the pose; the pose error is judged against the truth and against the pose's own
Cramér–Rao bound."""

import dataclasses
import json
import time
from dataclasses import dataclass

import numpy as np

from ..core import bspline
from ..core import span as span_mod
from ..core import transforms as tf
from ..core.errors import InputError
from ..core.pointio import PointSet, write_points_csv
from ..measurement.planning import face_count_and_planes, span_frame
from .pipeline import AtomicOutput, register, write_register_outputs

# Good readings and gross outliers get these SNRs: outliers come from poor signal.
GOOD_SNR = (60.0, 95.0)
OUTLIER_SNR = (2.0, 10.0)
SECTION_LINE_HEIGHTS_PCT = (25.0, 50.0, 75.0)


def measurement_faces(nominal, sides):
    """Face indices a scan of the given sides covers: the suction/pressure roles (and a root
    block's faces, for both sides) when the CAD has them, otherwise every face that is not planar (hub and tip caps are planes)."""
    roles = nominal.roles or {}
    if sides not in ("both", "suction", "pressure"):
        raise InputError("--sides: expected both, suction or pressure, got %r" % sides)
    if roles.get("suction") and roles.get("pressure"):
        # A root block is part of the part a scan of both sides sees (and holds the datums).
        names = ("suction", "pressure", "root_block") if sides == "both" else (sides,)
        return sorted(i for name in names for i in roles.get(name, ()))
    if sides != "both":
        raise InputError("--sides %s: this CAD has no suction/pressure faces marked" % sides)
    # No side named: the airfoil rule without roles, every face that is not a plane.
    return span_mod.airfoil_faces(None, *face_count_and_planes(nominal))


def sample_faces(nominal, faces, n, rng):
    """n points spread over the given faces by area, evaluated exactly on their surfaces at
    parameters jittered off the nominal's own sample grid, inside each face's trimmed domain."""
    s = nominal.samples
    mask = np.isin(s.face, faces)
    idx = np.flatnonzero(mask)
    if len(idx) == 0:
        raise InputError("the CAD has no samples on the faces to simulate")
    p = s.weight[idx] / s.weight[idx].sum()
    chosen = rng.choice(idx, size=n, p=p)
    points = np.empty((n, 3))
    normals = np.empty((n, 3))
    for f in np.unique(s.face[chosen]):
        sel = np.flatnonzero(s.face[chosen] == f)
        surf = nominal.surfaces[f]
        uv = s.uv[chosen[sel]]
        # Jitter by a fraction of the local sample step; clamp to the face's parameter box.
        du = (surf.u_range[1] - surf.u_range[0]) * 2e-3
        dv = (surf.v_range[1] - surf.v_range[0]) * 2e-3
        u = np.clip(uv[:, 0] + rng.uniform(-du, du, len(sel)), *surf.u_range)
        v = np.clip(uv[:, 1] + rng.uniform(-dv, dv, len(sel)), *surf.v_range)
        S, Su, Sv = bspline.evaluate(surf, u, v, order=1)
        nrm = np.cross(Su, Sv)
        nrm /= np.linalg.norm(nrm, axis=1)[:, None]
        # Orient like the nominal's outward sample normals.
        flip = np.einsum("ij,ij->i", nrm, s.normal[chosen[sel]]) < 0
        nrm[flip] *= -1
        points[sel], normals[sel] = S, nrm
    return points, normals


def section_lines(nominal, heights_pct, spacing):
    """Points along plane cuts of the CAD across its span (paper: three section lines), at
    heights of the span as every command measures it (measurement.planning.span_frame)."""
    from ..cad.sections import cut   # cad/ needs FreeCAD; inspection/ imports without it
    frame = span_frame(nominal)
    normal = frame.axis
    pts = []
    for h in heights_pct:
        origin = normal * (frame.lo + (frame.hi - frame.lo) * h / 100.0)
        for line in cut(nominal.shape, origin, normal):
            seg = np.linalg.norm(np.diff(line, axis=0), axis=1)
            arc = np.concatenate([[0.0], np.cumsum(seg)])
            t = np.arange(0.0, arc[-1], spacing)
            pts.append(np.column_stack([np.interp(t, arc, line[:, k]) for k in range(3)]))
    return np.vstack(pts) if pts else np.zeros((0, 3))


def measurement_error(n, noise, rng, amplitude=0.006, sigma=0.002):
    """Uniform on [-a, a] (the paper's protocol) or normal sigma clipped at +-3 sigma (what its
    Fig. 8 figures fit, see docs/contracts.md)."""
    if noise == "uniform":
        return rng.uniform(-amplitude, amplitude, n)
    if noise == "normal":
        return np.clip(rng.normal(0.0, sigma, n), -3 * sigma, 3 * sigma)
    raise InputError("--noise: expected uniform or normal, got %r" % noise)


@dataclass(frozen=True)
class SimulatedScan:
    """What the simulated measurement samples and how it errs: ``n_points`` surface points on
    the ``sides`` (both, suction, pressure), section lines at ``section_heights`` (% of span),
    measurement error ``noise`` (uniform on +-``amplitude`` or normal ``sigma``, mm), a
    fraction ``outlier_fraction`` of gross outliers, and a random pose whose translation is at
    most ``max_translation`` mm."""
    n_points: int = 20000
    sides: str = "both"
    noise: str = "uniform"
    amplitude: float = 0.006
    sigma: float = 0.002
    outlier_fraction: float = 0.0
    section_heights: tuple = SECTION_LINE_HEIGHTS_PCT
    max_translation: float = 100.0


def simulate_measurement(nominal, scan=None, seed=0, pose=None, **fields):
    """A measured point set in an unknown frame and the truth that maps it into the CAD frame:
    ``scan`` (SimulatedScan; None: its defaults) with ``fields`` of SimulatedScan replacing
    its values, drawn from ``seed``, moved by ``pose`` (None: a random pose).

    Returns (PointSet, measured_to_cad_truth, info dict, mask of the readings without a gross
    error)."""
    scan = dataclasses.replace(scan or SimulatedScan(), **fields)
    n_points, sides, noise = scan.n_points, scan.sides, scan.noise
    amplitude, sigma, outlier_fraction = scan.amplitude, scan.sigma, scan.outlier_fraction
    section_heights, max_translation = scan.section_heights, scan.max_translation
    if n_points < 10:
        raise InputError("--points: at least 10 points are needed, got %d" % n_points)
    rng = np.random.default_rng(seed)
    faces = measurement_faces(nominal, sides)
    n_surface = int(n_points)
    pts, nrm = sample_faces(nominal, faces, n_surface, rng)
    section_id = np.full(len(pts), -1.0)
    if section_heights:
        lines = section_lines(nominal, section_heights, spacing=0.1)
        if len(lines):
            res = nominal.signed_distance(lines)
            pts = np.vstack([pts, res.closest])
            nrm = np.vstack([nrm, res.normal])
            section_id = np.concatenate([section_id, np.zeros(len(lines))])
    n = len(pts)
    err = measurement_error(n, noise, rng, amplitude, sigma)
    snr = rng.uniform(*GOOD_SNR, n)
    n_out = int(round(outlier_fraction * n))
    outliers = rng.choice(n, size=n_out, replace=False) if n_out else np.zeros(0, int)
    err[outliers] = rng.choice([-1.0, 1.0], n_out) * rng.uniform(0.1, 0.5, n_out)
    snr[outliers] = rng.uniform(*OUTLIER_SNR, n_out)
    measured_cad = pts + err[:, None] * nrm
    move = tf.random_transform(rng, max_translation) if pose is None else np.asarray(pose)
    measured = tf.apply_transform(move, measured_cad)
    truth = tf.invert_transform(move)
    good = np.ones(n, bool)
    good[outliers] = False
    info = {"n_points": n, "n_section_points": int(np.count_nonzero(section_id >= 0)),
            "n_outliers": int(n_out), "noise": noise,
            "noise_rms_injected_mm": float(np.sqrt(np.mean(err[good] ** 2))),
            "noise_rms_model_mm": (amplitude / np.sqrt(3.0) if noise == "uniform" else None),
            "faces": [int(f) for f in faces], "sides": sides, "seed": seed}
    ps = PointSet(xyz=measured, snr=snr, columns={}, n_rows_skipped=0,
                  source="simulated measurement (seed %d)" % seed)
    return ps, truth, info, good


def pose_error(estimated, truth, corners):
    """Largest displacement of a corner of the CAD's bounding box between the two poses."""
    delta = estimated @ tf.invert_transform(truth)
    return tf.corner_displacement(delta, np.eye(4), corners)


def run_simulation(nominal, seed=0, progress=None, **options):
    """Simulate, register, judge. Returns (RegistrationResult, report dict)."""
    t0 = time.perf_counter()
    pointset, truth, info, good = simulate_measurement(nominal, seed=seed, **options)
    t_sim = time.perf_counter() - t0
    result = register(nominal, pointset, seed=seed, progress=progress)
    result.timing_s = dict(simulate=t_sim, **result.timing_s)
    err = pose_error(result.measured_to_cad, truth, nominal.bbox_corners)
    dev_good = result.deviation[good]
    report = dict(info)
    report.update({
        "truth_measured_to_cad": truth.tolist(),
        "pose_error_mm": float(err),
        "pose_uncertainty_mm": result.pose_uncertainty_mm,
        "pose_error_over_bound": float(err / result.pose_uncertainty_mm),
        "residual_rms_mm": float(np.sqrt(np.mean(dev_good ** 2))),
        "residual_min_mm": float(dev_good.min()),
        "residual_max_mm": float(dev_good.max()),
        "outliers_flagged": int(np.count_nonzero(~result.inlier[~good])),
        "good_points_rejected": int(np.count_nonzero(~result.inlier[good])),
        "paper": {"rms_mm": 0.0019, "min_mm": -0.0053, "max_mm": 0.006},
    })
    return result, report, pointset


def write_simulation(out_dir, result, report, pointset):
    with AtomicOutput(out_dir) as out:
        write_register_outputs(out_dir, result, extra={"simulation": report}, output=out)
        write_points_csv(out.path("points.csv"), pointset.xyz, {"snr": pointset.snr})
        with open(out.path("simulation.json"), "w") as fh:
            json.dump(report, fh, indent=1)
