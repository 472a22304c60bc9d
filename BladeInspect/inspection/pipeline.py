"""The registration pipeline, one plain function per stage (docs/contracts.md "Data flow").

The command line, the GUI commands and the tests all call these functions; nothing here knows
about a terminal or a window. Long stages report through ``progress(fraction, message)``; a
progress callback that raises ``core.errors.Cancelled`` stops the work.
"""

import dataclasses
import json
import os
import shutil
import tempfile
import time

import numpy as np

from .. import __version__, NAME
from ..core import csvtext
from ..core import icp as icp_mod
from ..core import pca as pca_mod
from ..core import ranking
from ..core import stats as stats_mod
from ..core import transforms as tf
from ..core.closest import FootStart
from ..core.icp import MAD_TO_SIGMA
from ..core.errors import InputError
from ..core.pointio import MIN_POINTS, check_magnitude
from . import checks, weighting
from .result import RegistrationResult
from .run_options import FineOptions, RegisterOptions, RunOptions
from ..core.contracts import json_default

# Points used for the ICP ranking of each PCA candidate and for the fine fit's inner
# iterations; the full cloud only enters the last Gauss-Newton steps and the deviations, which
# keeps a 269k-point registration within seconds without giving up the full cloud's accuracy.
COARSE_SUBSAMPLE = 1500
# Points on which the distinct candidates are ranked, by exact distance to the CAD (a random
# subset beyond this): the ambiguity test's power grows with the number of points that tell
# two poses apart, and every candidate costs one exact distance evaluation of these.
RANKING_POINTS = 10000
FINE_SUBSAMPLE = 30000
# The fine fit's first, coarsest level (a random part of the FINE_SUBSAMPLE points): its Horn
# iterations from the coarse stage's pose only have to bring the pose within Gauss-Newton's
# reach, which a tenth of the points does at a tenth of the cost; FINE_SUBSAMPLE's level then
# takes it on with Gauss-Newton (SUBSAMPLE_STEPS), and the full cloud finishes.
FINE_FIRST_SUBSAMPLE = 3000
# Gauss-Newton steps on the FINE_SUBSAMPLE points: the full cloud's optimum is a few of its
# standard deviations from theirs, so one step (which leaves the subsample a few 1e-3 of the
# way from its own optimum) starts the full cloud as well as converging them would; only the
# pose is kept, so the step's residuals are left linear, without another evaluation.
SUBSAMPLE_STEPS = 1
# The full cloud starts a few of its own standard deviations from its optimum (the
# subsample's), and Gauss-Newton contracts the remaining error by a few 1e-3 a step on these
# surfaces (the rate is residual x curvature): the first step leaves about 1e-2 of a standard
# deviation, the second about 1e-5. The fit stops once the motion still to come, extrapolated
# from how the steps shrink (core.icp, ICPOptions.uncertainty_fraction), is below this
# fraction of the pose's own 1 sigma - nothing that could matter against it - within
# FULL_CLOUD_STEPS closest-point evaluations of every point.
FULL_CLOUD_UNCERTAINTY_FRACTION = 1e-3
FULL_CLOUD_STEPS = 4
# A last step below both is applied to the residuals linearly (core.icp): their error is of
# order curvature x step^2, below 1e-9 mm for radii of curvature down to 0.05 mm at 1e-5 mm
# (1e-7 rad turns a point 100 mm from the centre by 1e-5 mm). The deviations are then the
# fit's own residuals, without another closest-point evaluation of every point; a larger last
# step costs that evaluation at the final pose.
LINEAR_UPDATE_MM = 1e-5
LINEAR_UPDATE_RAD = 1e-7
# The coarse stage's capture phase (see coarse_register): full weight within this many standard
# errors of the PCA centroid (3: the start is rarely farther off), for this many iterations.
CAPTURE_STANDARD_ERRORS = 3.0
CAPTURE_ITERATIONS = 15
# The coarse stage searches around its best candidate when that candidate's median residual is
# above this (several times a point sensor's noise, well below any misalignment worth keeping).
SEARCH_MEDIAN_MM = 0.015
SEARCH_ROUNDS = 4
SEARCH_SHIFTS_MM = (-6.0, -3.0, 3.0, 6.0)
SEARCH_TURNS_DEG = (-8.0, -4.0, 4.0, 8.0)
# Wall-clock budget of the coarse stage, checked at each candidate and search step it reports:
# its ICPs and search rounds are bounded in number, so this only ends a stage that a slow
# distance (points far inside or off the CAD) would stretch to minutes. Half the fine stage's.
COARSE_TIME_LIMIT_S = 60.0
# Wall-clock budget of the fine stage: twelve times docs/contracts.md's 10 s for the whole
# registration of the paper's 269k-point cloud on two cores. A fit still iterating then is
# lost (its points are not on this CAD), not slow; its iteration counts are bounded as well.
FINE_TIME_LIMIT_S = 120.0


