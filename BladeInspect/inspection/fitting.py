"""The fit objective chosen on the command line (--fit, --free, --weights-by-zone,
--decision-rule), applied after the robust least-squares ICP, and the fit-sensitivity table.

Every fit starts from the ICP's pose and judges the ICP's inliers with its weights (core.fits,
"Which points"); only the pose changes. The default (least squares, all six degrees of
freedom, no region weights) is the ICP's pose itself, unchanged.

Zones of the whole blade (for --weights-by-zone): each point is labelled by its foot point on
the CAD (its closest CAD point) in the chord frame of the nominal profile cut at the nearest of
the planes at ZONE_HEIGHTS_PCT of the span (inspection.sections.classify: LE / TE within the
section table's edge fraction of the chord from either end, else suction or pressure by the
nearer profile half). Points nearer no profile (beyond the blade's ends) have no zone and
weight 1.
"""

import dataclasses
import time
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..core import background
from ..core import decision as decision_mod
from ..core import fits
from ..core import stats as stats_mod
from ..core import transforms as tf
from ..core.errors import InputError
from . import characteristic_names
from .closest_fn import exact_closest_fn
from . import sections as sections_mod
from . import weighting

ENGINE_AXIS = (1.0, 0.0, 0.0)        # CAD +X: the engine axis of a blade modelled along Z
# Every tenth of the span: one OCC cut each (about 0.2-0.5 s); the chord turns by a tenth of
# the blade's twist between planes, which moves an LE/TE zone border by a fraction of a mm.
ZONE_HEIGHTS_PCT = tuple(np.arange(5.0, 100.0, 10.0))
DEFAULT_OBJECTIVE = "least-squares"
DATUM = "datum"
SIZE = fits.SIZE_OBJECTIVE
# SIZE after DATUM: a saved document's Fit enumeration keeps its earlier entries' places
OBJECTIVE_NAMES = fits.OBJECTIVES + (DATUM, SIZE)
LEAST_SQUARES_NAMES = ("least-squares", SIZE)
DATUM_ROLES = ("datum_primary", "datum_secondary", "datum_tertiary")


@dataclass
class FitChoice:
    """What the user chose: the objective, the free degrees of freedom (text of --free, None
    for all six), region weights (text of --weights-by-zone), the decision rule; ``weights``
    the fine ICP's weight model (--weights snr|sensor, None the default: inspection.weighting),
    whose weights the fits start from (region weights multiply them)."""
    objective: str = DEFAULT_OBJECTIVE
    free: Optional[str] = None
    weights_by_zone: Optional[str] = None
    decision_rule: str = "iso14253"
    engine_axis: tuple = ENGINE_AXIS
    datum_faces: Optional[str] = None
    weights: Optional[str] = None   # inspection.weighting

    def __post_init__(self):
        # Checked before anything is measured or written: a typo must not cost a scan.
        if self.objective not in OBJECTIVE_NAMES:
            raise InputError("--fit: unknown objective '%s' (use %s)"
                             % (self.objective, ", ".join(OBJECTIVE_NAMES)))
        if self.datum_faces is not None and self.objective != DATUM:
            raise InputError("--datum-faces: for --fit datum only")
        if self.objective == DATUM and self.free is not None:
            raise InputError("--free: a datum reference frame fixes all six degrees of freedom")
        if self.datum_faces is not None and len(self.datum_faces.split(",")) != 3:
            raise InputError("--datum-faces: '%s' is not three faces (primary,secondary,"
                             "tertiary, by index or name)" % self.datum_faces)
        if self.decision_rule not in decision_mod.RULES:
            raise InputError("--decision-rule: unknown rule '%s' (use %s)"
                             % (self.decision_rule, ", ".join(decision_mod.RULES)))
        weighting.check_choice(self.weights)
        if self.free is not None:
            fits.parse_free(self.free, _axes((0.0, 0.0, 1.0), self.engine_axis))
        if self.weights_by_zone is not None:
            if self.objective not in LEAST_SQUARES_NAMES:
                raise InputError("--weights-by-zone: region weights apply to --fit "
                                 "least-squares or %s only, not to %s"
                                 % (SIZE, self.objective))
            self.zone_weights()

    def zone_weights(self):
        if self.weights_by_zone is None:
            return None
        return fits.parse_zone_weights(self.weights_by_zone, zones=sections_mod.ZONES)

    @property
    def is_icp(self):
        """The ICP's own pose: nothing to refit."""
        return (self.objective == "least-squares" and self.free is None
                and self.weights_by_zone is None)

    def to_json(self):
        doc = {"objective": self.objective, "free": self.free or "all",
               "weights_by_zone": self.zone_weights(), "decision_rule": self.decision_rule,
               "engine_axis": list(self.engine_axis)}
        if self.objective == DATUM:
            doc["datum_faces"] = self.datum_faces or ",".join(DATUM_ROLES)
        return doc


