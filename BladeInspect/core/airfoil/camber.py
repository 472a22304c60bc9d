"""The mean camber line: its centres as a spline, its end tangents (the metal angles) from a
quartic over the end window, and its ends closed onto the edge circles."""

import numpy as np
from scipy.interpolate import CubicSpline

from ..errors import InputError
from .geometry import norms, unit
from .profile import ray_hit

END_SKIP = 0.5
# Metal angles: the camber line's end tangent is the slope at its end of a quartic in arc
# length fitted to the inscribed-circle centres over this % of the locus back from the end
# (the last half edge radius left out). A wide window is what conditions the tangent on
# noisy points (the end centres are the least conditioned); a quartic keeps the window's
# curvature change from biasing it (docs/validation.md gives the figures).
DEFAULT_METAL_ANGLE_WINDOW_PCT = 50.0
END_DEGREE = 4
# A centre further from the window's quartic than this many robust sigmas of the centres'
# distances from it (and than the floor) is off the locus (_end_quartic); a few rounds.
_END_OUTLIER_SIGMAS = 8.0
_END_OUTLIER_FLOOR_MM = 1e-4
_END_OUTLIER_ROUNDS = 4
_BEND_WARN_DEG = 1.0
_EDGE_CORE = 1e-3


class CamberLine:
    """Inscribed-circle centres (a cubic spline in arc length) extended straight along the end
    tangents to the profile: the LE point at s = 0, the TE point at s = length."""

    def __init__(self, le, centres, te, le_tangent, te_tangent):
        self.centres = centres
        seg = np.linalg.norm(np.diff(centres, axis=0), axis=1)
        s = np.concatenate([[0.0], np.cumsum(seg)])
        self._spline = CubicSpline(s, centres, axis=0)
        self.le, self.te = le, te
        self.le_extension = float(np.linalg.norm(centres[0] - le))
        self.inner_length = float(s[-1])
        te_extension = float(np.linalg.norm(te - centres[-1]))
        self.length = self.le_extension + self.inner_length + te_extension
        self.le_tangent, self.te_tangent = le_tangent, te_tangent
        self._le_dir = (centres[0] - le) / max(self.le_extension, 1e-300)
        self._te_dir = (te - centres[-1]) / max(te_extension, 1e-300)

    def at(self, s):
        """Points and unit tangents (LE -> TE) at arc lengths s from the LE point."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        inner = np.clip(s - self.le_extension, 0.0, self.inner_length)
        p = self._spline(inner)
        t = unit(self._spline(inner, 1))
        before = s < self.le_extension
        after = s > self.le_extension + self.inner_length
        # The extensions run straight from the end centres to the edge points (which lie on
        # the end tangents but for the edge circle's centre's offset from them, edge_point);
        # their tangents are the end tangents (the metal angles).
        p[before] = self.centres[0] + (s[before] - self.le_extension)[:, None] * self._le_dir
        t[before] = self.le_tangent
        p[after] = self.centres[-1] + (s[after] - self.le_extension
                                       - self.inner_length)[:, None] * self._te_dir
        t[after] = self.te_tangent
        return p, t

    def sample(self, n=400):
        return self.at(np.linspace(0.0, self.length, n))[0]


def line_end(centres, radii, end, edge=None, window_pct=DEFAULT_METAL_ANGLE_WINDOW_PCT):
    """The camber line's centres and its unit tangent at its first (end=0) or last (end=-1)
    centre, pointing out of that end: the slope at the end of a least-squares quartic (in arc
    length) through the centres within the end window (``window_pct`` of the locus, after the
    last half edge radius) -- a fit over a wide window rather than an interpolating spline's
    end slope, which the closely packed last centres of a circular edge and noise would tilt.

    With ``edge`` (the fitted edge circle): the centres nearer to its centre than _EDGE_CORE of
    its radius are dropped (ill-conditioned bisectors on a circular edge), and the line ends on
    the fitted quartic at its point abreast of the edge circle's centre (ahead of the last
    centre, at most one edge radius, or behind it), the centres beyond dropped -- on a circular
    edge the inscribed circles end as the edge circle, at its centre; on a varying-curvature
    nose the line ends abreast of the fitted circle's centre. A rule continuous in the geometry
    and blind to the last, ill-conditioned centres."""
    c = centres if end == -1 else centres[::-1]
    r = radii if end == -1 else radii[::-1]
    if edge is not None:
        far = np.linalg.norm(c - edge.center, axis=1) >= _EDGE_CORE * edge.radius
        c, r = c[far], r[far]
    c, r, s, sel, fit = _end_quartic(c, r, edge, window_pct)
    skip = END_SKIP * (r[-1] if edge is None else edge.radius)
    tangent = unit(fit.slope(0.0))
    # How far the last stretch turns from that tangent: the metal angle's definition spread.
    last = s >= -skip
    bend = 0.0
    if last.sum() >= 2 and np.linalg.norm(c[-1] - c[last][0]) > 0:
        chord = unit(c[-1] - c[last][0])
        bend = float(np.degrees(np.arccos(np.clip(chord @ tangent, -1.0, 1.0))))
        # the turn of the fitted line itself over that stretch (a curved camber line's own)
        # is not a spread of the definition
        own = unit(fit.point(0.0) - fit.point(float(s[last][0])))
        bend = max(0.0, bend - float(np.degrees(np.arccos(np.clip(own @ tangent, -1.0,
                                                                     1.0)))))
    if edge is not None:
        # The line ends on the fitted curve (not at the last, least conditioned centre),
        # at its point abreast of the edge circle's centre, ahead of the last centre or behind.
        reach = 0.0
        for _ in range(8):
            p, d = fit.point(reach), unit(fit.slope(reach))
            reach = float(np.clip(reach + (edge.center - p) @ d, s[sel][0], edge.radius))
        tip = fit.point(reach)
        tangent = unit(fit.slope(reach))
        keep = s < reach - 1e-9
        c, r = np.vstack([c[keep], tip]), np.concatenate([r[keep], [edge.radius]])
    if end == 0:
        return c[::-1], r[::-1], tangent, bend
    return c, r, tangent, bend


def _arc_from_end(c):
    """Arc lengths along the centres, 0 at the last one and negative before it."""
    s = np.concatenate([[0.0], np.cumsum(norms(np.diff(c, axis=0)))])
    return s - s[-1]


class _EndFit:
    """The end window's curve: an arc of curvature ``kappa`` through the end (arc length 0)
    plus a quartic in arc length, least squares to the centres. The arc takes up the window's
    mean turning, so a camber line of constant curvature (a circular arc, as on a high-turning
    profile) is fitted exactly, and the quartic only the change of curvature; with kappa = 0
    it is the plain quartic in arc length."""

    def __init__(self, s, c, kappa, width):
        self.kappa, self.width = float(kappa), float(width)
        a = self._design(s)
        self.coef = np.linalg.lstsq(a, c.reshape(-1), rcond=None)[0]

    def _arc(self, s):
        # sin(k s)/k and (1 - cos(k s))/k, and their slopes, finite at k = 0
        ks = self.kappa * s
        sin_ = s * np.sinc(ks / np.pi)
        vers = 0.5 * self.kappa * s * s * np.sinc(ks / (2.0 * np.pi)) ** 2
        return sin_, vers, np.cos(ks), np.sin(ks)

    def _design(self, s, der=0):
        s = np.atleast_1d(np.asarray(s, dtype=float))
        sin_, vers, dsin, dvers = self._arc(s)
        q = s / self.width
        n = len(s)
        a = np.zeros((n, 2, 2 + 2 + 2 * (END_DEGREE - 1)))
        a[:, 0, 0] = a[:, 1, 1] = 1.0 if der == 0 else 0.0
        f, g = (sin_, vers) if der == 0 else (dsin, dvers)
        # the arc's tangent e at the end: S e + V J e, J the quarter turn
        a[:, 0, 2], a[:, 0, 3] = f, -g
        a[:, 1, 2], a[:, 1, 3] = g, f
        for k in range(2, END_DEGREE + 1):
            col = 4 + 2 * (k - 2)
            term = q ** k if der == 0 else k * q ** (k - 1) / self.width
            a[:, 0, col] = a[:, 1, col + 1] = term
        return a.reshape(2 * n, -1)

    def point(self, s):
        xy = (self._design(s) @ self.coef).reshape(-1, 2)
        return xy[0] if np.ndim(s) == 0 else xy

    def slope(self, s):
        d = (self._design(s, 1) @ self.coef).reshape(-1, 2)
        return d[0] if np.ndim(s) == 0 else d

    def mean_curvature(self):
        """The slope of a straight line fitted to the fitted curve's tangent angle over the
        window (a grid of arc lengths): its mean curvature, weighted to the window's middle
        rather than read off its ends, where a fit is least sure of its slope."""
        grid = np.linspace(-self.width, 0.0, 33)
        d = self.slope(grid)
        angle = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
        return float(np.polyfit(grid, angle, 1)[0])


def _window_fit(s, c, sel, width):
    """The end fit over the window's centres, its arc's curvature the mean curvature over the
    window's ``width`` back from the end (a plain quartic's first, then the fit's own, twice).
    The width is the window's nominal span, not its first centre's: a centre entering the
    window must not move the curvature by a step."""
    width = max(float(width), 1e-9)
    fit = _EndFit(s[sel], c[sel], 0.0, width)
    for _ in range(2):
        fit = _EndFit(s[sel], c[sel], fit.mean_curvature(), width)
    return fit


def _end_quartic(c, r, edge, window_pct):
    """The end window's fit (_EndFit) of the centres (ordered towards the end), the centres
    off the locus dropped first: a centre refined onto a wrong foot (inscribed, but far off
    the locus) would tilt the end tangent by tens of mdeg. Returns the kept centres and radii,
    their arc lengths, the window's selection of them and the fit. On the exact nominal no
    centre is dropped."""
    s = _arc_from_end(c)
    # The last stretch of the locus bends towards the centre of curvature of the edge's
    # tightest point when the edge is not a circle: it is left out of the fit.
    skip = END_SKIP * (r[-1] if edge is None else edge.radius)

    def window_of(s):
        window = window_pct / 100.0 * -s[0]
        sel = (s >= -(skip + window)) & (s <= -skip)
        if sel.sum() < 2 * END_DEGREE:
            sel = np.arange(len(s)) >= len(s) - 2 * END_DEGREE
            return sel, -s[sel][0]
        return sel, skip + window

    sel, width = window_of(s)
    for _ in range(_END_OUTLIER_ROUNDS):
        fit = _window_fit(s, c, sel, width)
        off = norms(c - fit.point(s))
        spread = 1.4826 * np.median(off[sel])
        stray = sel & (off > max(_END_OUTLIER_SIGMAS * spread, _END_OUTLIER_FLOOR_MM))
        if not stray.any():
            break
        c, r = c[~stray], r[~stray]
        s = _arc_from_end(c)
        sel, width = window_of(s)
    return c, r, s, sel, _window_fit(s, c, sel, width)


def closed_end(profile, centres, radii, end, circle, notes, window_pct):
    """The line closed onto the fitted edge circle at one end (see line_end) and its edge
    point; when the closed end's tangent does not meet the profile (a corner, a clipped
    section), the unclosed end, with a note saying so."""
    c, r, out, bend = line_end(centres, radii, end, circle, window_pct)
    try:
        u, point = ray_hit(profile, c[end], out)
    except InputError:
        c, r, out, bend = line_end(centres, radii, end, window_pct=window_pct)
        u, point = ray_hit(profile, c[end], out, behind=True)
        notes.append("the camber line's end at (%.4f, %.4f) mm could not be brought abreast "
                     "of its edge circle; it ends at its last inscribed circle"
                     % tuple(c[end]))
    if bend > _BEND_WARN_DEG:
        notes.append("the camber line turns %.2f deg from its end tangent within its last "
                     "half edge radius near (%.4f, %.4f) mm (the edge is not a circle): the "
                     "metal angle there depends on the rule (docs/user-guide.md)"
                     % (bend, c[end][0], c[end][1]))
    return c, r, out, u, point