def _no_progress(fraction, message):
    pass


# ---------------------------------------------------------------- inputs

def load_nominal(cad_path=None, sample_spacing=None, flip_faces=()):
    """The nominal geometry (see cad.load.load_nominal): a CAD file, a section table, or the
    demo blade when ``cad_path`` is None; ``flip_faces`` as ``--flip-face``."""
    from ..cad.load import load_nominal as load   # cad/ needs FreeCAD; inspection/ does not
    return load(cad_path, sample_spacing=sample_spacing, flip_faces=flip_faces)


def load_points(path):
    """A measured point file (csv/xyz/asc/txt, or ply/pcd through FreeCAD's Points)."""
    from ..cad.load import read_points_any   # cad/ needs FreeCAD; inspection/ does not
    return read_points_any(path)


def _check_points(pointset):
    xyz = np.asarray(pointset.xyz, dtype=float)
    if xyz.ndim != 2 or xyz.shape[1] != 3:
        raise InputError("%s: points must have x, y, z" % pointset.source)
    if len(xyz) < MIN_POINTS:
        raise InputError("%s: %d usable points, at least %d needed"
                         % (pointset.source or "points", len(xyz), MIN_POINTS))
    if not np.all(np.isfinite(xyz)):
        raise InputError("%s: points contain NaN or infinite coordinates" % pointset.source)
    check_magnitude(pointset.source or "points", xyz)
    return xyz


def _subsample(n, k, rng):
    if n <= k:
        return np.arange(n)
    return np.sort(rng.choice(n, size=k, replace=False))


# ---------------------------------------------------------------- coarse

def _sample_closest_fn(nominal):
    """Closest point on the nominal's dense samples, point-to-plane distance to the sample's
    tangent plane: good to the sample spacing's curvature error, enough to rank candidates."""
    xyz, nrm = nominal.samples.xyz, nominal.samples.normal

    def closest(points):
        idx = nominal.nearest_sample(points)
        normal = nrm[idx]
        dist = np.einsum("ij,ij->i", points - xyz[idx], normal)
        return points - dist[:, None] * normal, normal, dist
    return closest


