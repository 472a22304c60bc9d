"""The edge rule in one place: the edge circle fitted over its zone, the edge point, which
end is the LE, the radius's uncertainty and the points an edge needs, and edges that are
corners (docs/user-guide.md)."""

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .geometry import cross2, norms, unit
from .profile import ray_hit

# Edge zone of the LE/TE circle fit: profile points seen from the end of the inscribed-circle
# locus within this angle of the mean camber line's outward direction (docs/user-guide.md).
DEFAULT_EDGE_ZONE_DEG = 45.0


# The blunter end is the LE only when the two edge radii differ by more than this many
# standard deviations of their difference; else the engine axis decides (docs/user-guide.md).
LE_RADIUS_SIGMAS = 3.0


_ZONE_ROUNDS = 20
_ZONE_SAMPLES = 400
_ZONE_GRID, _ZONE_GRID_ROUNDS = 256, 4
_ZONE_WINDOW = 512            # dense samples either side of the edge point scanned first
# A resampled zone (too few input points) moves with its fitted centre and converges linearly:
# it is settled when its bounds move by less than this (a nanometre; the radius moves far less).
_ZONE_SETTLED_MM = 1e-6
# The edge-zone rule (docs/user-guide.md, "Edges measured or not"): an edge zone holding fewer
# measured points than this is fitted to the smoothing spline, whose shape error at a sharp
# turn the circle fit amplifies beyond any U the points' noise gives; on a measured (smoothed)
# profile the edge's radius and the values read from its edge point are then withheld.
ZONE_MIN_POINTS = 12


def zone_points_enough(n_points):
    """The one rule for an edge zone: whether ``n_points`` measured points in it are enough
    for its edge circle to be fitted to the points themselves (ZONE_MIN_POINTS)."""
    return n_points is not None and int(n_points) >= ZONE_MIN_POINTS


@dataclass
class CircleFit2D:
    center: np.ndarray
    radius: float
    rms: float
    n_points: int
    zone_deg: float
    # the input points in the final zone (n_points counts the resampled curve's samples when
    # these are too few, zone_points_enough); None for a record written before it was kept
    zone_points: int = None


def _solve_spd3(a, b):
    """x with a x = b for a symmetric 3 x 3 ``a`` by Cholesky in plain floats (a numpy linalg
    call costs more than the arithmetic), None when ``a`` is not positive definite."""
    (a00, a01, a02), (_, a11, a12), (_, _, a22) = a.tolist()
    if a00 <= 0.0:
        return None
    l00 = a00 ** 0.5
    l10, l20 = a01 / l00, a02 / l00
    d1 = a11 - l10 * l10
    if d1 <= 0.0:
        return None
    l11 = d1 ** 0.5
    l21 = (a12 - l20 * l10) / l11
    d2 = a22 - l20 * l20 - l21 * l21
    if d2 <= 0.0:
        return None
    l22 = d2 ** 0.5
    b0, b1, b2 = b.tolist()
    y0 = b0 / l00
    y1 = (b1 - l10 * y0) / l11
    y2 = (b2 - l20 * y0 - l21 * y1) / l22
    x2 = y2 / l22
    x1 = (y1 - l21 * x2) / l11
    x0 = (y0 - l10 * x1 - l20 * x2) / l00
    return np.array([x0, x1, x2])


