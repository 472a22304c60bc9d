"""Section curves and lofted surfaces from measured section passes (paper 3.1.2).

Each pass of the sensor over one side of one section gives points along a plane curve. They
are approximated by a cubic B-spline in the weighted least-squares sense, with the points'
curve parameters corrected towards their closest curve points. The knots start uniform and are
refined where the curve misses a point by more than FOLLOW_SIGMAS of that reading's noise, so
the curve follows every reading it keeps within that bound; readings are left out only as
isolated gross errors, by the rule of ``fit_section_pass``, and are reported. The curves of one
side, across the sections, are made compatible (same degree and knots, each reparametrised by
normalised arc length, refitted until within COMPATIBLE_TOLERANCE_MM of itself) and skinned:
their poles are interpolated across the sections, so each section curve is an iso-parametric
curve of the lofted surface.
"""
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline
from scipy.linalg import solveh_banded
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, minimum_spanning_tree, shortest_path
from scipy.spatial import cKDTree

import FreeCAD
import Part

from ..core import background
from ..core.errors import InputError

DEGREE = 3
MIN_GROUP_POINTS = 4
# Passes of one view share a rotary angle; views of a section are 90 degrees or more apart.
ANGLE_CLUSTER_GAP_DEG = 20.0
# Between neighbouring sections a view's angle follows the blade's twist, well below this.
ANGLE_TRACK_DEG = 60.0
PARAMETER_CORRECTIONS = 3
# Every reading kept lies within FOLLOW_SIGMAS of its noise from its curve: a uniform error's
# largest value is sqrt(3) sigma, a normal one's beyond 4 sigma once in 16000.
FOLLOW_SIGMAS = 4.0
# Below this the bound is the fit's own resolution, not the sensor's noise.
FOLLOW_FLOOR_MM = 0.002
# A reading (or two neighbouring readings) is a gross error only if the curve fitted without
# it passes its neighbours within their bounds and misses it by more than this many bounds;
# a smaller miss is the shape, and the knots are refined there instead.
GROSS_BOUNDS = 2.0
GROSS_RUN = 2
# Readings this near a pass's ends are never judged gross: a pass runs out onto an edge, whose
# turn the neighbours on one side cannot predict.
END_READINGS = 3
# More readings than this called gross means the curve, not the data, is at fault (a pass
# whose readings could not be put in order): none are left out then.
MAX_GROSS_FRACTION = 0.1
MAX_REFINE_ROUNDS = 16
# The sensor's SNR scale (0..100): sigma_beam = sigma_ref sqrt(SNR_REF / SNR) (rig.sensor).
SNR_REF = 100.0
SNR_FLOOR = 1.0
# The Gaussian |z|'s median: a robust scale from absolute deviations.
HALF_NORMAL_MEDIAN = 0.6744897501960817
COMPATIBLE_TOLERANCE_MM = 1e-4
# Curves of one side more different in length than this cover different parts of the blade.
MAX_LENGTH_RATIO = 1.5
SAMPLES_U = 160
SAMPLES_V_PER_SECTION = 8


@dataclass
class Reconstruction:
    curves: list             # Part.BSplineCurve, one per (section, side) group fitted
    surfaces: list           # Part.BSplineSurface, one per side seen on >= 2 sections
    samples: np.ndarray      # (M, 3) points of the surfaces (of the curves if none)
    fit_errors: list         # dicts: section, side, n_points, rms, max (mm), SectionFit.record
    groups: list             # dicts: section, side, angle_deg, n_points, curve index or None
    notes: list = field(default_factory=list)   # groups skipped and why
    # The sensor noise at SNR_REF the curves' bounds were scaled from (mm): measured from the
    # pseudo-residuals of every pass together, since the passes share one sensor.
    sigma_ref: float = None
    # dicts per surface: side, sections, max_gap_mm (largest distance from a reading kept to
    # its surface, at the reading's own section: the curve's miss plus the compatible refit's
    # stray), compatible_stray_mm.
    surface_errors: list = field(default_factory=list)


def uniform_knots(n_poles, degree=DEGREE):
    """Clamped uniform knot vector on [0, 1] (flat, with multiplicities)."""
    inner = np.linspace(0.0, 1.0, n_poles - degree + 1)
    return np.concatenate([np.zeros(degree), inner, np.ones(degree)])