def add_arguments(parser):
    """--fit, --free, --weights-by-zone, --decision-rule and --weights on a subcommand."""
    parser.add_argument("--fit", default=DEFAULT_OBJECTIVE, choices=OBJECTIVE_NAMES,
                        help="fit objective after the robust least-squares ICP "
                             "(default least-squares: the ICP's pose; %s: least squares "
                             "with a uniform normal offset, reported as the part's size "
                             "deviation, that no longer moves the pose)" % SIZE)
    parser.add_argument("--datum-faces", default=None,
                        help="--fit datum: primary,secondary,tertiary CAD faces by index or "
                             "role name (default the CAD's datum_primary,datum_secondary,"
                             "datum_tertiary)")
    parser.add_argument("--free", default=None,
                        help="free degrees of freedom, any of tx,ty,tz,rx,ry,rz and "
                             "t_stacking,r_stacking,t_engine,r_engine (default all six)")
    parser.add_argument("--weights-by-zone", default=None,
                        help="least-squares region weights, e.g. LE=2,TE=2,suction=1,pressure=1")
    parser.add_argument("--decision-rule", default="iso14253", choices=decision_mod.RULES,
                        help="iso14253 (pass / not proven / fail, the default) or simple "
                             "(simple acceptance)")
    parser.add_argument("--weights", default=None, choices=weighting.WEIGHT_MODELS,
                        help="the fine fit's weights: snr (the paper's, SNR-linear) or sensor "
                             "(the sensor model's 1/(sigma_beam cos incidence)^2, needs "
                             "angle_deg); default: %s" % weighting.DEFAULT_RULE)


def from_args(args):
    return FitChoice(objective=args.fit, free=args.free, weights_by_zone=args.weights_by_zone,
                     decision_rule=args.decision_rule, datum_faces=args.datum_faces,
                     weights=getattr(args, "weights", None))


def _axes(stacking, engine):
    return {"stacking": np.asarray(stacking, dtype=float),
            "engine": np.asarray(engine, dtype=float)}


def free_of(choice, nominal):
    """The FreeDOF of the choice on this CAD (its stacking axis from sections.span_axis_of)."""
    if choice.free is None:
        return None
    axis, _ = sections_mod.span_axis_of(nominal)
    return fits.parse_free(choice.free, _axes(axis, choice.engine_axis))


def zones_of(result, nominal, edge_fraction=sections_mod.EDGE_FRACTION):
    """(N,) zone label of every point (module notes: foot point, nearest profile in span)."""
    from ..cad.sections import cut
    axis, (lo, hi) = sections_mod.span_axis_of(nominal)
    foot = np.asarray(result.closest, dtype=float)
    span = foot @ axis
    heights = lo + (hi - lo) * np.asarray(ZONE_HEIGHTS_PCT) / 100.0
    nearest = np.argmin(np.abs(span[:, None] - heights[None, :]), axis=1)
    labels = np.full(len(foot), "", dtype=object)
    inside = (span >= lo) & (span <= hi)
    for k, h in enumerate(heights):
        sel = np.flatnonzero(inside & (nearest == k))
        if not len(sel):
            continue
        origin = axis * h
        try:
            polylines = cut(nominal.shape, origin, axis)
        except InputError:
            continue
        profile = sections_mod.build_profile(nominal, polylines, axis, foot[sel], origin)
        labels[sel] = sections_mod.classify(profile, foot[sel], edge_fraction)
    return labels