def coarse_register(measured_xyz, weights, nominal, pca_points=None, rng=None,
                    progress=_no_progress):
    """PCA coarse registration (paper 3.1.3): principal axes of the measured surface (or of its
    B-spline reconstruction's samples, ``pca_points``) against the nominal's, every proper sign
    combination refined by a short ICP on a subsample, then ranked by one objective common to
    all of them (core.ranking: the fine stage's robust loss at one noise scale, over all points
    up to RANKING_POINTS, exact distances to the CAD), the best tested against its best distinct
    rival.

    Returns a dict: measured_to_cad (chosen candidate, refined), pca_measured_to_cad (the raw
    PCA pose of that candidate), eigenvalues, candidates, chosen, ranking, rival (the best
    distinct other pose, or None), local_search, warning."""
    rng = np.random.default_rng(0) if rng is None else rng
    pca_source = measured_xyz if pca_points is None else pca_points
    axes_m = pca_mod.principal_axes(pca_source)
    axes_n = pca_mod.principal_axes(nominal.samples.xyz, nominal.samples.weight)
    axes_warning = pca_mod.axes_warning(axes_m, axes_n)
    candidates = list(pca_mod.candidate_poses(axes_m, axes_n))
    if axes_warning:
        # Two axes are interchangeable up to noise: their directions in that plane are
        # arbitrary, so try the candidates turned about the well-defined axis as well.
        extra = []
        for T in candidates:
            for k in range(1, 12):
                angle = np.pi * k / 6.0
                R = tf.rotation_from_vector(axes_n.axes[:, 0] * angle)
                c = axes_n.centroid
                turn = tf.make_transform(R, c - R @ c)
                extra.append(turn @ T)
        candidates += extra

    sub = _subsample(len(measured_xyz), COARSE_SUBSAMPLE, rng)
    pts, w = measured_xyz[sub], None if weights is None else weights[sub]
    closest = _sample_closest_fn(nominal)
    options = icp_mod.ICPOptions(max_iter=30)
    # The PCA start's translation is off by the measured centroid's sampling error, which
    # along the long axis is sqrt(lambda_1 / n) (0.4 mm on a 100 mm vane at 5,000 points). A
    # surface that alone fixes a direction (a vane's end caps fix its span position) may hold
    # a few per cent of the points: the robust weight, scaled by the noise of the many others,
    # would reject it from the first iteration and leave that direction where PCA put it. So
    # each candidate is first drawn in with full weight for every point within
    # CAPTURE_STANDARD_ERRORS such errors (and without the defect test, which would reject
    # that surface as one coherent deviation), then refined robustly.
    capture_mm = CAPTURE_STANDARD_ERRORS * np.sqrt(axes_m.eigenvalues[0] / len(pca_source))
    capture = icp_mod.ICPOptions(max_iter=CAPTURE_ITERATIONS, defect_neighbours=0,
                                 min_scale=max(capture_mm / options.k_full, options.min_scale))

    def refine(T, capture_first=True):
        if capture_first:
            T = icp_mod.icp(pts, w, closest, T, capture).transform
        fit = icp_mod.icp(pts, w, closest, T, options)
        # The median |residual| over the subsample only steers the local search below; the
        # candidates are ranked by the common objective.
        return float(np.median(np.abs(fit.distances))), fit.transform

    refined = []
    for i, T in enumerate(candidates):
        progress(0.7 * i / len(candidates), "coarse registration: candidate %d of %d"
                 % (i + 1, len(candidates)))
        refined.append(refine(T))

    # Poses closer than the ICP's rejection distance at every corner explain every point
    # alike and lead the fine stage to one optimum: rank one of them (the one of smallest
    # median) and record the others as the same pose.
    corners = nominal.bbox_corners
    same_pose_mm = options.k_zero * max(min(r[0] for r in refined) * MAD_TO_SIGMA,
                                        options.min_scale)
    distinct, same_as = [], {}
    for i in sorted(range(len(candidates)), key=lambda i: refined[i][0]):
        twin = next((j for j in distinct
                     if pose_distance(refined[i][1], refined[j][1], corners)
                     < same_pose_mm), None)
        if twin is None:
            distinct.append(i)
        else:
            same_as[i] = twin

    # A pose with more than half of its points beyond that rejection distance (median above
    # it) cannot be the best nor a credible rival of a pose within the noise: it loses on at
    # least half of the points by the largest loss there is. Only the others cost an exact
    # distance evaluation (those of far-off poses are the slowest, OCC decides many).
    screened = {i for i in distinct if refined[i][0] > same_pose_mm}
    ranked = [i for i in distinct if i not in screened]
    progress(0.75, "coarse registration: ranking %d distinct poses" % len(ranked))
    rank_idx = _subsample(len(measured_xyz), RANKING_POINTS, rng)
    rank_xyz = measured_xyz[rank_idx]
    rank_snr = None if weights is None else weights[rank_idx]

    def standardised(T):
        dist = nominal.signed_distance(tf.apply_transform(T, rank_xyz)).distance
        return ranking.standardised(dist, rank_snr)

    poses = {i: refined[i][1] for i in ranked}
    residuals = {i: standardised(poses[i]) for i in ranked}
    best_i = _best_ranked(residuals)[0]

    score = refined[best_i][0]
    search = {"start_median_mm": score, "tried": 0, "rounds": 0}
    if score > SEARCH_MEDIAN_MM:
        # A sparse scan (few sections on a nearly helical blade) can leave the right candidate
        # in a neighbouring minimum that is far above the sensor's noise: look around it.
        best_pose = poses[best_i]
        for round_ in range(SEARCH_ROUNDS):
            progress(0.8 + 0.2 * round_ / SEARCH_ROUNDS, "coarse registration: local search")
            improved = False
            for step in _search_steps(axes_n):
                # Steps from a pose already drawn in: the robust refinement alone.
                s, T = refine(step @ best_pose, capture_first=False)
                search["tried"] += 1
                if s < 0.8 * score:
                    score, best_pose, improved = s, T, True
            search["rounds"] = round_ + 1
            if not improved or score <= SEARCH_MEDIAN_MM:
                break
        if search["tried"] and best_pose is not poses[best_i]:
            poses[best_i] = best_pose
            residuals[best_i] = standardised(best_pose)
    search["final_median_mm"] = score

    best_i, scale, losses, objectives = _best_ranked(residuals)
    rival = None
    others = [i for i in ranked if i != best_i
              and pose_distance(poses[i], poses[best_i], corners) >= same_pose_mm]
    if others:
        rival_i = min(others, key=lambda i: objectives[i])
        test = ranking.compare(losses[best_i], losses[rival_i])
        rival = {"candidate": int(rival_i),
                 "measured_to_cad": poses[rival_i].tolist(),
                 "pca_measured_to_cad": candidates[rival_i].tolist(),
                 "objective": objectives[rival_i],
                 "objective_difference": test.difference,
                 "standard_error": test.standard_error,
                 "z": test.z,
                 "decided": test.decided,
                 "distance_mm": pose_distance(poses[rival_i], poses[best_i], corners)}
    ambiguity = None
    if rival is not None and not rival["decided"]:
        ambiguity = ("coarse pose ambiguous: candidate %d and candidate %d, %.3g mm apart at "
                     "the worst corner, fit the points equally well (Vuong z = %.2f < %.1f: "
                     "objective %.1f vs %.1f, difference %.1f +- %.1f); the part may be "
                     "symmetric - check the pose before using the result"
                     % (best_i, rival["candidate"], rival["distance_mm"], rival["z"],
                        ranking.DECIDED_Z, objectives[best_i], rival["objective"],
                        rival["objective_difference"], rival["standard_error"]))
    warning = "; ".join(w for w in (ambiguity, axes_warning) if w) or None
    return {
        "measured_to_cad": poses[best_i],
        "pca_measured_to_cad": candidates[best_i],
        "eigenvalues": {"measured": axes_m.eigenvalues.tolist(),
                        "nominal": axes_n.eigenvalues.tolist()},
        "candidates": [{"measured_to_cad": T.tolist(),
                        "refined_to_cad": poses.get(i, refined[i][1]).tolist(),
                        "residual_mm": refined[i][0],
                        "objective": objectives.get(i),
                        "same_pose_as": same_as.get(i),
                        "screened": i in screened}
                       for i, T in enumerate(candidates)],
        "chosen": int(best_i),
        "ranking": {"objective": "sum over the points of the fine ICP's robust loss at one "
                                 "noise scale for every candidate (core.ranking)",
                    "scale_mm": scale, "n_points": int(len(rank_idx)),
                    "decided_z": ranking.DECIDED_Z, "same_pose_mm": same_pose_mm},
        "rival": rival,
        "ambiguous": ambiguity is not None,
        "local_search": search,
        "warning": warning,
    }