def _least_squares_poles(params, points, knots, degree, weights=None):
    """Poles minimising the (weighted) squared residuals; a faint second-difference penalty
    keeps the system regular where a knot span holds no points. The normal equations of a
    B-spline are banded (degree off-diagonals), so they are solved in band form."""
    n_poles = len(knots) - degree - 1
    A = BSpline.design_matrix(np.clip(params, 0.0, 1.0), knots, degree)
    Aw = A if weights is None else A.multiply(np.asarray(weights)[:, None]).tocsr()
    normal = (A.T @ Aw).toarray()
    D = np.diff(np.eye(n_poles), 2, axis=0)
    ridge = 1e-9 * np.trace(normal) / n_poles
    normal += ridge * (D.T @ D)
    width = max(degree, 2)
    band = np.zeros((width + 1, n_poles))
    for k in range(width + 1):
        band[width - k, k:] = np.diagonal(normal, k)
    rhs = np.asarray(Aw.T @ points)
    try:
        return solveh_banded(band, rhs)
    except np.linalg.LinAlgError:
        # Not numerically positive definite (spans with no reading and the penalty's linear
        # null space): the least-norm solution.
        return np.linalg.lstsq(normal, rhs, rcond=None)[0]


def _closest_params(spline, points, params):
    """Newton steps on (C(t) - p) . C'(t) = 0 from ``params``, clamped to [0, 1]."""
    d1, d2 = spline.derivative(1), spline.derivative(2)
    t = params.copy()
    for _ in range(8):
        r = spline(t) - points
        c1, c2 = d1(t), d2(t)
        f = np.einsum("ij,ij->i", r, c1)
        fp = np.einsum("ij,ij->i", c1, c1) + np.einsum("ij,ij->i", r, c2)
        step = np.where(fp > 0, f / np.where(fp > 0, fp, 1.0), 0.0)
        t = np.clip(t - step, 0.0, 1.0)
        if np.max(np.abs(step)) < 1e-12:
            break
    return t


def order_points(points):
    """Indices ordering points along the curve they sample, and each point's distance from
    the curve's first end along the way (an arc length, noise zig-zags included).

    Walks a minimum spanning tree of near neighbours from one end of its longest path. Unlike
    sorting along the direction of largest extent this also orders passes that fold back, such
    as an edge view wrapping round a leading edge."""
    pts = np.asarray(points, dtype=float)
    n = len(pts)
    tree_index = cKDTree(pts)
    k = min(8, n - 1)
    while True:
        dist, nbr = tree_index.query(pts, k + 1)
        # csgraph reads a zero weight as "no edge": keep coincident points joined.
        graph = coo_matrix((dist[:, 1:].ravel() + 1e-12,
                            (np.repeat(np.arange(n), k), nbr[:, 1:].ravel())), shape=(n, n))
        if k >= n - 1 or connected_components(graph, directed=False)[0] == 1:
            break
        k = min(2 * k, n - 1)
    mst = minimum_spanning_tree(graph)
    first_end = int(np.argmax(shortest_path(mst, directed=False, indices=0)))
    along = shortest_path(mst, directed=False, indices=first_end)
    order = np.argsort(along, kind="stable")
    return order, along[order]


def _to_part_curve(knots, poles, degree):
    unique, mults = np.unique(np.round(knots, 14), return_counts=True)
    curve = Part.BSplineCurve()
    curve.buildFromPolesMultsKnots([FreeCAD.Vector(*p) for p in poles], mults.tolist(),
                                   unique.tolist(), False, degree)
    return curve


def _spline_of(curve):
    """scipy BSpline (parameter on [0, 1]) of a non-rational Part.BSplineCurve."""
    knots = np.repeat(curve.getKnots(), curve.getMultiplicities())
    lo, hi = knots[0], knots[-1]
    poles = np.array([tuple(p) for p in curve.getPoles()])
    return BSpline((knots - lo) / (hi - lo), poles, curve.Degree)