def fit_circle_2d(xy):
    """Geometric least-squares circle (Newton from Kasa's algebraic circle)."""
    xy = np.asarray(xy, dtype=float)
    if len(xy) < 3:
        raise InputError("edge circle fit: fewer than 3 points in the edge zone")
    A = np.column_stack([2.0 * xy, np.ones(len(xy))])
    sol, *_ = np.linalg.lstsq(A, np.einsum("ij,ij->i", xy, xy), rcond=None)
    c = sol[:2]
    r = float(np.sqrt(max(sol[2] + c @ c, 0.0)))
    J = np.ones((len(xy), 3))       # minus the residuals' gradient: (w_i, 1)
    for _ in range(50):
        # Newton on the sum of squared residuals rho_i - r (the Gauss-Newton normal matrix
        # plus the residuals' curvature, (I - w w^T) / rho on the centre): the same minimum
        # as Gauss-Newton's, reached quadratically, a 3 x 3 solve per step. Gauss-Newton's
        # matrix alone where the full one is not positive definite (far from the minimum).
        v = xy - c
        rho = np.sqrt(np.einsum("ij,ij->i", v, v))
        w = J[:, :2]
        np.divide(v, rho[:, None], out=w)
        res = rho - r
        jtj = J.T @ J
        step_rhs = J.T @ res          # minus the gradient
        q = res / rho
        hess = jtj.copy()
        hess[:2, :2] -= (w * q[:, None]).T @ w
        qs = q.sum()
        hess[0, 0] += qs
        hess[1, 1] += qs
        dx = _solve_spd3(hess, step_rhs)
        if dx is None:
            dx = np.linalg.lstsq(jtj, step_rhs, rcond=None)[0]
        c, r = c + dx[:2], r + dx[2]
        if float(dx @ dx) < (1e-14 * max(1.0, r)) ** 2:
            break
    res = np.linalg.norm(xy - c, axis=1) - r
    return c, float(r), float(np.sqrt(np.mean(res ** 2)))


def edge_circle(profile, end_centre, outward, edge_u, zone_deg):
    """Circle fitted to the edge zone: the stretch of profile round the edge point (parameter
    edge_u) seen within +-zone_deg of the camber line's outward direction from the fitted
    circle's own centre (first from the last inscribed circle's centre; re-fitted until the
    zone stops changing). The fit is to the input points in the zone (_zone_points).

    On measured points the zone's set of points may alternate between two sets (one fitted
    centre sees a boundary point, the other's does not): no set is then seen from its own
    fit's centre, and the larger of the sets in the cycle is kept (more points, the smaller
    radius uncertainty) -- a choice independent of the number of rounds run."""
    centre = np.asarray(end_centre, dtype=float)
    zone = None
    seen = []            # (point set key, fit) of each round, for a cycle's detection
    for _ in range(_ZONE_ROUNDS):
        lo, hi = _zone_range(profile, centre, outward, edge_u, zone_deg)
        settled = 1e-9 if not seen or seen[-1][0] is not None else _ZONE_SETTLED_MM
        if zone is not None and abs(lo - zone[0]) < settled and abs(hi - zone[1]) < settled:
            break
        xy, key, n_in = _zone_points(profile, lo, hi)
        zone = (lo, hi)
        earlier = [k for k, (kk, _) in enumerate(seen) if key is not None and kk == key]
        if earlier:
            if earlier[-1] == len(seen) - 1:      # the same points: the same fit, converged
                break
            cycle = [fit for _, fit in seen[earlier[-1]:]]
            centre, radius, rms, n, n_in = max(cycle, key=lambda f: f[3])
            return CircleFit2D(centre, radius, rms, n, zone_deg, n_in)
        centre, radius, rms = fit_circle_2d(xy)
        seen.append((key, (centre, radius, rms, len(xy), n_in)))
    centre, radius, rms, n, n_in = seen[-1][1]
    return CircleFit2D(centre, radius, rms, n, zone_deg, n_in)


def _zone_points(profile, lo, hi):
    """The input points in the parameter range [lo, hi] (unwrapped) when they are enough
    (zone_points_enough) -- measured points fit without any smoothing's bias -- else the
    profile curve resampled finely over it. Returns the points, a key of the input points
    taken (None for a resampled curve, which moves with the range) and their count."""
    u = np.mod(profile.point_params - lo, profile.length)
    inside = u <= hi - lo
    n_in = int(inside.sum())
    if zone_points_enough(n_in):
        return profile.points[inside], np.flatnonzero(inside).tobytes(), n_in
    return profile.eval(np.linspace(lo, hi, _ZONE_SAMPLES)), None, n_in