def fit_weights(result):
    """The ICP's weights of the result's points (SNR x robust), or where the result does not
    carry them (a restricted view) the SNR of its inliers."""
    weights = getattr(result, "icp_weights", None)
    if weights is not None and len(weights) == result.n_points:
        return np.asarray(weights, dtype=float)
    snr = np.ones(result.n_points) if result.snr is None else np.asarray(result.snr, float)
    return np.where(result.inlier, snr, 0.0)


@dataclass
class FitRuns:
    """The fits made from the ICP pose: {objective: core.fits.FitResult}, None for the ICP's
    own pose; the starting pose and deviations."""
    start: np.ndarray
    start_deviation: np.ndarray
    runs: dict
    zone_labels: Optional[np.ndarray]
    seconds: dict


def datum_groups(choice, nominal):
    """[(name, face indices)] of the primary, secondary and tertiary datum faces."""
    tokens = [t.strip() for t in (choice.datum_faces or ",".join(DATUM_ROLES)).split(",")]
    groups = []
    for token in tokens:
        if token.isdigit():
            index = int(token)
            if index >= len(nominal.faces):
                raise InputError("--datum-faces: face %d does not exist (the CAD has %d faces)"
                                 % (index, len(nominal.faces)))
            groups.append((token, [index]))
        elif token in nominal.roles:
            groups.append((token, list(nominal.roles[token])))
        else:
            raise InputError("--datum-faces: '%s' is neither a face index nor a face name of "
                             "this CAD (names: %s)" % (token, ", ".join(sorted(nominal.roles))
                                                       or "none"))
    return groups


@dataclass
class DatumRun:
    """A datum fit: the motion (CAD frame) and the planes it came from."""
    transform: np.ndarray
    planes: list
    distances: np.ndarray          # (N,) every point's deviation at this pose
    max_abs_deviation: float       # of the inliers, mm
    margin: Optional[float] = None

    def to_json(self):
        return {"objective": DATUM, "free": "datum reference frame (all six)",
                "cad_motion": np.asarray(self.transform).tolist(), "datums": self.planes}


def _datum_run(result, nominal, choice):
    from ..core import datum
    groups = datum_groups(choice, nominal)
    measured, cad, planes = [], [], []
    for order, (name, faces) in zip(datum.ORDER, groups):
        on_face = np.asarray(result.inlier, bool) & np.isin(result.face, faces)
        label = "--datum-faces: %s datum %s" % (order, name)
        measured.append(datum.plane_of(result.points_cad[on_face], label))
        cad.append(datum.plane_of(nominal.samples.xyz[np.isin(nominal.samples.face, faces)],
                                  label + " (CAD)"))
        planes.append({"order": order, "faces": faces, "name": name,
                       "n_points": measured[-1].n_points,
                       "flatness_rms_mm": measured[-1].rms_mm,
                       "cad_flatness_rms_mm": cad[-1].rms_mm})
    G = datum.datum_pose(measured, cad)
    distances = nominal.signed_distance(tf.apply_transform(G, result.points_cad)).distance
    inlier = np.asarray(result.inlier, bool)
    return DatumRun(transform=G, planes=planes, distances=distances,
                    max_abs_deviation=float(np.max(np.abs(distances[inlier]))))


def _run(objective, result, nominal, choice, tolerance, free, labels, closest):
    if objective == DATUM:
        return _datum_run(result, nominal, choice)
    if objective == "least-squares" and free is None and choice.weights_by_zone is None:
        return None
    weights = fit_weights(result)
    multipliers = None
    if objective in LEAST_SQUARES_NAMES and choice.weights_by_zone is not None:
        multipliers = fits.per_zone(labels, choice.zone_weights())
    lower = upper = None
    if objective == "tolerance":
        lower, upper = -float(tolerance), float(tolerance)
    # The points are already in the CAD frame at the ICP pose: the fit moves them from there.
    return fits.fit(objective, result.points_cad, closest, np.eye(4), weights, free=free,
                    multipliers=multipliers, lower=lower, upper=upper,
                    at_init=(np.asarray(result.deviation), np.asarray(result.normal)))