@dataclass
class SectionFit:
    """One pass's curve and how it follows the readings it was fitted to (mm). ``residuals``
    and ``bounds`` are per reading, in the order given; ``rejected`` marks the readings left
    out as gross errors; ``sigma_ref`` is the noise at SNR_REF the bounds were scaled from."""
    curve: object
    residuals: np.ndarray
    bounds: np.ndarray
    rejected: np.ndarray
    sigma_ref: float
    params: np.ndarray          # each reading's curve parameter on [0, 1]

    @property
    def kept(self):
        return ~self.rejected

    @property
    def rms(self):
        return float(np.sqrt(np.mean(self.residuals[self.kept] ** 2)))

    @property
    def max(self):
        return float(self.residuals[self.kept].max())

    @property
    def beyond_bound(self):
        """Readings kept but farther from the curve than their bound (refinement ran out)."""
        return int(np.count_nonzero(self.kept & (self.residuals > self.bounds)))

    def record(self):
        r = self.residuals
        return {"rms": self.rms, "max": self.max,
                "max_over_bound": float(np.max(r[self.kept] / self.bounds[self.kept])),
                "bound_max": float(self.bounds[self.kept].max()),
                "sigma_ref": self.sigma_ref, "n_poles": int(self.curve.NbPoles),
                "n_beyond_bound": self.beyond_bound,
                "n_rejected": int(self.rejected.sum()),
                "rejected_mm": sorted(float(v) for v in r[self.rejected])}


def noise_scale(snr, n):
    """Each reading's noise relative to SNR_REF's, sqrt(SNR_REF / SNR) (1 without SNR)."""
    if snr is None:
        return np.ones(n)
    snr = np.asarray(snr, dtype=float)
    return np.sqrt(SNR_REF / np.maximum(np.where(np.isfinite(snr), snr, SNR_FLOOR), SNR_FLOOR))


def pseudo_residuals(ordered, along, scale):
    """Each interior reading's miss from the cubic through its two neighbours on each side
    (Lagrange in arc length), across the chord, over that miss's noise in units of sigma_ref:
    a noise sample that does not depend on any fitted curve (a cubic's own error over four
    readings is far below the noise on a resolved pass, and the median ignores the few turns
    onto an edge that are not resolved)."""
    n = len(ordered)
    if n < 5:
        return np.zeros(0)
    i = np.arange(2, n - 2)
    nb = np.stack([i - 2, i - 1, i + 1, i + 2], axis=1)
    x, x0 = along[nb], along[i]
    w = np.ones_like(x)
    for j in range(4):
        for k in range(4):
            if k != j:
                w[:, j] *= (x0 - x[:, k]) / np.where(x[:, j] != x[:, k], x[:, j] - x[:, k], 1e-12)
    miss = ordered[i] - np.einsum("ij,ijk->ik", w, ordered[nb])
    chord = ordered[i + 1] - ordered[i - 1]
    chord /= np.maximum(np.linalg.norm(chord, axis=1), 1e-15)[:, None]
    across = np.linalg.norm(miss - np.einsum("ij,ij->i", miss, chord)[:, None] * chord, axis=1)
    spread = np.sqrt(scale[i] ** 2 + np.einsum("ij,ij->i", w ** 2, scale[nb] ** 2))
    return across / spread


def noise_sigma_ref(z):
    """sigma_ref from pseudo-residuals (robust: the median of |z|)."""
    z = np.asarray(z, dtype=float)
    return float(np.median(z) / HALF_NORMAL_MEDIAN) if len(z) else 0.0


def _fit_on_knots(params, points, weights, knots, degree, corrections=PARAMETER_CORRECTIONS):
    for _ in range(corrections):
        spline = BSpline(knots, _least_squares_poles(params, points, knots, degree, weights),
                         degree)
        params = _closest_params(spline, points, params)
    spline = BSpline(knots, _least_squares_poles(params, points, knots, degree, weights), degree)
    params = _closest_params(spline, points, params)
    return spline, params, np.linalg.norm(spline(params) - points, axis=1)


def _runs(mask):
    """(start, stop) of the runs of True in a boolean array."""
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)))