def _zone_range(profile, centre, outward, edge_u, zone_deg):
    """Unwrapped parameter range round edge_u where the profile is seen from ``centre``
    within zone_deg of ``outward`` (to the exact crossing of the zone's bounding rays)."""
    cos_zone = np.cos(np.radians(zone_deg))
    n = len(profile.dense)
    h = profile.length / n
    i0 = int(np.round(np.mod(edge_u, profile.length) / h)) % n
    # The samples round edge_u first (a zone spans a few edge radii); the whole loop only
    # when the zone reaches past them.
    near = np.arange(i0 - _ZONE_WINDOW, i0 + _ZONE_WINDOW + 1) % n
    seen_near = unit(profile.dense[near] - centre) @ outward >= cos_zone
    ahead_near = np.flatnonzero(~seen_near[_ZONE_WINDOW:])
    behind_near = np.flatnonzero(~seen_near[_ZONE_WINDOW::-1][1:])
    if 2 * _ZONE_WINDOW + 1 < n and len(ahead_near) and len(behind_near):
        ahead = int(ahead_near[0])               # first sample outside, going forwards
        behind = int(behind_near[0])             # first sample outside, going backwards
    else:
        seen = np.roll(unit(profile.dense - centre) @ outward >= cos_zone, -i0)
        if seen.all():
            raise InputError("edge zone: the whole profile is within the edge zone")
        ahead = int(np.argmin(seen))
        behind = int(np.argmin(seen[::-1][:-1] if seen[0] else seen[::-1]))
    base = profile.dense_u[i0]
    # Each bound lies between its last sample inside (a) and the next one out (a + step);
    # the bracket is cut into _ZONE_GRID parts per round, both bounds in one evaluation:
    # the resolution of 32 bisections (h / 2**32, far below a nanometre) in 4 rounds.
    a = np.array([base - behind * h, base + (ahead - 1) * h])
    step = np.array([-h, h])
    frac = np.arange(1, _ZONE_GRID) / _ZONE_GRID
    for _ in range(_ZONE_GRID_ROUNDS):
        trial = a[:, None] + step[:, None] * frac[None, :]
        ok = (unit(profile.eval(trial.ravel()) - centre) @ outward >= cos_zone)
        ok = ok.reshape(trial.shape)
        # the last grid point inside before the first one outside
        first_out = np.where(ok.all(axis=1), _ZONE_GRID - 1, np.argmin(ok, axis=1))
        a = a + step * first_out / _ZONE_GRID
        step = step / _ZONE_GRID
    return float(a[0]), float(a[1])


# The edge point on noisy points (docs/user-guide.md, "LE and TE points"): the input points'
# distances from the edge circle's centre, a weighted local quadratic in their angle from the
# camber line's direction over +-_EDGE_POINT_DEG (biweight), read at angle 0.
_EDGE_POINT_DEG = 15.0


def edge_point(profile, circle, outward, noise_mm, u_line, p_line):
    """The edge point: where the ray from the edge circle's centre along the camber line's
    outward end direction meets the profile. Noise-free, the profile is the interpolating
    spline (its exact crossing). On noisy points it is the input points themselves seen from
    the centre: their distance as a local quadratic in the angle from the ray, weighted by a
    biweight that falls to zero at +-_EDGE_POINT_DEG (so a point entering or leaving moves it
    by nothing), when at least ZONE_MIN_POINTS points weigh in; else the smoothing spline's
    crossing. The smoothing spline's knots -- FITPACK's, re-chosen by the data -- change with
    every micrometre the points move and tilt its edges by micrometres; the input points and
    the circle fitted to them (edge_circle) do not jump. Returns (parameters, points) as
    ray_hit; (u_line, p_line), the extended camber line's crossing, when the ray misses."""
    centre = np.asarray(circle.center, dtype=float)
    direction = unit(np.asarray(outward, dtype=float))
    if noise_mm > 0:
        v = profile.points - centre
        ang = np.arctan2(cross2(direction, v), v @ direction)
        x = ang / np.radians(_EDGE_POINT_DEG)
        near = np.abs(x) < 1.0
        if near.sum() >= ZONE_MIN_POINTS:
            sw = 1.0 - x[near] ** 2          # the square root of the biweight
            q = np.polyfit(x[near], norms(v[near]), 2, w=sw)
            point = centre + q[-1] * direction
            u, _ = profile.closest(point)
            return u, point[None, :]
    try:
        return ray_hit(profile, centre, direction)
    except InputError:
        return u_line, p_line