def pose_distance(a_to_cad, b_to_cad, corners):
    """How far apart two measured -> CAD poses put the part: the largest displacement of a
    corner of the CAD's bounding box between them (mm)."""
    return tf.corner_displacement(a_to_cad @ tf.invert_transform(b_to_cad), np.eye(4), corners)


def _best_ranked(residuals):
    """(best candidate, common scale, per-point losses, objectives) of candidates' standardised
    residuals {index: (n,)}, all on the same points."""
    keys = list(residuals)
    scale, losses, objectives = ranking.rank([residuals[k] for k in keys])
    losses, objectives = dict(zip(keys, losses)), dict(zip(keys, objectives))
    return min(keys, key=lambda k: objectives[k]), scale, losses, objectives


def _search_steps(axes):
    """Small rigid moves about the nominal's centroid: shifts along and turns about each
    principal axis, in both directions."""
    c = axes.centroid
    for k in range(3):
        a = axes.axes[:, k]
        for d in SEARCH_SHIFTS_MM:
            yield tf.make_transform(np.eye(3), d * a)
        for ang in SEARCH_TURNS_DEG:
            R = tf.rotation_from_vector(np.radians(ang) * a)
            yield tf.make_transform(R, c - R @ c)


# ---------------------------------------------------------------- fine

class TrackedDistance:
    """An ICP closest_fn over one fixed set of points (rows in the same order at every call):
    each call is warm-started from the previous one (core.closest.FootStart), which saves
    work - the distances are the exact ones, as exact_closest_fn's. ``start`` is the
    FootStart of the next call (None: cold)."""

    def __init__(self, nominal, start=None):
        self.nominal = nominal
        self.start = start
        self.result = None   # the last call's DistanceResult

    def __call__(self, points):
        res = self.nominal.signed_distance(points, self.start)
        self.start = FootStart.of(points, res)
        self.result = res
        return res.closest, res.normal, res.distance


def final_distances(fit, tracked):
    """The DistanceResult at the fit's pose of the fine ICP's last level, which ran on every
    point through ``tracked`` (a TrackedDistance): its residuals, foot points and normals are
    that closest-point evaluation's at the final pose, or follow from it to first order in a
    last step below LINEAR_UPDATE_MM / LINEAR_UPDATE_RAD (core.icp); the faces are the
    evaluation's."""
    last = tracked.result
    return dataclasses.replace(last, closest=fit.closest, normal=fit.normals,
                               distance=fit.distances)