def _gross_readings(over, params, points, weights, knots, degree, residuals, bounds,
                    rejected):
    """Readings beyond their bound that the rule calls gross errors. Candidates are the peaks
    of residual / bound above GROSS_BOUNDS in the runs of readings beyond their bounds, at
    least END_READINGS from either end of the pass, each with its worse neighbour when that is
    above GROSS_BOUNDS too (GROSS_RUN readings at most). A candidate is gross if the curve
    fitted without the candidates misses it by more than GROSS_BOUNDS of its bound while
    passing the nearest readings kept on both sides within theirs (a spike pulls its
    neighbours off with it; a turn the knots do not resolve stays off)."""
    n = len(points)
    ratio = residuals / bounds
    peaks = []
    for a, b in _runs(over):
        for k in range(max(a, END_READINGS), min(b, n - END_READINGS)):
            if ratio[k] > GROSS_BOUNDS and ratio[k] >= ratio[k - 1] and ratio[k] > ratio[k + 1]:
                pair = max((k - 1, k + 1), key=lambda j: ratio[j])
                if GROSS_RUN > 1 and ratio[pair] > GROSS_BOUNDS and over[pair]:
                    peaks.append((min(k, pair), max(k, pair) + 1))
                else:
                    peaks.append((k, k + 1))
    gross = np.zeros(n, dtype=bool)
    if not peaks:
        return gross
    out = rejected.copy()
    for lo, hi in peaks:
        out[lo:hi] = True
    _, _, miss = _fit_on_knots(params, points, weights * ~out, knots, degree, corrections=1)
    kept = np.flatnonzero(~out)
    for lo, hi in peaks:
        sides = kept[np.clip(np.searchsorted(kept, [lo, hi]) - [1, 0], 0, len(kept) - 1)]
        if (np.all(miss[lo:hi] > GROSS_BOUNDS * bounds[lo:hi])
                and np.all(miss[sides] <= bounds[sides])):
            gross[lo:hi] = True
    return gross