def _tolerance_of_minimax(minimax, tolerance):
    """The fit to the zone +-T from the minimax fit of the same points: the slack of a point is
    T - |d|, so the pose of largest smallest slack is the pose of least largest |d| and the
    margin is T - max |d| (exactly the same problem, solved once)."""
    margin = float(tolerance) - minimax.max_abs_deviation
    return dataclasses.replace(minimax, objective="tolerance", margin=margin,
                               fits=bool(margin >= 0))


def apply(result, nominal, choice, tolerance, all_objectives=False, progress=None,
          sensor=None):
    """Move ``result`` (in place) to the pose of the chosen fit and record it in result.fit;
    with ``all_objectives`` also fit every other objective from the same start, for
    sensitivity(). ``sensor``: the rig.sensor.SensorModel whose stated accuracy enters the
    size deviation's U (None: the default sensor). Returns the FitRuns."""
    choice = choice or FitChoice()
    progress = progress or (lambda f, m: None)
    free = free_of(choice, nominal)
    labels = zones_of(result, nominal) if choice.weights_by_zone is not None else None
    closest = exact_closest_fn(nominal)
    # The size fit among them: the sensitivity table then shows what a uniform size error the
    # other fits take up does to every judged value and airfoil characteristic.
    wanted = fits.OBJECTIVES + (SIZE,) if all_objectives else (choice.objective,)
    if choice.objective not in wanted:
        wanted = wanted + (choice.objective,)
    runs, seconds = {}, {}
    for objective in wanted:
        progress(0.0, "fit: %s" % objective)
        t0 = time.perf_counter()
        if objective == "tolerance" and runs.get("minimax") is not None:
            runs[objective] = _tolerance_of_minimax(runs["minimax"], tolerance)
        else:
            runs[objective] = _run(objective, result, nominal, choice, tolerance, free,
                                   labels, closest)
        seconds[objective] = time.perf_counter() - t0
    out = FitRuns(start=np.asarray(result.measured_to_cad).copy(),
                  start_deviation=np.asarray(result.deviation).copy(), runs=runs,
                  zone_labels=labels, seconds=seconds)
    chosen = runs[choice.objective]
    record = dict(choice.to_json(), start="the robust least-squares ICP's pose and inliers",
                  tolerance_mm=float(tolerance), margin_mm=None, fits=None, violation_mm=None)
    if labels is not None:
        names, counts = np.unique(labels.astype(str), return_counts=True)
        record["zone_rule"] = ("foot point's chord position in the nominal profile at the "
                               "nearest of %d span planes" % len(ZONE_HEIGHTS_PCT))
        record["zone_counts"] = {(n or "none"): int(c) for n, c in zip(names, counts)}
    if chosen is None:
        record.update(max_abs_deviation_mm=float(np.max(np.abs(
            result.deviation[result.inlier]))) if result.inlier.any() else None,
            rms_mm=result.rms_mm, measured_to_cad=out.start.tolist())
    else:
        t0 = time.perf_counter()
        record.update(chosen.to_json())
        record["measured_to_cad_least_squares"] = out.start.tolist()
        _move(result, nominal, chosen)
        if "measured_to_cad" in record:   # core.fits' pose is the motion in the CAD frame
            record["cad_motion"] = record.pop("measured_to_cad")
        record["measured_to_cad"] = np.asarray(result.measured_to_cad).tolist()
        if choice.objective == DATUM:
            inlier = np.asarray(result.inlier, bool)
            record.update(max_abs_deviation_mm=float(np.max(np.abs(
                result.deviation[inlier]))), rms_mm=result.rms_mm)
        if choice.objective == SIZE:
            record["size_deviation"] = size_deviation(chosen, sensor)
            # The pose covariance the deviations' U propagates is the size fit's own: with
            # the offset free the screw along the span is determined by the form alone.
            _take_size_fit_covariance(result, nominal, chosen)
        seconds["deviations"] = time.perf_counter() - t0
    if choice.objective == "least-squares":
        record["size_take_up"] = size_take_up(result, free)
        if chosen is None and runs.get(SIZE) is not None:
            # the size fit from this very pose: the airfoil stage's take-up term reuses it
            result.size_fit_run = runs[SIZE]
    record["timing_s"] = seconds
    result.fit = record
    return out


