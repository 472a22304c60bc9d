"""Section curves and lofted surfaces from measured section passes (paper 3.1.2).

Each pass of the sensor over one side of one section gives points along a plane curve. They
are approximated by a cubic B-spline on a uniform (clamped) knot vector in the least-squares
sense, with the points' curve parameters corrected towards their closest curve points. The
curves of one side, across the sections, are made compatible (same degree and knots, each
reparametrised by normalised arc length) and skinned: their poles are interpolated across the
sections, so each section curve is an iso-parametric curve of the lofted surface.
"""
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, minimum_spanning_tree, shortest_path
from scipy.spatial import cKDTree

import FreeCAD
import Part

from ..core.errors import InputError

DEGREE = 3
MIN_GROUP_POINTS = 4
# Passes of one view share a rotary angle; views of a section are 90 degrees or more apart.
ANGLE_CLUSTER_GAP_DEG = 20.0
# Between neighbouring sections a view's angle follows the blade's twist, well below this.
ANGLE_TRACK_DEG = 60.0
PARAMETER_CORRECTIONS = 3
OUTLIER_SIGMAS = 4.0
OUTLIER_FLOOR_MM = 0.002
MAX_OUTLIER_FRACTION = 0.1
OUTLIER_ROUNDS = 3
# Curves of one side more different in length than this cover different parts of the blade.
MAX_LENGTH_RATIO = 1.5
SAMPLES_U = 160
SAMPLES_V_PER_SECTION = 8


@dataclass
class Reconstruction:
    curves: list             # Part.BSplineCurve, one per (section, side) group fitted
    surfaces: list           # Part.BSplineSurface, one per side seen on >= 2 sections
    samples: np.ndarray      # (M, 3) points of the surfaces (of the curves if none)
    fit_errors: list         # dicts: section, side, n_points, rms, max (mm)
    groups: list             # dicts: section, side, angle_deg, n_points, curve index or None
    notes: list = field(default_factory=list)   # groups skipped and why


def uniform_knots(n_poles, degree=DEGREE):
    """Clamped uniform knot vector on [0, 1] (flat, with multiplicities)."""
    inner = np.linspace(0.0, 1.0, n_poles - degree + 1)
    return np.concatenate([np.zeros(degree), inner, np.ones(degree)])


def _least_squares_poles(params, points, knots, degree):
    """Poles minimising the squared residuals; a faint second-difference penalty keeps the
    system regular where a knot span holds no points."""
    n_poles = len(knots) - degree - 1
    A = BSpline.design_matrix(np.clip(params, 0.0, 1.0), knots, degree).toarray()
    D = np.diff(np.eye(n_poles), 2, axis=0)
    normal = A.T @ A
    ridge = 1e-9 * np.trace(normal) / n_poles
    return np.linalg.solve(normal + ridge * D.T @ D, A.T @ points)


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