def fine_register(measured_xyz, snr, nominal, init, rng=None, progress=_no_progress,
                  weight_model=None, **settings):
    """SNR-weighted ICP (paper 3.2) against the exact CAD faces: converged on a subsample, then
    finished with Gauss-Newton steps on every point so the pose carries the whole cloud's
    information (and its covariance is the whole cloud's). ``settings``: the fields of
    inspection.run_options.FineOptions (time_limit_s, full_distance, systematic_mm; absent or
    None: FINE_TIME_LIMIT_S, a TrackedDistance of its own, the default sensor's accuracy).
    Both runs together get ``time_limit_s``; an InputError says so when it is spent.
    ``weight_model``: core.icp's (inspection.weighting; None: the SNR weights). ``full_distance``: the TrackedDistance of
    all the points to use (so that the caller can start its deviations from the fit's last
    foot points), or None. ``systematic_mm``: the sensor's stated accuracy (the default
    sensor's, as the uncertainty model's systematic term); with the sensor weights' beams,
    core.icp's defect test grants each neighbourhood the field a bias of that size leaves
    after the fit (the sensor's own error, not a defect's flank: docs/maintainers.md)."""
    settings = FineOptions(**settings)
    time_limit_s = (FINE_TIME_LIMIT_S if settings.time_limit_s is None
                    else settings.time_limit_s)
    systematic_mm = (checks.SENSOR_ACCURACY_MM if settings.systematic_mm is None
                     else settings.systematic_mm)
    rng = np.random.default_rng(1) if rng is None else rng
    full_distance = settings.full_distance or TrackedDistance(nominal)
    deadline = time.monotonic() + time_limit_s

    def remaining():
        return max(deadline - time.monotonic(), 0.0)

    def fit_level(rows, options):
        """ICP on measured rows ``rows`` from T, warm-started from and feeding back into
        full_distance's starts of those rows."""
        distance = TrackedDistance(nominal, full_distance.start.take(rows))
        fit = icp_mod.icp(measured_xyz[rows], None if snr is None else snr[rows], distance, T,
                          options, weight_model=_weights_of_rows(weight_model, rows))
        _check_time(fit, time_limit_s)
        full_distance.start.set_rows(rows, distance.start)
        return fit.transform
    T = init
    n = len(measured_xyz)
    if n > FINE_SUBSAMPLE:
        sub = _subsample(n, FINE_SUBSAMPLE, rng)
        first = sub[_subsample(len(sub), FINE_FIRST_SUBSAMPLE, rng)]
        full_distance.start = FootStart.none(n)
        progress(0.1, "fine registration on %d of %d points" % (len(first), n))
        T = fit_level(first, icp_mod.ICPOptions(systematic_mm=systematic_mm,
                                                time_limit_s=remaining()))
        progress(0.3, "fine registration on %d of %d points" % (len(sub), n))
        T = fit_level(sub, icp_mod.ICPOptions(horn_iters=0, max_iter=SUBSAMPLE_STEPS,
                                              systematic_mm=systematic_mm,
                                              linear_update_mm=np.inf, linear_update_rad=np.inf,
                                              time_limit_s=remaining()))
        options = icp_mod.ICPOptions(max_iter=FULL_CLOUD_STEPS, horn_iters=0,
                                     systematic_mm=systematic_mm,
                                     uncertainty_fraction=FULL_CLOUD_UNCERTAINTY_FRACTION,
                                     linear_update_mm=LINEAR_UPDATE_MM,
                                     linear_update_rad=LINEAR_UPDATE_RAD,
                                     time_limit_s=remaining())
    else:
        options = icp_mod.ICPOptions(linear_update_mm=LINEAR_UPDATE_MM,
                                     systematic_mm=systematic_mm,
                                     linear_update_rad=LINEAR_UPDATE_RAD,
                                     time_limit_s=remaining())
    progress(0.6, "fine registration on all %d points" % n)
    fit = icp_mod.icp(measured_xyz, snr, full_distance, T, options, weight_model=weight_model)
    _check_time(fit, time_limit_s)
    return fit


def _weights_of_rows(weight_model, rows):
    """The weight model of the measured rows ``rows`` (None: the SNR weights)."""
    return None if weight_model is None else weight_model.subset(rows)


def _with_deadline(progress, limit_s, what):
    """``progress`` that raises an InputError once ``limit_s`` has passed since it was made."""
    deadline = time.monotonic() + limit_s

    def report(fraction, message):
        if time.monotonic() > deadline:
            raise InputError("%s: stopped at its %g s time limit (%s) - the points do not "
                             "settle on this CAD" % (what, limit_s, message))
        progress(fraction, message)
    return report


def _check_time(fit, time_limit_s):
    if fit.stopped:
        raise InputError("fine registration: stopped after %d iterations at its %g s time "
                         "limit without converging - the points do not settle on this CAD"
                         % (fit.iterations, time_limit_s))


# ---------------------------------------------------------------- the whole registration