def leading_end(end_a, end_b, circle_a, circle_b, axis, le_hint, le_upstream, noise_mm,
                le_radius_sigmas=LE_RADIUS_SIGMAS):
    """Whether end a is the LE, and the rule that decided (docs/user-guide.md)."""
    if le_hint is not None:
        hint = np.asarray(le_hint, dtype=float).reshape(2)
        return bool(np.linalg.norm(end_a - hint) <= np.linalg.norm(end_b - hint)), "given"
    if le_upstream is not None:
        up = np.asarray(le_upstream, dtype=float).reshape(2)
        if not np.all(np.isfinite(up)) or np.linalg.norm(up) < 1e-12:
            raise InputError("LE upstream direction: %s must be a finite non-zero 2D "
                             "direction" % up)
        return bool((end_a - end_b) @ up >= 0), "given upstream direction"
    sigma = np.hypot(edge_radius_sigma(circle_a, noise_mm), edge_radius_sigma(circle_b, noise_mm))
    if abs(circle_a.radius - circle_b.radius) > le_radius_sigmas * sigma:
        return bool(circle_a.radius > circle_b.radius), "larger edge radius"
    return bool((end_a - end_b) @ axis <= 0), "upstream along the engine axis"


def edge_radius_sigma(circle, noise_mm=0.0):
    """1-sigma of a fitted edge radius: sigma_R = s / sqrt(n) * f(alpha) (docs/user-guide.md),
    s the larger of the points' noise and the fit's rms (a non-circular edge's form counts as
    the radius's definition spread), alpha the zone's half-angle."""
    s = max(float(noise_mm), circle.rms)
    return s / np.sqrt(circle.n_points) * circle_radius_factor(np.radians(circle.zone_deg))


def circle_radius_factor(half_angle_rad):
    """f(alpha) in sigma_R = sigma / sqrt(n) * f(alpha): the radius's standard deviation of a
    geometric circle fit to n points spread evenly in angle over an arc of half-angle alpha,
    each with normal noise sigma. From the Fisher information of (centre, radius) with the
    residual's gradient (cos t, sin t, 1): f^2 = m_cc / (m_cc - m_c^2), m_c = sin(a)/a,
    m_cc = (1 + sin(2a)/(2a))/2 (the centre's along-axis coordinate and the radius trade off
    on a short arc)."""
    a = float(half_angle_rad)
    m_c = np.sin(a) / a
    m_cc = 0.5 * (1.0 + np.sin(2 * a) / (2 * a))
    return float(np.sqrt(m_cc / (m_cc - m_c ** 2)))


def edge_points_needed(noise_mm, radius_sigma_mm, zone_deg=DEFAULT_EDGE_ZONE_DEG):
    """Points the edge zone (+-zone_deg) needs for the fitted radius's 1-sigma to be at most
    radius_sigma_mm at the points' noise: n = (noise / sigma_R * f(alpha))^2."""
    f = circle_radius_factor(np.radians(zone_deg))
    return int(np.ceil((float(noise_mm) / float(radius_sigma_mm) * f) ** 2))


def edge_spacing_mm(radius_mm, noise_mm, radius_sigma_mm, zone_deg=DEFAULT_EDGE_ZONE_DEG):
    """Point spacing along an edge of radius radius_mm giving the zone those points: its arc
    2 alpha r over edge_points_needed."""
    arc = 2.0 * np.radians(zone_deg) * float(radius_mm)
    return arc / edge_points_needed(noise_mm, radius_sigma_mm, zone_deg)


# A turn of the input polyline flagged as a corner (profile._corners) is a round edge's when
# the edge circle fitted there is a circle (rms within _ROUND_RMS of its radius), the vertex
# and its two neighbours lie on it (within _ROUND_ON of its radius), no input point near it
# lies inside it (an edge's circle is inscribed: its flanks leave it outwards, where a spline
# rounding off a point overshoots the points round it), and the vertex turns by no more than
# _ROUND_TURN times the turn of a polyline inscribed in that circle with the same segments: a
# small-radius edge cut at a spacing of a fair part of its radius turns by tens of degrees
# per vertex and is still round.
_ROUND_RMS, _ROUND_ON, _ROUND_TURN = 0.02, 0.02, 1.25
_ROUND_REACH = 3.0            # radii from the centre within which no point may lie inside