K = 2.0   # coverage factor of the size deviation's U
SIZE_RULE = ("uniform offset of the surface along its normals fitted with the pose (--fit %s; "
             "+ is material added, the part oversize); U (k = 2) combines its least-squares "
             "standard deviation with the sensor's stated accuracy as a rectangular bias of "
             "every reading, taken whole: a reading bias reads as a size error, which the "
             "fit cannot tell apart" % SIZE)


def size_deviation(run, sensor=None):
    """result.json's fit.size_deviation of a size fit (core.fits.FitResult of SIZE): the
    offset with its U (k = 2); U null when the points do not determine it."""
    from ..rig.sensor import SensorModel
    accuracy = (sensor or SensorModel()).accuracy
    variance = run.size_variance
    statistical = float(np.sqrt(variance)) if np.isfinite(variance) else None
    systematic = float(accuracy / np.sqrt(3.0))
    U = (None if statistical is None
         else float(K * np.sqrt(statistical ** 2 + systematic ** 2)))
    return {"value_mm": float(run.size), "U_mm": U, "k": K,
            "u_statistical_mm": statistical, "u_systematic_mm": systematic, "rule": SIZE_RULE}


# The size error the take-up note gives its figures for (a typical profile tolerance's tenth).
TAKE_UP_EXAMPLE_MM = 0.02


def size_take_up(result, free=None):
    """The plain least-squares pose's take-up of a uniform size error, stated (result.json's
    fit.size_take_up): core.fits.size_take_up's r per mm of size about the inliers' weighted
    centroid (in the span of the free degrees of freedom ``free``), how far it moves the
    points and the deviations per mm of size (largest over the inliers, and the deviations'
    median), and a note with the figures at TAKE_UP_EXAMPLE_MM. Linearised: where the take-up
    slides points by tenths of a mm along the span, past the blade's ends, the real one is
    smaller but of that order. None with too few inliers."""
    weights = fit_weights(result)
    points = np.asarray(result.points_cad, dtype=float)
    normals = np.asarray(result.normal, dtype=float)
    usable = (weights > 0) & np.all(np.isfinite(normals), axis=1)
    if np.count_nonzero(usable) <= 7:
        return None
    w, p, n = weights[usable], points[usable], normals[usable]
    center = w @ p / w.sum()
    r = fits.size_take_up(p, n, w, center, free)
    motion = float(np.max(np.linalg.norm(r[:3] + np.cross(r[3:], p - center), axis=1)))
    change = np.abs(np.hstack([n, np.cross(p - center, n)]) @ r)
    deviation, median = float(np.max(change)), float(np.median(change))
    example = TAKE_UP_EXAMPLE_MM
    note = ("the least-squares pose takes up part of a uniform size error (to first order): "
            "%.3f mm of size would move the pose by up to %.3f mm at the points and change "
            "the deviations by %.4f mm (median) to %.4f mm, and the sizes measured across "
            "the blade (thickness, chord) with them; --fit %s (or a datum fit on a root "
            "block) keeps size out of the pose"
            % (example, example * motion, example * median, example * deviation, SIZE))
    return {"per_mm": {"t_mm": r[:3].tolist(), "w_rad": r[3:].tolist()},
            "center_mm": center.tolist(), "pose_motion_mm_per_mm": motion,
            "deviation_mm_per_mm": deviation, "deviation_median_mm_per_mm": median,
            "note": note}