def register(nominal, pointset, seed=0, progress=None, options=None, rig_kinematics=None,
             use_reconstruction=True, **choices):
    """Register a measured point set to the nominal with no knowledge of its pose.

    ``options``: inspection.run_options.RegisterOptions (None: its defaults), its fields also
    taken as keywords (``choices``, which replace them). Refused (InputError) before any
    fitting when the points are too degenerate to fix a pose or do not match the CAD's size,
    and after it when they do not fit the CAD (see inspection.checks; ``allow_mismatch`` keeps
    the result with a warning instead, and ``tolerance`` is the profile tolerance the fit rule
    allows). ``cad_source`` names the CAD in those messages. ``fit_choice``: an
    inspection.fitting.FitChoice applied after the ICP. ``weights``: the fine fit's, "snr",
    "sensor" or None for the default (inspection.weighting; None also takes
    ``fit_choice.weights``); ``rig_kinematics`` turns the sensor weights' beams back (default
    the nominal rig's)."""
    options = dataclasses.replace(options or RegisterOptions(), **choices)
    tolerance, fit_choice = options.tolerance, options.fit_choice
    progress = progress or _no_progress
    timing = {}
    xyz = _check_points(pointset)
    source = pointset.source or "points"
    cad_label = options.cad_source or "the CAD"
    checks.check_spread(xyz, source, coincide_only=True)
    extent_ratio = checks.check_scale(xyz, nominal, source, cad_label)
    checks.check_spread(xyz, source)
    snr = None if pointset.snr is None else np.asarray(pointset.snr, dtype=float)
    weight_model, weights_record = _weight_model(pointset, options, rig_kinematics)
    rng = np.random.default_rng(seed)
    # A CAD face whose outside could not be decided signs its deviations by a guess: say so.
    warnings = list(nominal.face_side_warnings)

    pca_points = None
    t0 = time.perf_counter()
    if use_reconstruction and "section" in pointset.columns and "angle_deg" in pointset.columns:
        progress(0.02, "reconstructing section curves and surfaces")
        from ..cad.loft import reconstruct   # cad/ needs FreeCAD; inspection/ does not
        try:
            recon = reconstruct(pointset)
        except InputError as exc:
            recon = None
            warnings.append("reconstruction skipped: %s" % exc)
        if recon is not None and len(recon.samples) >= MIN_POINTS:
            pca_points = recon.samples
    timing["reconstruction"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    coarse = coarse_register(xyz, snr, nominal, pca_points=pca_points, rng=rng,
                             progress=_with_deadline(
                                 lambda f, m: progress(0.05 + 0.25 * f, m),
                                 COARSE_TIME_LIMIT_S, "%s: against %s: coarse registration"
                                 % (source, cad_label)))
    timing["coarse"] = time.perf_counter() - t0
    if coarse["warning"]:
        warnings.append(coarse["warning"])

    t0 = time.perf_counter()
    full_distance = TrackedDistance(nominal)
    try:
        fit = fine_register(xyz, snr, nominal, coarse["measured_to_cad"], rng=rng,
                            progress=lambda f, m: progress(0.3 + 0.6 * f, m),
                            weight_model=weight_model, full_distance=full_distance)
    except InputError as exc:
        raise InputError("%s: against %s: %s" % (source, cad_label, exc)) from None
    timing["fine"] = time.perf_counter() - t0
    if not fit.converged:
        warnings.append("fine registration: not converged after %d iterations"
                        % fit.iterations)

    t0 = time.perf_counter()
    progress(0.92, "signed deviations of %d points" % len(xyz))
    points_cad = tf.apply_transform(fit.transform, xyz)
    dist = final_distances(fit, full_distance)
    stats = stats_mod.deviation_statistics(dist.distance)
    inlier = np.asarray(fit.inlier, dtype=bool)
    rms = float(np.sqrt(np.mean(dist.distance[inlier] ** 2))) if inlier.any() else float("nan")
    fit_record = checks.surface_fit(dist.distance, tolerance)
    fit_record["extent_ratio"] = extent_ratio
    if not fit_record["fits"]:
        message = checks.mismatch_message(fit_record, source, cad_label)
        if not options.allow_mismatch:
            raise InputError(message)
        fit_record["warning"] = message
        warnings.append(message)
    covariance, statistical, unmeasured = pose_summary(fit, nominal)
    if unmeasured:
        warnings.append(checks.unmeasured_warning(unmeasured))
    timing["deviations"] = time.perf_counter() - t0

    coarse_out = {
        "measured_to_cad": np.asarray(coarse["pca_measured_to_cad"]).tolist(),
        "refined_measured_to_cad": np.asarray(coarse["measured_to_cad"]).tolist(),
        "eigenvalues": coarse["eigenvalues"],
        "candidates": coarse["candidates"],
        "chosen": coarse["chosen"],
        "ranking": coarse["ranking"],
        "rival": coarse["rival"],
        "ambiguous": coarse["ambiguous"],
        "local_search": coarse["local_search"],
        "pca_source": "reconstruction" if pca_points is not None else "points",
        "warning": coarse["warning"],
    }
    uncertainty, includes_rival = uncertainty_with_rival(statistical, fit.transform, coarse_out,
                                                         nominal.bbox_corners)
    progress(1.0, "registered: RMS %.4f mm, pose uncertainty %.2f um"
             % (rms, uncertainty * 1000.0))
    result = RegistrationResult(
        measured_to_cad=fit.transform, points_cad=points_cad, deviation=dist.distance,
        inlier=inlier, closest=dist.closest, normal=dist.normal, face=dist.face, snr=snr,
        columns=dict(pointset.columns), n_rows_skipped=int(pointset.n_rows_skipped),
        rms_mm=rms, pose_covariance=covariance, center=fit.center,
        pose_uncertainty_mm=float(uncertainty), deviation_stats=stats, coarse=coarse_out,
        timing_s=timing, warnings=warnings, source=pointset.source, cad_faces=nominal.cad_faces,
        pose_unmeasured=unmeasured, surface_fit=fit_record,
        pose_uncertainty_statistical_mm=float(statistical),
        pose_uncertainty_includes_rival=includes_rival, icp_weights=fit.weights,
        inlier_cut=fit.cut)
    result.weights = weights_record
    _apply_fit_choice(result, nominal, fit_choice, tolerance)
    return result


def _weight_model(pointset, options, rig_kinematics):
    """(the fine fit's weight model, its record) for ``options.weights``, else the fit
    choice's (inspection.weighting)."""
    weights = options.weights
    if weights is None:
        weights = getattr(options.fit_choice, "weights", None)
    return weighting.weight_model_for(pointset, weights, kinematics=rig_kinematics)


def _apply_fit_choice(result, nominal, fit_choice, tolerance):
    """The result moved to the pose of ``fit_choice`` (inspection.fitting; None: the ICP's)."""
    if fit_choice is not None:
        from . import fitting
        fitting.apply(result, nominal, fit_choice, tolerance)


def pose_summary(fit, nominal):
    """(covariance, 1 sigma at the worst CAD corner, unmeasured directions) of an ICP fit: the
    covariance of the directions the points measure (core.icp.split_information) and the
    others named (inspection.checks.describe_unmeasured); the full covariance when all are."""
    split = fit.split
    if split is None:
        return fit.covariance, float("inf"), []
    uncertainty = icp_mod.pose_uncertainty(split.covariance, fit.center, nominal.bbox_corners)
    return split.covariance, float(uncertainty), checks.describe_unmeasured(split, nominal)


def uncertainty_with_rival(statistical_mm, measured_to_cad, coarse, corners):
    """The pose uncertainty to state, and whether it covers the coarse stage's rival.

    The statistical bound is the spread of the pose about the optimum the fine stage reached;
    when the coarse stage could not tell that optimum from a distinct rival (coarse["rival"]
    not decided), the pose is one of two places and the bound alone would state a confidence
    the data do not give. The stated uncertainty is then raised to the distance between the
    final pose and the rival at the worst corner of the CAD's bounding box, so the rival lies
    within it (the statistical bound stays in pose_uncertainty_statistical_mm); that distance
    is written into the rival's record as distance_from_final_mm."""
    rival = coarse.get("rival")
    if not rival or rival.get("decided", True):
        return float(statistical_mm), False
    distance = pose_distance(np.asarray(measured_to_cad),
                             np.asarray(rival["measured_to_cad"]), corners)
    rival["distance_from_final_mm"] = distance
    return float(max(statistical_mm, distance)), True


# ---------------------------------------------------------------- outputs

def freecad_version():
    try:
        import FreeCAD
        return ".".join(FreeCAD.Version()[:3])
    except ImportError:
        return None


def result_json(result, extra=None):
    """The result.json of docs/contracts.md, plus ``extra`` fields merged at the top level."""
    stats = dict(result.deviation_stats)
    doc = {
        "measured_to_cad": np.asarray(result.measured_to_cad).tolist(),
        "rms_mm": result.rms_mm,
        "n_points": result.n_points,
        "n_inliers": result.n_inliers,
        "n_rows_skipped": result.n_rows_skipped,
        "deviation": stats,
        "pose_covariance": np.asarray(result.pose_covariance).tolist(),
        "pose_covariance_center": np.asarray(result.center).tolist(),
        "pose_uncertainty_mm": result.pose_uncertainty_mm,
        "pose_uncertainty_statistical_mm": result.pose_uncertainty_statistical_mm,
        "pose_uncertainty_includes_rival": result.pose_uncertainty_includes_rival,
        "timing_s": result.timing_s,
        "software": {"name": NAME, "version": __version__, "FreeCAD version": freecad_version()},
        "coarse": result.coarse,
        "cad_faces": result.cad_faces,
        "warnings": result.warnings,
        "points_file": result.source,
        "cad_file": result.cad_source,
        "pose_unmeasured": list(result.pose_unmeasured),
        "surface_fit": result.surface_fit,
    }
    for name in ("fit", "fit_sensitivity", "weights"):   # inspection.fitting
        if getattr(result, name, None) is not None:
            doc[name] = getattr(result, name)
    if extra:
        doc.update(extra)
    return doc


def _write_deviations_csv(path, result):
    cols = [result.points_cad[:, 0], result.points_cad[:, 1], result.points_cad[:, 2],
            result.deviation]
    header = ["x", "y", "z", "deviation_mm", "snr", "inlier"]
    snr = result.snr if result.snr is not None else np.full(result.n_points, np.nan)
    # Byte matrices per column (core.csvtext): what "%.6f", "%.3f" and "%d" print, unformatted
    # one value at a time.
    text = [csvtext.fixed_matrix(c, 6) for c in cols] + [csvtext.fixed_matrix(snr, 3),
                                                          csvtext.integer_matrix(result.inlier)]
    for name, values in result.columns.items():
        values = np.asarray(values)
        if name in header or len(values) != result.n_points:
            continue
        header.append(name)
        if values.dtype.kind in "fc":
            text.append(csvtext.string_matrix(np.char.mod("%.6g", values)))
        else:
            text.append(csvtext.string_matrix(values.astype(str)))
    with open(path, "wb") as fh:
        fh.write((",".join(header) + "\n").encode("utf-8"))
        fh.write(csvtext.csv_rows(text))


class AtomicOutput:
    """Write a command's files into a private folder beside DIR and move them into DIR only when
    all of them are complete, so an error never leaves a half-written result."""

    def __init__(self, out_dir):
        checks.check_out_dir(out_dir)
        self.out_dir = os.path.abspath(out_dir)
        parent = os.path.dirname(self.out_dir)
        os.makedirs(parent, exist_ok=True)
        # The process id in the name lets ./bladeinspect remove the folder of a process that
        # crashed before it could discard it.
        self.tmp = tempfile.mkdtemp(prefix=".bladeinspect-%d-" % os.getpid(), dir=parent)

    def path(self, name):
        return os.path.join(self.tmp, name)

    def commit(self):
        os.makedirs(self.out_dir, exist_ok=True)
        # result.json last: a folder holding it is complete (a batch's test of a done file)
        for name in sorted(os.listdir(self.tmp), key=lambda name: name == "result.json"):
            os.replace(os.path.join(self.tmp, name), os.path.join(self.out_dir, name))
        shutil.rmtree(self.tmp, ignore_errors=True)

    def discard(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.commit()
        else:
            self.discard()
        return False


def write_register_outputs(out_dir, result, extra=None, output=None):
    """result.json and deviations.csv; into ``output`` (an open AtomicOutput) when the caller
    writes more files that must appear together, else atomically on their own."""
    def write(out):
        t0 = time.perf_counter()
        _write_deviations_csv(out.path("deviations.csv"), result)
        result.timing_s["write"] = time.perf_counter() - t0
        with open(out.path("result.json"), "w") as fh:
            json.dump(result_json(result, extra), fh, indent=1, default=json_default)
    if output is not None:
        write(output)
    else:
        with AtomicOutput(out_dir) as out:
            write(out)


def run_register(cad_path, points_path, out_dir, options=None, progress=None):
    """The `register` command: load, register, write, with ``options``
    (inspection.run_options.RunOptions: its seed, flip_faces, allow_mismatch, fit_choice and
    tolerance). Returns the RegistrationResult."""
    options = options or RunOptions()
    checks.check_out_dir(out_dir)
    t0 = time.perf_counter()
    nominal = load_nominal(cad_path, flip_faces=options.flip_faces)
    t_cad = time.perf_counter() - t0
    t0 = time.perf_counter()
    points = load_points(points_path)
    t_pts = time.perf_counter() - t0
    result = register(nominal, points, seed=options.seed, progress=progress,
                      options=RegisterOptions(allow_mismatch=options.allow_mismatch,
                                              cad_source=cad_path or "the demo blade",
                                              fit_choice=options.fit_choice,
                                              tolerance=options.tolerance))
    result.timing_s = dict(load_cad=t_cad, load_points=t_pts, **result.timing_s)
    result.cad_source = cad_path or "built-in demo blade"
    write_register_outputs(out_dir, result)
    return result