def fit_section_pass(points, snr=None, sigma_ref=None, n_poles=None, degree=DEGREE):
    """A cubic B-spline through one section pass that follows every reading it keeps within
    FOLLOW_SIGMAS sigma_ref sqrt(SNR_REF / SNR) (at least FOLLOW_FLOOR_MM), as a SectionFit.

    ``points`` (K, 3), in any order, are ordered along the curve (see ``order_points``);
    parameters start as their normalised distance along it and are then corrected to the
    closest curve points. Readings weigh 1 / their noise squared. ``sigma_ref``: the sensor's
    noise at SNR_REF; by default measured from the pass's own pseudo-residuals.
    ``n_poles``: the starting uniform knots, by default K/10 within [degree + 3, 100] (ten
    readings a span keep the noise averaged). Where a reading is missed by more than its bound,
    the knot span holding it is halved and the curve refitted, until every reading is followed
    or the poles would outnumber the readings; isolated readings that a curve through their
    neighbours misses by more than GROSS_BOUNDS bounds are left out as gross errors
    (``_gross_readings``). The cause of a miss at a fixed knot count is the shape, not the
    noise: a pass's ends turn onto a leading or trailing edge that uniform spans cannot
    follow (0.1-0.5 mm at 1 mm point spacing)."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or not np.all(np.isfinite(pts)):
        raise InputError("section points: expected finite (K, 3) coordinates, got shape %s"
                         % (pts.shape,))
    if len(pts) < max(MIN_GROUP_POINTS, degree + 1):
        raise InputError("section points: %d points, at least %d needed for a cubic curve"
                         % (len(pts), max(MIN_GROUP_POINTS, degree + 1)))
    if n_poles is None:
        n_poles = int(np.clip(len(pts) // 10, degree + 3, 100))
    n_poles = int(min(n_poles, len(pts)))
    if n_poles < degree + 1:
        raise InputError("section curve: %d poles, at least %d needed" % (n_poles, degree + 1))
    scale = noise_scale(snr, len(pts))
    # A fixed starting order: the same points in any row order give the same curve.
    first = np.lexsort(pts.T[::-1])
    order, along = order_points(pts[first])
    if along[-1] <= 1e-9:
        raise InputError("section points: all %d points coincide" % len(pts))
    walk = first[order]
    if sigma_ref is None:
        sigma_ref = noise_sigma_ref(pseudo_residuals(pts[walk], along, scale[walk]))
    fit = _fit_walk(pts, scale, walk, along, sigma_ref, n_poles, degree)
    if fit.beyond_bound:
        # A pass folded round an edge thinner than its point spacing has no order that the
        # points alone give (near neighbours lie across the edge): the order the readings
        # were taken in, the rows', is tried then, and the better kept.
        rows = np.arange(len(pts))
        steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        if not np.array_equal(rows, walk) and not np.array_equal(rows, walk[::-1]) \
                and np.all(steps > 0):
            again = _fit_walk(pts, scale, rows, np.concatenate([[0.0], np.cumsum(steps)]),
                              sigma_ref, n_poles, degree)
            if (again.beyond_bound, again.max) < (fit.beyond_bound, fit.max):
                fit = again
    return fit


def _fit_walk(pts, scale, walk, along, sigma_ref, n_poles, degree):
    """fit_section_pass's refinement on the readings taken in the order ``walk`` (indices of
    ``pts``), ``along`` their distances along the way."""
    ordered, scale = pts[walk], scale[walk]
    bounds = np.maximum(FOLLOW_SIGMAS * sigma_ref * scale, FOLLOW_FLOOR_MM)
    weights = 1.0 / scale ** 2
    params = along / along[-1]
    knots = uniform_knots(n_poles, degree)
    rejected = np.zeros(len(ordered), dtype=bool)
    for round_ in range(MAX_REFINE_ROUNDS):
        background.tick()    # a GUI's event loop turns between the refinements
        spline, params, residuals = _fit_on_knots(params, ordered, weights * ~rejected, knots,
                                                  degree)
        if round_ == 0:
            params = (params - params.min()) / max(params.max() - params.min(), 1e-15)
        over = (residuals > bounds) & ~rejected
        if not over.any():
            break
        gross = _gross_readings(over, params, ordered, weights, knots, degree, residuals,
                                bounds, rejected)
        if np.count_nonzero(rejected | gross) > MAX_GROSS_FRACTION * len(ordered):
            gross[:] = False
        if gross.any():
            # The readings the gross ones pulled off come back once they are left out.
            rejected |= gross
            continue
        shape = over
        unique = np.unique(knots)
        spans = np.unique(np.clip(np.searchsorted(unique, params[shape], side="right") - 1,
                                  0, len(unique) - 2))
        if len(knots) - degree - 1 + len(spans) > int(np.count_nonzero(~rejected)):
            break
        knots = np.sort(np.concatenate([knots, 0.5 * (unique[spans] + unique[spans + 1])]))
    else:
        spline, params, residuals = _fit_on_knots(params, ordered, weights * ~rejected, knots,
                                                  degree)
    back = np.empty(len(ordered), dtype=int)
    back[walk] = np.arange(len(ordered))
    return SectionFit(curve=_to_part_curve(knots, spline.c, degree),
                      residuals=residuals[back], bounds=bounds[back], rejected=rejected[back],
                      sigma_ref=float(sigma_ref), params=params[back])


def fit_section_curve(points, n_poles=None, degree=DEGREE, snr=None, sigma_ref=None):
    """``fit_section_pass``'s (Part.BSplineCurve, rms, max): distances from the readings kept
    to the curve, mm."""
    fit = fit_section_pass(points, snr=snr, sigma_ref=sigma_ref, n_poles=n_poles,
                           degree=degree)
    return fit.curve, fit.rms, fit.max


def make_compatible(curves, n_poles=None, samples=2000, tolerance=COMPATIBLE_TOLERANCE_MM):
    """``compatible_curves``' curves."""
    return compatible_curves(curves, n_poles, samples, tolerance)[0]


def compatible_curves(curves, n_poles=None, samples=2000, tolerance=COMPATIBLE_TOLERANCE_MM):
    """The curves on one degree and one knot vector, each reparametrised by normalised arc
    length (refitted by least squares to dense samples of it). The knots start uniform with
    ``n_poles`` (default: the largest pole count among the curves) and the spans where any
    refit strays more than ``tolerance`` mm from its curve's sample at the same arc length are
    halved until none does: a curve that turns sharply onto an edge needs short spans there,
    which uniform ones do not give. Curves must run the same way. Returns (curves, the largest
    such stray, mm: a bound on how far the refit moved any curve)."""
    if not curves:
        raise InputError("make_compatible: no curves")
    degree = max(c.Degree for c in curves)
    n_poles = int(n_poles or max(c.NbPoles for c in curves))
    n_poles = max(n_poles, degree + 1)
    knots = uniform_knots(n_poles, degree)
    t = np.linspace(0.0, 1.0, samples)
    dense = []
    for curve in curves:
        xyz = _spline_of(curve)(t)
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xyz, axis=0), axis=1))])
        dense.append((arc / arc[-1], xyz))
    for _ in range(MAX_REFINE_ROUNDS):
        poles = [_least_squares_poles(s, xyz, knots, degree) for s, xyz in dense]
        gaps = np.array([np.linalg.norm(BSpline(knots, p, degree)(s) - xyz, axis=1)
                         for (s, xyz), p in zip(dense, poles)])
        stray = np.any(gaps > tolerance, axis=0)
        if not stray.any() or len(knots) - degree - 1 >= samples // 4:
            break
        unique = np.unique(knots)
        at = np.concatenate([s[g > tolerance] for (s, _), g in zip(dense, gaps)])
        spans = np.unique(np.clip(np.searchsorted(unique, at, side="right") - 1, 0,
                                  len(unique) - 2))
        knots = np.sort(np.concatenate([knots, 0.5 * (unique[spans] + unique[spans + 1])]))
    return [_to_part_curve(knots, p, degree) for p in poles], float(gaps.max())