def round_vertex(points, i, circle):
    """Whether vertex i of the closed polyline ``points`` is a vertex of a round edge cut
    coarsely: of a polyline inscribed in ``circle`` (a CircleFit2D) and turning as such a
    polyline does, the points round it outside the circle (above)."""
    if circle is None or not circle.radius > 0 or circle.rms > _ROUND_RMS * circle.radius:
        return False
    n = len(points)
    prev, p, nxt = points[(i - 1) % n], points[i], points[(i + 1) % n]
    c, r = np.asarray(circle.center, dtype=float), float(circle.radius)
    if np.max(np.abs(norms(np.array([prev, p, nxt]) - c) - r)) > _ROUND_ON * r:
        return False
    dist = norms(points - c)
    if np.any(dist[dist <= _ROUND_REACH * r] < (1.0 - _ROUND_ON) * r):
        return False
    d1, d2 = p - prev, nxt - p
    turn = abs(np.arctan2(cross2(d1, d2), d1 @ d2))
    inscribed = sum(np.arcsin(min(1.0, np.linalg.norm(d) / (2.0 * r))) for d in (d1, d2))
    return bool(turn <= _ROUND_TURN * inscribed)


def _edge_corners(profile, le, te, chord, circles):
    """[(index, "LE"/"TE"/None)] of the input points' corners that are not round edges
    (round_vertex against the edge circle of the edge they lie at; ``circles``: (LE circle,
    TE circle) or None), each with the edge it lies at (within 2 % of the chord of its edge
    point) or None on a side."""
    out = []
    for i in profile.corners:
        p = profile.points[i]
        where = ("LE" if np.linalg.norm(p - le) < 0.02 * chord else
                 "TE" if np.linalg.norm(p - te) < 0.02 * chord else None)
        if where is not None and circles is not None and \
                round_vertex(profile.points, i, circles[0 if where == "LE" else 1]):
            continue
        out.append((int(i), where))
    return out


def corner_edges(profile, le, te, chord, circles=None):
    """{"LE" and/or "TE": the corner}: the edges that are a corner of the input points (one
    within 2 % of the chord of the edge point, corner_warnings's rule; with ``circles``, (LE
    circle, TE circle), a vertex of a round edge cut coarsely is not one: round_vertex)."""
    out = {}
    for i, where in _edge_corners(profile, le, te, chord, circles):
        if where is not None and where not in out:
            out[where] = profile.points[i]
    return out


def corner_warnings(profile, le, te, chord, circles=None):
    """One line per corner of the input points (corner_edges's rule): the spline rounds a
    corner off over a point spacing, so an edge radius, edge point and chord read there are
    not the part's."""
    out = []
    for i, where in _edge_corners(profile, le, te, chord, circles):
        p = profile.points[i]
        out.append("corner %s at (%.4f, %.4f) mm: the profile is not smooth there; "
                   "characteristics near it (edge radius, edge point, chords, metal angle) "
                   "are not trustworthy" % ("at the " + where if where else "on a side",
                                            p[0], p[1]))
    return out


# What rests on each edge's fit (docs/user-guide.md, "Edges measured or not"): its circle, its
# camber-line end (the metal angle) and its edge point (the edge thicknesses, measured along the
# camber line from it), and, through the edge point, every chord and the stagger (the chord's
# angle). The axial chord rests on an edge when its extreme along the engine axis lies on that
# edge's round (_axial_extreme_at_edge). The thickness stations and the largest thickness's
# position move with an edge point only by its bias times the thickness's slope there, far
# below their U: they are kept.
EDGE_FIELDS = {"LE": ("le_radius_mm", "inlet_angle_deg", "le_thickness_mm"),
               "TE": ("te_radius_mm", "outlet_angle_deg", "te_thickness_mm")}
CHORD_FIELDS = ("chord_mm", "nose_tail_chord_mm", "caliper_chord_mm", "tangent_chord_mm",
                "stagger_deg")


def sparse_edges(ch, noise_mm):
    """{"LE"/"TE": measured points in its zone} of the edges of a measured (smoothed,
    ``noise_mm`` > 0) profile whose zone fails zone_points_enough; {} for exact points (the
    nominal's cut), whose interpolating curve is the profile."""
    if not noise_mm > 0:
        return {}
    return {name: int(circle.zone_points) for name, circle in
            (("LE", ch.le_circle), ("TE", ch.te_circle))
            if circle.zone_points is not None and not zone_points_enough(circle.zone_points)}