def fit_section_curve(points, n_poles=None, degree=DEGREE):
    """A cubic B-spline least-squares approximation of one section pass.

    ``points`` (K, 3), in any order, are ordered along the curve (see ``order_points``);
    parameters start as their normalised distance along it and are then corrected to the
    closest curve points.
    ``n_poles`` defaults to K/10 within [degree + 3, 100]: uniform knots need many spans to
    follow a rounded edge, and ten points a span keep the noise averaged. Gross outliers
    (beyond 4 robust sigmas, at most 10 % of the points) are left out and the curve refitted. Returns (Part.BSplineCurve, rms_fit_error, max_fit_error): distances from the
    points kept to the curve, mm."""
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
    # A fixed starting order: the same points in any row order give the same curve.
    pts = pts[np.lexsort(pts.T[::-1])]
    order, along = order_points(pts)
    ordered = pts[order]
    if along[-1] <= 1e-9:
        raise InputError("section points: all %d points coincide" % len(pts))
    params = along / along[-1]
    knots = uniform_knots(n_poles, degree)
    for _ in range(PARAMETER_CORRECTIONS):
        spline = BSpline(knots, _least_squares_poles(params, ordered, knots, degree), degree)
        params = _closest_params(spline, ordered, params)
        params = (params - params.min()) / max(params.max() - params.min(), 1e-15)
    spline = BSpline(knots, _least_squares_poles(params, ordered, knots, degree), degree)
    params = _closest_params(spline, ordered, params)
    dist = np.linalg.norm(spline(params) - ordered, axis=1)
    # Gross-error rejection (a sensor's spikes): points beyond OUTLIER_SIGMAS robust sigmas of
    # the current curve are left out and the curve refitted, a few rounds, since a curve
    # pulled by spikes also flags good points next to them. Skipped when so many points are
    # flagged that the curve, not the data, is at fault.
    keep = np.ones(len(ordered), dtype=bool)
    for _ in range(OUTLIER_ROUNDS):
        sigma = 1.4826 * np.median(dist[keep])
        flagged = dist > max(OUTLIER_SIGMAS * sigma, OUTLIER_FLOOR_MM)
        if flagged.mean() > MAX_OUTLIER_FRACTION or np.array_equal(~flagged, keep):
            break
        keep = ~flagged
        for _ in range(2):
            spline = BSpline(knots, _least_squares_poles(params[keep], ordered[keep], knots,
                                                         degree), degree)
            params = _closest_params(spline, ordered, params)
        dist = np.linalg.norm(spline(params) - ordered, axis=1)
    dist = dist[keep]
    return (_to_part_curve(knots, spline.c, degree), float(np.sqrt(np.mean(dist ** 2))),
            float(dist.max()))


def make_compatible(curves, n_poles=None, samples=2000):
    """The curves on one degree and one uniform knot vector, each reparametrised by normalised
    arc length (refitted by least squares to dense samples of it). ``n_poles`` defaults to
    the largest pole count among the curves. Curves must run the same way."""
    if not curves:
        raise InputError("make_compatible: no curves")
    degree = max(c.Degree for c in curves)
    n_poles = int(n_poles or max(c.NbPoles for c in curves))
    n_poles = max(n_poles, degree + 1)
    knots = uniform_knots(n_poles, degree)
    out = []
    for curve in curves:
        spline = _spline_of(curve)
        t = np.linspace(0.0, 1.0, samples)
        xyz = spline(t)
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xyz, axis=0), axis=1))])
        s = arc / arc[-1]
        poles = _least_squares_poles(s, xyz, knots, degree)
        out.append(_to_part_curve(knots, poles, degree))
    return out


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
    curves, fit_errors, groups = [], [], []
    for g in raw_groups:
        idx = g.pop("index")
        groups.append(g)
        if len(idx) < MIN_GROUP_POINTS:
            notes.append("section %s side %d: %d points, skipped (at least %d needed)"
                         % (g["section"], g["side"], len(idx), MIN_GROUP_POINTS))
            continue
        try:
            curve, rms, worst = fit_section_curve(xyz[idx], n_poles=n_poles)
        except InputError as exc:
            notes.append("section %s side %d: skipped (%s)" % (g["section"], g["side"], exc))
            continue
        g["curve"] = len(curves)
        g["offset"] = float(np.mean(xyz[idx], axis=0) @ span)
        curves.append(curve)
        fit_errors.append({"section": g["section"], "side": g["side"],
                           "n_points": int(len(idx)), "rms": rms, "max": worst})
    if not curves:
        raise InputError("%s: no section curve could be fitted (%s)"
                         % (source, "; ".join(notes) or "no groups"))

    surfaces = []
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
        surfaces.append(loft(make_compatible(_oriented(side_curves, span)),
                             v_params=offsets))
    for g in groups:
        g.pop("offset", None)

    if surfaces:
        samples = np.vstack([surface_samples(s, n_v=SAMPLES_V_PER_SECTION * s.NbVPoles)
                             for s in surfaces])
    else:
        samples = np.vstack([[tuple(p) for p in c.discretize(SAMPLES_U)] for c in curves])
    return Reconstruction(curves=curves, surfaces=surfaces, samples=samples,
                          fit_errors=fit_errors, groups=groups, notes=notes)


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