def _chord_v_params(pole_rows):
    """Averaged chord-length parameters across rows of corresponding poles."""
    gaps = np.mean(np.linalg.norm(np.diff(pole_rows, axis=0), axis=2), axis=1)
    if np.any(gaps <= 0):
        raise InputError("loft: two section curves coincide")
    v = np.concatenate([[0.0], np.cumsum(gaps)])
    return v / v[-1]


def loft(curves, v_params=None):
    """A B-spline surface through >= 2 section curves (made compatible first when they are
    not), interpolating their poles across the sections: cubic, or of degree n-1 for n < 4
    curves. ``v_params`` (increasing, one per curve) defaults to averaged chord length."""
    if len(curves) < 2:
        raise InputError("loft: %d section curve(s), at least 2 needed" % len(curves))
    first = curves[0]
    same = all(c.Degree == first.Degree and c.getKnots() == first.getKnots()
               and c.getMultiplicities() == first.getMultiplicities() for c in curves)
    if not same:
        curves = make_compatible(curves)
        first = curves[0]
    rows = np.array([[tuple(p) for p in c.getPoles()] for c in curves])
    v = _chord_v_params(rows) if v_params is None else np.asarray(v_params, dtype=float)
    if len(v) != len(curves) or np.any(np.diff(v) <= 0):
        raise InputError("loft: v parameters must increase, one per curve")
    degree_v = min(DEGREE, len(curves) - 1)
    across = make_interp_spline(v, rows, k=degree_v, axis=0)
    poles = across.c  # (n_v_poles, n_u_poles, 3)
    vknots, vmults = np.unique(np.round(across.t, 14), return_counts=True)
    surface = Part.BSplineSurface()
    surface.buildFromPolesMultsKnots(
        [[FreeCAD.Vector(*poles[j, i]) for j in range(poles.shape[0])]
         for i in range(poles.shape[1])],
        first.getMultiplicities(), vmults.tolist(), first.getKnots(), vknots.tolist(),
        False, False, first.Degree, degree_v)
    return surface


def surface_samples(surface, n_u=SAMPLES_U, n_v=20):
    """(n_u * n_v, 3) points of a B-spline surface on a uniform parameter grid."""
    u0, u1, v0, v1 = surface.bounds()
    return np.array([tuple(surface.value(u, v)) for v in np.linspace(v0, v1, n_v)
                     for u in np.linspace(u0, u1, n_u)])


def _circular_mean_deg(a):
    r = np.radians(a)
    return float(np.degrees(np.arctan2(np.mean(np.sin(r)), np.mean(np.cos(r)))) % 360.0)


def _angle_gap(a, b):
    return abs((a - b + 180.0) % 360.0 - 180.0)


def cluster_angles(angles_deg, gap=ANGLE_CLUSTER_GAP_DEG):
    """Labels (N,) grouping rotary angles (mod 360): neighbours on the circle more than
    ``gap`` apart start a new cluster."""
    a = np.mod(np.asarray(angles_deg, dtype=float), 360.0)
    labels = np.zeros(len(a), dtype=int)
    order = np.argsort(a)
    s = a[order]
    after = np.diff(np.concatenate([s, [s[0] + 360.0]]))  # gap from s[i] to the next
    if after.max() <= gap:
        return labels
    # Walk the circle from just after its widest gap so that no cluster wraps round.
    walk = np.roll(np.arange(len(s)), -((int(np.argmax(after)) + 1) % len(s)))
    starts = np.array([k > 0 and after[walk[k] - 1] > gap for k in range(len(s))])
    sorted_labels = np.empty(len(s), dtype=int)
    sorted_labels[walk] = np.cumsum(starts)
    labels[order] = sorted_labels
    return labels