def is_plain_rigid(result):
    """Whether ``result``'s pose is the plain rigid least-squares one (no size parameter, no
    datum, no minimax): the pose that takes up a uniform size error."""
    fit = getattr(result, "fit", None) or {}
    return fit.get("objective", DEFAULT_OBJECTIVE) == "least-squares"


def size_fit_from_pose(result, nominal):
    """core.fits' least-squares-size fit (its transform the motion in the CAD frame) from the
    result's present pose, inliers, weights and free degrees of freedom; None with too few
    inliers. The run apply() made from this pose is reused when there is one."""
    run = getattr(result, "size_fit_run", None)
    if run is not None:
        return run
    record = getattr(result, "fit", None) or {}
    text = record.get("free")
    choice = FitChoice(free=None if text in (None, "all") else text,
                       engine_axis=tuple(record.get("engine_axis") or ENGINE_AXIS))
    weights = fit_weights(result)
    if np.count_nonzero(weights > 0) <= 7:
        return None
    return fits.fit(SIZE, result.points_cad, exact_closest_fn(nominal), np.eye(4), weights,
                    free=free_of(choice, nominal),
                    at_init=(np.asarray(result.deviation), np.asarray(result.normal)))


def _take_size_fit_covariance(result, nominal, run):
    """The result's pose covariance, and the pose uncertainty it states, the size fit's."""
    from ..core import icp
    result.pose_covariance = np.asarray(run.covariance, dtype=float)
    result.center = np.asarray(run.center, dtype=float)
    statistical = float(icp.pose_uncertainty(result.pose_covariance, result.center,
                                             nominal.bbox_corners))
    stated = statistical
    if getattr(result, "pose_uncertainty_includes_rival", False):
        # the rival's distance, which the ICP's stated figure covered, stays covered
        stated = max(statistical, float(result.pose_uncertainty_mm))
    result.pose_uncertainty_statistical_mm = statistical
    result.pose_uncertainty_mm = stated


def _move(result, nominal, chosen):
    """The result at the fit's pose: new points, deviations, closest points, statistics."""
    result.measured_to_cad = chosen.transform @ np.asarray(result.measured_to_cad)
    result.points_cad = tf.apply_transform(chosen.transform, result.points_cad)
    dist = nominal.signed_distance(result.points_cad)
    result.deviation, result.closest = dist.distance, dist.closest
    result.normal, result.face = dist.normal, dist.face
    result.deviation_stats = stats_mod.deviation_statistics(dist.distance)
    inlier = np.asarray(result.inlier, dtype=bool)
    result.rms_mm = float(np.sqrt(np.mean(dist.distance[inlier] ** 2))) if inlier.any() \
        else float("nan")


# ---------------------------------------------------------------- sensitivity

def section_worst_characteristics(verdict):
    """Judged values of a verdict (inspection.verdict.judge): each section's worst deviation
    and the part's, as [(name, value mm, U mm, verdict)]."""
    rows = []
    for sec in verdict["sections"]:
        if "worst_deviation_mm" in sec:
            rows.append(("section %s worst deviation" % sec["label"], sec["worst_deviation_mm"],
                         sec.get("U_mm"), sec.get("verdict")))
    part = verdict.get("part")
    if part:
        rows.append(("part worst deviation", part["worst_deviation_mm"], part["U_mm"],
                     part["verdict"]))
    return rows


CHARACTERISTICS = (section_worst_characteristics,)
# After a change whose worst deviation changes side between the objectives.
SIDE_MARK = " *"
SIDE_NOTE = ("* the worst deviation is + under one objective and - under another; the change "
             "is of its size, which the verdict judges against +-T")
CHANGE_RULE = ("worst deviation rows: largest minus smallest |worst deviation| over the "
               "objectives (its size is what the verdict judges against +-T); side_changes: "
               "it is + under one objective and - under another. Airfoil rows: largest minus "
               "smallest deviation (the characteristic itself changed)")