def edge_zone_withheld(ch, noise_mm):
    """{Characteristics field: the reason (one line)} of every value withheld because an
    edge's zone holds too few measured points (sparse_edges, EDGE_FIELDS, CHORD_FIELDS)."""
    out = {}
    for name, n in sparse_edges(ch, noise_mm).items():
        circle = ch.le_circle if name == "LE" else ch.te_circle
        reason = ("%d measured point%s in the %s zone (+-%g deg), %d needed"
                  % (n, "" if n == 1 else "s", name, circle.zone_deg, ZONE_MIN_POINTS))
        fields = EDGE_FIELDS[name] + CHORD_FIELDS
        if _axial_extreme_at_edge(ch, circle, ch.le_point if name == "LE" else ch.te_point):
            fields += ("axial_chord_mm",)
        for f in fields:
            out.setdefault(f, reason)
    return out


# The axial chord's end rests on an edge when it lies on the edge's round: seen from the edge
# circle's centre on the outward half (within 90 deg of the camber line's end direction, wider
# than the zone: on a staggered blade the extreme along the axis lies on the round outside
# the zone) and within _AXIAL_REACH radii of it.
_AXIAL_REACH = 3.0


def _axial_extreme_at_edge(ch, circle, edge_pt):
    """Whether one of the profile's two extremes along the engine axis (the axial chord's
    ends) lies on the round of the edge of ``circle`` (above)."""
    outward = unit(np.asarray(edge_pt, dtype=float) - circle.center)
    along = ch.profile.dense @ ch.engine_axis
    for p in ch.profile.dense[[int(np.argmin(along)), int(np.argmax(along))]]:
        v = p - circle.center
        if np.linalg.norm(v) <= _AXIAL_REACH * circle.radius and v @ outward >= 0.0:
            return True
    return False


def withhold_sparse_edges(ch, noise_mm):
    """``ch`` with the values edge_zone_withheld names set to None (a list to Nones) and one
    warning per sparse edge, first, saying what is not measured and why."""
    withheld = edge_zone_withheld(ch, noise_mm)
    for name in sorted(sparse_edges(ch, noise_mm), reverse=True):
        names = [f for f in EDGE_FIELDS[name] + CHORD_FIELDS + ("axial_chord_mm",)
                 if f in withheld and getattr(ch, f) is not None]
        ch.warnings.insert(0, "%s: %s: not measured (null): %s; a circle there would be "
                              "fitted to the smooth fit's edge, whose shape is not the part's"
                           % (name, withheld[EDGE_FIELDS[name][0]], ", ".join(names)))
    for f in withheld:
        value = getattr(ch, f)
        setattr(ch, f, [None] * len(value) if isinstance(value, list) else None)
    return ch


def withhold_corner_edges(measured, nominal):
    """The measured characteristics with the metal angle and edge radius of every edge that
    is a corner of the nominal (a corner of its exact cut within 2 % of the chord of that edge
    point, the rule of its "corner at the LE/TE" warning) set to None, and a warning saying
    why. A corner has no edge circle and no camber-line end for a tangent; the nominal's
    value is its cut's, read at the corner's exact vertex, while a measured profile's smooth
    fit rounds the corner off over the points' spacing and noise, and the same rule then
    reads the rounding, degrees off on a perfect part. docs/user-guide.md, "Sharp edges"."""
    corners = corner_edges(nominal.profile, nominal.le_point, nominal.te_point,
                           nominal.nose_tail_chord_mm, (nominal.le_circle, nominal.te_circle))
    for name, angle, radius in (("LE", "inlet_angle_deg", "le_radius_mm"),
                                ("TE", "outlet_angle_deg", "te_radius_mm")):
        if name not in corners:
            continue
        setattr(measured, angle, None)
        setattr(measured, radius, None)
        corner = corners[name]
        measured.warnings.append(
            "%s: the nominal's %s is a corner at (%.4f, %.4f) mm, not a rounded edge: its "
            "metal angle (%s) and edge radius (%s) are not measurable with this sampling "
            "(the smooth fit of the measured points rounds the corner off) and are not "
            "reported" % (name, name, corner[0], corner[1], angle, radius))
    return measured