def _span_axis(groups_points):
    """Common normal of the section planes: the direction in which the points of every group
    vary least about their own centroid."""
    cov = np.zeros((3, 3))
    for pts in groups_points:
        c = pts - pts.mean(axis=0)
        cov += c.T @ c
    w, vecs = np.linalg.eigh(cov)
    return vecs[:, 0]


def reconstruct(pointset, n_poles=None):
    """Section curves and lofted side surfaces from a PointSet with ``section`` and
    ``angle_deg`` columns (None without them: callers then use the raw points).

    Points with a negative or non-numeric section are not section points. Within a section,
    rotary angles are clustered into views; views are followed from section to section by
    angle (they turn with the twist) and each followed view is one side. Every (section,
    side) group of at least 4 points becomes a curve; every side with curves on at least two
    sections becomes a surface. InputError when no curve can be fitted."""
    columns = getattr(pointset, "columns", None) or {}
    if "section" not in columns or "angle_deg" not in columns:
        return None
    xyz = np.asarray(pointset.xyz, dtype=float)
    section = _as_float(columns["section"])
    angle = _as_float(columns["angle_deg"])
    use = np.isfinite(section) & (section >= 0) & np.isfinite(angle) \
        & np.all(np.isfinite(xyz), axis=1)
    source = getattr(pointset, "source", "") or "points"
    if not use.any():
        raise InputError("%s: no section points (section >= 0 with an angle) to reconstruct"
                         % source)

    notes, raw_groups = [], []
    tracks = []  # last mean angle of each followed view
    for sec in np.unique(section[use]):
        in_sec = np.flatnonzero(use & (section == sec))
        labels = cluster_angles(angle[in_sec])
        clusters = [(in_sec[labels == lab], _circular_mean_deg(angle[in_sec[labels == lab]]))
                    for lab in np.unique(labels)]
        taken = set()
        # Biggest views claim their sides first; ties by angle, so labels are reproducible.
        for idx, mean in sorted(clusters, key=lambda c: (-len(c[0]), c[1])):
            free = [(k, _angle_gap(mean, a)) for k, a in enumerate(tracks) if k not in taken]
            near = [k for k, g in free if g < ANGLE_TRACK_DEG]
            if near:
                side = min(near, key=lambda k: _angle_gap(mean, tracks[k]))
                tracks[side] = mean
            else:
                side = len(tracks)
                tracks.append(mean)
            taken.add(side)
            raw_groups.append({"section": _plain(sec), "side": side,
                               "angle_deg": round(mean, 6), "n_points": int(len(idx)),
                               "curve": None, "index": idx})

    span = _span_axis([xyz[g["index"]] for g in raw_groups if g["n_points"] >= 3])
    snr = getattr(pointset, "snr", None)
    snr = None if snr is None else np.asarray(snr, dtype=float)
    sigma_ref = _pooled_sigma_ref(xyz, snr, [g["index"] for g in raw_groups
                                             if g["n_points"] >= MIN_GROUP_POINTS])
    curves, fits, fit_errors, groups = [], [], [], []
    for g in raw_groups:
        background.tick()    # a GUI's event loop turns between the section fits
        idx = g.pop("index")
        groups.append(g)
        if len(idx) < MIN_GROUP_POINTS:
            notes.append("section %s side %d: %d points, skipped (at least %d needed)"
                         % (g["section"], g["side"], len(idx), MIN_GROUP_POINTS))
            continue
        try:
            fit = fit_section_pass(xyz[idx], snr=None if snr is None else snr[idx],
                                   sigma_ref=sigma_ref, n_poles=n_poles)
        except InputError as exc:
            notes.append("section %s side %d: skipped (%s)" % (g["section"], g["side"], exc))
            continue
        g["curve"] = len(curves)
        g["offset"] = float(np.mean(xyz[idx], axis=0) @ span)
        curves.append(fit.curve)
        fits.append(fit)
        fit_errors.append(dict({"section": g["section"], "side": g["side"],
                                "n_points": int(len(idx))}, **fit.record()))
        if fit.rejected.any():
            notes.append("section %s side %d: %d reading(s) left out as gross errors, %s mm "
                         "off the curve" % (g["section"], g["side"], fit.rejected.sum(),
                                            ", ".join("%.3f" % v for v in
                                                      fit.record()["rejected_mm"])))
        if fit.beyond_bound:
            notes.append("section %s side %d: %d reading(s) beyond their bound (the poles "
                         "would outnumber the readings), up to %.3f mm"
                         % (g["section"], g["side"], fit.beyond_bound, fit.max))
    if not curves:
        raise InputError("%s: no section curve could be fitted (%s)"
                         % (source, "; ".join(notes) or "no groups"))

    surfaces, surface_errors = [], []
    for side in sorted({g["side"] for g in groups}):
        fitted = sorted((g for g in groups if g["side"] == side and g["curve"] is not None),
                        key=lambda g: g["offset"])
        if len(fitted) < 2:
            notes.append("side %d: curves on %d section(s), no surface" % (side, len(fitted)))
            continue
        offsets = np.array([g["offset"] for g in fitted])
        if np.any(np.diff(offsets) <= 1e-9):
            notes.append("side %d: two sections in one plane, no surface" % side)
            continue
        side_curves = [curves[g["curve"]] for g in fitted]
        lengths = [c.length() for c in side_curves]
        if max(lengths) > MAX_LENGTH_RATIO * min(lengths):
            # The view saw very different stretches of the blade on different sections (as
            # edge views do): skinning them would shear the surface through the part.
            notes.append("side %d: section curves %.1f to %.1f mm long, no surface"
                         % (side, min(lengths), max(lengths)))
            continue
        oriented = _oriented(side_curves, span)
        compatible, stray = compatible_curves(oriented)
        surfaces.append(loft(compatible, v_params=offsets))
        surface_errors.append({
            "side": side, "sections": [g["section"] for g in fitted],
            "max_gap_mm": max(fits[g["curve"]].max for g in fitted) + stray,
            "compatible_stray_mm": stray})
    for g in groups:
        g.pop("offset", None)

    if surfaces:
        samples = np.vstack([surface_samples(s, n_v=SAMPLES_V_PER_SECTION * s.NbVPoles)
                             for s in surfaces])
    else:
        samples = np.vstack([[tuple(p) for p in c.discretize(SAMPLES_U)] for c in curves])
    return Reconstruction(curves=curves, surfaces=surfaces, samples=samples,
                          fit_errors=fit_errors, groups=groups, notes=notes,
                          sigma_ref=sigma_ref, surface_errors=surface_errors)


