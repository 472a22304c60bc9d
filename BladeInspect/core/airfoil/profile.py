"""The section profile as a periodic cubic spline (Profile), its crossings with lines and
its area and centroid."""

import numpy as np
from scipy.interpolate import PPoly, splprep
from scipy.spatial import ConvexHull, cKDTree

from ..errors import InputError
from .geometry import cross2
from .refit import refit_in_arc_length

NEWTON_ITERATIONS = 12


# Consecutive input segments turning by more than this make a corner (not a rounded edge).
_CORNER_DEG = 20.0
_CORNER_RUN = 5


_DENSE_SPACING_MM = 0.02


_DENSE_MIN, _DENSE_MAX = 2000, 8000
_GATHER_SPLIT = 64            # Profile._pieces: from this many parameters, one gather a power
_MEMO_MIN_POINTS, _MEMO_SETS = 64, 8    # Profile.closest's remembered point sets


# ---------------------------------------------------------------- the profile curve

class Profile:
    """A closed section profile as a periodic cubic spline, counter-clockwise. Noisy points
    (``noise_mm`` > 0) are smoothed; with ``nominal``, the CAD's Profile of the same section,
    their fit also takes the knots the section's shape wants where they are sparse
    (_knots_from_nominal)."""

    def __init__(self, points, noise_mm=0.0, nominal=None):
        pts = np.asarray(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 8:
            raise InputError("airfoil profile: need an (N, 2) array of at least 8 points, got "
                             "shape %s" % (pts.shape,))
        if not np.all(np.isfinite(pts)):
            raise InputError("airfoil profile: points must be finite")
        step = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        pts = np.vstack([pts[:1], pts[1:][step > 1e-12]])
        if np.linalg.norm(pts[-1] - pts[0]) < 1e-12:
            pts = pts[:-1]
        if _signed_area(pts) < 0:
            pts = pts[::-1].copy()
        self.points = pts
        self.corners = _corners(pts) if noise_mm == 0 else np.zeros(0, int)
        closed = np.vstack([pts, pts[:1]])
        u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
        self.length = float(u[-1])
        self.point_params = u[:-1]
        smoothing = len(pts) * float(noise_mm) ** 2
        self._tck, _ = splprep([closed[:, 0], closed[:, 1]], u=u, s=smoothing, per=1, k=3)
        if noise_mm > 0:
            # noisy points fitted again in the first fit's arc length (refit.py)
            self.points, self.point_params, self._tck = refit_in_arc_length(
                pts, self._tck, u[-1], noise_mm, nominal)
            self.length = float(self._tck[0][len(self._tck[0]) - 4])
        pieces = [PPoly.from_spline((self._tck[0], cx, 3)) for cx in self._tck[1]]
        keep = (pieces[0].x[:-1] >= 0.0) & (pieces[0].x[:-1] < self.length)
        keep &= np.diff(pieces[0].x) > 0
        self._breaks = pieces[0].x[:-1][keep]
        self._clamp = not self._breaks[0] <= 0.0
        self._coef = np.stack([pp.c[:, keep] for pp in pieces], axis=-1).transpose(1, 0, 2)
        # the same coefficients one contiguous (pieces, 2) array per power: a gather of many
        # parameters' pieces from these and the Horner steps on contiguous rows run ~1.5x
        # faster than on the strided slices of one (n, 4, 2) gather (the same arithmetic)
        self._c4 = tuple(np.ascontiguousarray(self._coef[:, k]) for k in range(4))
        n_dense = int(np.clip(self.length / _DENSE_SPACING_MM, _DENSE_MIN, _DENSE_MAX))
        self.dense_u = np.linspace(0.0, self.length, n_dense, endpoint=False)
        self.dense = self.eval(self.dense_u)
        self._tree = cKDTree(self.dense)
        self._hull = None
        self._memo = {}            # closest(): point set (sorted rows' bytes) -> feet

    def eval(self, u, der=0):
        # Only the asked derivative: most calls want points alone (the same arithmetic as
        # eval3's, so the values are eval3's to the bit).
        t, (c0, c1, c2, c3) = self._pieces(u)
        if der == 0:
            return ((c0 * t + c1) * t + c2) * t + c3
        if der == 1:
            return (3.0 * c0 * t + 2.0 * c1) * t + c2
        return self.eval3(u)[der]

    def eval01(self, u):
        """Points and first derivatives at parameters u (eval's and eval3's arithmetic, one
        piece lookup for both)."""
        t, (c0, c1, c2, c3) = self._pieces(u)
        return ((c0 * t + c1) * t + c2) * t + c3, (3.0 * c0 * t + 2.0 * c1) * t + c2

    def _pieces(self, u):
        """Each parameter's offset into its spline piece and that piece's coefficients (a
        sequence of the four powers' (n, 2) arrays, highest first)."""
        # (the array methods and operators: numpy's function wrappers cost more than the
        # arithmetic on the few parameters of most calls; the same values)
        u = np.asarray(u, dtype=float).reshape(-1) % self.length
        i = self._breaks.searchsorted(u, side="right") - 1
        # i <= len(breaks) - 1 always; i >= 0 as u >= 0 when the first break is at 0 (as
        # FITPACK's knots of a parameter starting at 0 put it)
        if self._clamp:
            i = np.maximum(i, 0)
        t = (u - self._breaks[i])[:, None]
        if len(i) < _GATHER_SPLIT:
            c = self._coef[i]          # few parameters: one gather costs less than four
            return t, (c[:, 0], c[:, 1], c[:, 2], c[:, 3])
        c0, c1, c2, c3 = self._c4
        return t, (c0.take(i, axis=0), c1.take(i, axis=0), c2.take(i, axis=0),
                   c3.take(i, axis=0))

    def eval3(self, u):
        """Points, first and second derivatives at parameters u (piecewise-cubic Horner)."""
        t, (c0, c1, c2, c3) = self._pieces(u)
        p = ((c0 * t + c1) * t + c2) * t + c3
        d1 = (3.0 * c0 * t + 2.0 * c1) * t + c2
        d2 = 6.0 * c0 * t + 2.0 * c1
        return p, d1, d2

    def outward_normal(self, u):
        d = self.eval(u, 1)
        d /= np.linalg.norm(d, axis=1)[:, None]
        return np.column_stack([d[:, 1], -d[:, 0]])

    def nearest_param(self, xy):
        _, i = self._tree.query(np.atleast_2d(xy))
        return self.dense_u[i]

    def closest(self, xy, u0=None, lo=None, hi=None):
        """Feet of ``xy`` on the curve by Newton from ``u0`` (default the nearest dense sample),
        parameters kept in [lo, hi] (unwrapped) when given. Returns (u, foot points).

        The feet of a set of many points from the nearest samples are remembered (the last
        _MEMO_SETS sets, whatever their order): a measured section's points are put on its
        nominal several times over (their noise, their order, the section fit, the contour,
        the maxima's bias). Every point's Newton steps are its own and the set decides when
        they stop, so a set's feet in another order are these, permuted, to the bit."""
        xy = np.atleast_2d(xy)
        if u0 is None and lo is None and len(xy) >= _MEMO_MIN_POINTS:
            xy = np.asarray(xy, dtype=float)
            order = np.lexsort((xy[:, 1], xy[:, 0]))
            key = np.ascontiguousarray(xy[order]).tobytes()
            known = self._memo.get(key)
            if known is None:
                u, foot = self._closest(xy, None, None, None)
                self._memo[key] = (u[order], foot[order])
                while len(self._memo) > _MEMO_SETS:
                    del self._memo[next(iter(self._memo))]
                return u, foot
            u, foot = np.empty_like(known[0]), np.empty_like(known[1])
            u[order], foot[order] = known
            return u, foot
        return self._closest(xy, u0, lo, hi)

    def _closest(self, xy, u0, lo, hi):
        u = self.nearest_param(xy) if u0 is None else np.array(u0, dtype=float)
        # Each point stops once its own step is below 1e-13 of the length (that step taken).
        tol = 1e-13 * self.length
        run = None                  # the rows still going: all of them while run is None
        ur, xr = u, xy
        if lo is not None:
            lo = np.broadcast_to(lo, u.shape)
            hi = np.broadcast_to(hi, u.shape)
            lr, hr = lo, hi
        for _ in range(NEWTON_ITERATIONS):
            new = self.newton_stationary(ur, xr)
            if lo is not None:
                new = np.minimum(np.maximum(new, lr), hr)
            going = np.abs(new - ur) >= tol
            n_going = np.count_nonzero(going)
            if run is None:
                u = new
            else:
                u[run] = new
            if n_going == 0:
                break
            if n_going == len(going):       # (no row stopped: the same rows, no gather)
                ur = new
                continue
            run = np.flatnonzero(going) if run is None else run[going]
            ur, xr = new[going], xr[going]
            if lo is not None:
                lr, hr = lr[going], hr[going]
        return u, self.eval(u)

    def newton_stationary(self, u, xy):
        # Stationary points of |S(u) - xy|^2: the closest point when started next to it.
        # (eval3's arithmetic inline, 2 c1 taken once: the hot loop's fewest calls)
        t, (c0, c1, c2, c3) = self._pieces(u)
        c1x2 = 2.0 * c1
        s = ((c0 * t + c1) * t + c2) * t + c3
        s1 = (3.0 * c0 * t + c1x2) * t + c2
        s2 = 6.0 * c0 * t + c1x2
        d = s - xy
        g = np.einsum("ij,ij->i", d, s1)
        speed2 = np.einsum("ij,ij->i", s1, s1)
        h = speed2 + np.einsum("ij,ij->i", d, s2)
        h = np.where(np.abs(h) > 1e-12, h, speed2)
        return u - g / h

    def hull_vertices(self):
        """Indices of the dense samples on their convex hull (the caliper and the tangent
        chord both want it; worked out once)."""
        if self._hull is None:
            self._hull = ConvexHull(self.dense).vertices
        return self._hull

    def knot_quadrature(self, order=5):
        """Gauss-Legendre nodes and weights over every knot span: exact for polynomials of
        degree 2*order-1 in the spline's parameter."""
        knots = np.unique(self._tck[0][(self._tck[0] >= 0) & (self._tck[0] <= self.length)])
        x, w = np.polynomial.legendre.leggauss(order)
        a, b = knots[:-1, None], knots[1:, None]
        return ((a + b) / 2 + (b - a) / 2 * x).ravel(), ((b - a) / 2 * w).ravel()


def _corners(pts):
    """Indices of input points where the polyline turns by more than _CORNER_DEG: a corner no
    smooth curve through the points has (a sharp edge, a kink between faces)."""
    d = np.diff(np.vstack([pts[-1:], pts, pts[:1]]), axis=0)
    a = np.arctan2(d[:, 1], d[:, 0])
    turn = np.abs(np.degrees(np.angle(np.exp(1j * np.diff(a)))))
    sharp = np.flatnonzero(turn > _CORNER_DEG)
    # A corner may bend over a few points: one index (the sharpest) per run of them.
    if not len(sharp):
        return sharp
    groups = np.split(sharp, np.flatnonzero(np.diff(sharp) > _CORNER_RUN) + 1)
    if len(groups) > 1 and groups[0][0] + len(pts) - groups[-1][-1] <= _CORNER_RUN:
        groups = [np.concatenate([groups[-1], groups[0]])] + groups[1:-1]
    return np.array([g[np.argmax(turn[g])] for g in groups], dtype=int)


def _signed_area(pts):
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def ray_hit(profile, origin, direction, behind=False):
    """First crossing of the ray origin + tau * direction (tau > 0) with the profile; with
    ``behind``, when there is none, the line's nearest crossing behind the origin."""
    p, q = profile.dense, np.roll(profile.dense, -1, axis=0)
    e = q - p
    den = cross2(direction, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = cross2(p - origin, e) / den
        lam = cross2(p - origin, direction) / den
    ok = (np.abs(den) > 1e-15) & (lam >= 0) & (lam <= 1) & (tau > 0)
    if not np.any(ok):
        # An origin outside the profile (the camber locus's last centre in a sharp corner of
        # a noisy profile, which the smooth fit rounds off) crosses it first just behind
        # itself: that crossing, for the edge the circle is fitted about (else the whole
        # section would be lost).
        ok = behind & (np.abs(den) > 1e-15) & (lam >= 0) & (lam <= 1) & (tau <= 0)
        tau = np.where(ok, -tau, tau)
    if not np.any(ok):
        raise InputError("airfoil profile: the camber line's end tangent leaves the profile "
                         "without crossing it; the profile is not closed around it")
    i = np.flatnonzero(ok)[np.argmin(tau[ok])]
    return line_hit(profile, origin, direction, profile.dense_u[i]
                     + lam[i] * (profile.length / len(profile.dense)))


# The edge point on noisy points (docs/user-guide.md, "LE and TE points"): the input points'
# distances from the edge circle's centre, a weighted local quadratic in their angle from the


def line_hit(profile, origin, direction, u):
    """Newton on cross(S(u) - origin, direction) = 0 from u: the crossing of a line."""
    u = np.atleast_1d(np.asarray(u, dtype=float))
    origin = np.atleast_2d(origin)
    direction = np.atleast_2d(direction)
    for _ in range(NEWTON_ITERATIONS):
        p, d1 = profile.eval01(u)
        f = cross2(p - origin, direction)
        df = cross2(d1, direction)
        u = u - f / np.where(np.abs(df) > 1e-15, df, 1e-15)
    return u, profile.eval(u)


def area_centroid(profile):
    """Area and centroid of the spline-bounded region (Green's theorem, exact quadrature of
    the piecewise-polynomial integrands)."""
    u, w = profile.knot_quadrature(5)
    p, d = profile.eval01(u)
    x, y, dx, dy = p[:, 0], p[:, 1], d[:, 0], d[:, 1]
    area = 0.5 * np.sum(w * (x * dy - y * dx))
    cx = np.sum(w * x * x * dy) / (2.0 * area)
    cy = -np.sum(w * y * y * dx) / (2.0 * area)
    return float(area), np.array([cx, cy])