def sensitivity(runs, result, table, tolerance, choice, judge_options=None,
                characteristics=CHARACTERISTICS):
    """fit_sensitivity: every judged value and the part's verdict under each fit objective,
    side by side, from the same start and points. ``characteristics``: callables
    verdict -> [(name, value, U, verdict)] (each section's and the part's worst deviation by
    default; more, such as airfoil characteristics, append to the list)."""
    from .verdict import judge
    t0 = time.perf_counter()
    judge_options = dict(judge_options or {}, decision_rule=choice.decision_rule)
    columns = {}
    for objective, run in runs.runs.items():
        background.tick()    # a GUI's event loop turns between the objectives' verdicts
        deviation = runs.start_deviation if run is None else run.distances
        view = dataclasses.replace(result, deviation=np.asarray(deviation))
        verdict = judge(view, table, tolerance=tolerance, **judge_options)
        values = [row for f in characteristics for row in f(verdict)]
        columns[objective] = {"verdict": verdict["verdict"], "values": values,
                              "max_abs_deviation_mm": None if run is None
                              else run.max_abs_deviation,
                              "margin_mm": None if run is None else run.margin}
    objectives = list(columns)
    names = [v[0] for v in columns[objectives[0]]["values"]]
    rows, largest = [], None
    for i, name in enumerate(names):
        cells = {o: {"value_mm": columns[o]["values"][i][1], "U_mm": columns[o]["values"][i][2],
                     "verdict": columns[o]["values"][i][3]} for o in objectives}
        values = [c["value_mm"] for c in cells.values()]
        # A worst deviation is judged by its size against +-T: +6 um under one fit and -6 um
        # under another leave the same margin, a change of 0, not 12 um. That the worst
        # point changes side (excess material under one fit, missing under another) is said
        # apart.
        sizes = [abs(v) for v in values]
        change = float(max(sizes) - min(sizes))
        rows.append({"characteristic": name, "by_fit": cells, "change_mm": change,
                     "side_changes": bool(min(values) < 0.0 < max(values))})
        if largest is None or change > largest["change_mm"]:
            largest = {"characteristic": name, "change_mm": change}
    verdicts = {o: columns[o]["verdict"] for o in objectives}
    # Each objective's motion of the points from the least-squares start (CAD frame), and the
    # chosen one's, so that later stages (the airfoil characteristics) can be re-measured
    # under every fit.
    motion = {o: (np.eye(4) if run is None else np.asarray(run.transform, float)).tolist()
              for o, run in runs.runs.items()}
    return {"objectives": objectives, "rows": rows, "verdict_by_fit": verdicts,
            "cad_motion_by_fit": motion, "chosen": choice.objective,
            "verdict_changes": len(set(verdicts.values())) > 1,
            "largest_change": largest,
            "change_rule": CHANGE_RULE,
            "free": choice.free or "all",
            "timing_s": dict(runs.seconds, judge=time.perf_counter() - t0)}


def report_rows(sensitivity_doc):
    """(header, rows) of the report's fit-sensitivity table: each row's characteristic by its
    display name (inspection.characteristic_names) and unit, then its value and verdict under
    each objective and its change."""
    names = characteristic_names
    objectives = sensitivity_doc["objectives"]
    definitions = sensitivity_doc.get("airfoil_definitions")
    header = ["Characteristic", "Unit"] + ["%s (verdict)" % o for o in objectives] + ["Change"]
    rows = []
    for row in sensitivity_doc["rows"]:
        # airfoil rows (inspection.airfoil_verdicts.add_to_sensitivity) carry value and unit
        _, key = names.sensitivity_row_parts(row)
        unit = names.unit(key) if key else "mm"
        value = [row["by_fit"][o].get("value_mm", row["by_fit"][o].get("value"))
                 for o in objectives]
        rows.append([names.sensitivity_row_name(row, values=definitions), unit] + [
            ("-" if v is None else "%+.4f %s" % (v, row["by_fit"][o]["verdict"] or ""))
            for v, o in zip(value, objectives)]
            + ["%.4f%s" % (row.get("change_mm", row.get("change")),
                           SIDE_MARK if row.get("side_changes") else "")])
    rows.append([names.PART_VERDICT, ""] + [sensitivity_doc["verdict_by_fit"][o] or ""
                                            for o in objectives] + [""])
    return header, rows