def _pooled_sigma_ref(xyz, snr, groups):
    """The sensor's noise at SNR_REF from the pseudo-residuals of every pass: one sensor read
    them all, and a short edge view alone gives too few readings for a scale."""
    z = []
    for idx in groups:
        pts = xyz[idx]
        scale = noise_scale(None if snr is None else snr[idx], len(idx))
        order, along = order_points(pts)
        if along[-1] > 1e-9:
            z.append(pseudo_residuals(pts[order], along, scale[order]))
    z = np.concatenate(z) if z else np.zeros(0)
    return noise_sigma_ref(z) if len(z) else None


def _oriented(curves, span):
    """The curves turned, where needed, to run the same way as the previous one: the way
    whose points, compared along the curves with the offset along ``span`` taken out, lie
    nearer (a curve's own direction comes from whichever end its points were walked from)."""
    def in_plane(curve, reverse=False):
        t = np.linspace(curve.FirstParameter, curve.LastParameter, 25)
        pts = np.array([tuple(curve.value(x)) for x in (t[::-1] if reverse else t)])
        return pts - np.outer(pts @ span, span)
    out = [curves[0]]
    for curve in curves[1:]:
        ref = in_plane(out[-1])
        same = np.mean(np.linalg.norm(in_plane(curve) - ref, axis=1))
        turned = np.mean(np.linalg.norm(in_plane(curve, reverse=True) - ref, axis=1))
        if turned < same:
            curve = curve.copy()
            curve.reverse()
        out.append(curve)
    return out


def _as_float(values):
    try:
        return np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        out = np.full(len(values), np.nan)
        for i, v in enumerate(values):
            try:
                out[i] = float(v)
            except (TypeError, ValueError):
                pass
        return out


def _plain(value):
    return int(value) if float(value).is_integer() else float(value)
