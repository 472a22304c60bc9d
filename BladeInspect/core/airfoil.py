"""Airfoil characteristics of one closed 2D section profile (issue 15), numpy/scipy only.

Input: the profile in its section plane as an (N, 2) array of points ordered around the loop
(either direction; a repeated closing point is dropped). Unordered measured points are first
ordered by their foot on the nominal (``order_by_nominal``). The profile is represented by a
periodic cubic spline through the points (interpolating; or smoothing with ``noise_mm``, the
points' 1-sigma scatter), parametrised by chord length (about arc length, in mm).

Every definition (mean camber line, chords, edge radii, thicknesses, angles, contour errors)
is written out in docs/airfoil.md; the names here are the fields of result.json's ``airfoil``
block. Lengths in mm, angles in degrees, counter-clockwise positive in the section's 2D frame.
"""

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Optional

import numpy as np
from scipy.interpolate import CubicSpline, PPoly, splev, splprep
from scipy.spatial import ConvexHull, cKDTree

from .errors import InputError

DEFAULT_EDGE_OFFSETS_MM = (0.5, 1.0, 2.0)
# Edge zone of the LE/TE circle fit: profile points seen from the end of the inscribed-circle
# locus within this angle of the mean camber line's outward direction (docs/airfoil.md).
DEFAULT_EDGE_ZONE_DEG = 45.0
# An inscribed circle belongs to the camber line only while its two contacts are at least this
# far apart as seen from its centre; closer, the circle sits in an edge and its centre is
# ill-conditioned (the bisector of two nearly parallel normals).
MIN_CONTACT_ANGLE_DEG = 60.0
# Contour zones: a point is at an edge when its foot on the nominal lies within this fraction
# of the chord from that end along the chord (as inspection/sections.py).
CONTOUR_EDGE_FRACTION = 0.03
CHORD_METHODS = ("nose-tail", "caliper", "tangent")
# The blunter end is the LE only when the two edge radii differ by more than this many
# standard deviations of their difference; else the engine axis decides (docs/airfoil.md).
LE_RADIUS_SIGMAS = 3.0
ZONES = ("LE", "TE", "suction", "pressure")

_NEWTON_ITERATIONS = 12
_FEET = 300                 # feet on one side seeding the inscribed circles
_END_FEET = 17              # finer feet closing in on each end of the camber line
_END_ROUNDS = 3
_SEED_STRIDE = 4
_RUN_GAP = 2                 # failed circles a run of camber-line circles may step over,
_RUN_MIN = 2                 # between runs at least this long
# Consecutive input segments turning by more than this make a corner (not a rounded edge).
_CORNER_DEG = 20.0
_CORNER_RUN = 5
_ZONE_ROUNDS = 20
_ZONE_SAMPLES = 400
_ZONE_GRID, _ZONE_GRID_ROUNDS = 256, 4
_ZONE_WINDOW = 512            # dense samples either side of the edge point scanned first
# A resampled zone (too few input points) moves with its fitted centre and converges linearly:
# it is settled when its bounds move by less than this (a nanometre; the radius moves far less).
_ZONE_SETTLED_MM = 1e-6
_ZONE_MIN_POINTS = 12
ZONE_MIN_POINTS = _ZONE_MIN_POINTS
_END_SKIP = 0.5
# Metal angles: the camber line's end tangent is the slope at its end of a quartic in arc
# length fitted to the inscribed-circle centres over this % of the locus back from the end
# (the last half edge radius left out). A wide window is what conditions the tangent on
# noisy points (the end centres are the least conditioned); a quartic keeps the window's
# curvature change from biasing it (docs/airfoil.md gives the figures).
DEFAULT_METAL_ANGLE_WINDOW_PCT = 50.0
_END_DEGREE = 4
# A centre further from the window's quartic than this many robust sigmas of the centres'
# distances from it (and than the floor) is off the locus (_end_quartic); a few rounds.
_END_OUTLIER_SIGMAS = 8.0
_END_OUTLIER_FLOOR_MM = 1e-4
_END_OUTLIER_ROUNDS = 4
_BEND_WARN_DEG = 1.0
_EDGE_CORE = 1e-3
_MCL_SPACING_MM = 0.05        # least spacing of the camber line's centres
# A camber-line circle clears the profile round the edge by this fraction of its radius; the
# camber line thus stops within 1e-4 r of an exact circular edge's centre.
_EDGE_GAP = 1e-4
_DENSE_SPACING_MM = 0.02
# Noisy points' feet on their first fit (_refit_in_arc_length): a table of that curve this
# fine (at most this many samples), then Newton steps.
_FOOT_TABLE_MM, _FOOT_TABLE_MAX, _FOOT_NEWTON = 1e-3, 400000, 3
_FREE_SHARE = 0.75            # of the spline's free coefficients taken off its budget
# Where the points thin out -- their spacing, averaged over _SPACING_RUN gaps either side,
# over _SPARSE_SPACING times its median -- a measured profile's fit takes the knots the
# nominal's shape wants (_knots_from_nominal): FITPACK's for the nominal at the points' feet
# at _NOMINAL_KNOT_SHARE of the noise budget, each knot span holding at least
# _KNOT_SPAN_POINTS points.
_SPACING_RUN = 8
_SPARSE_SPACING = 10.0
_NOMINAL_KNOT_SHARE = 1e-3
_KNOT_SPAN_POINTS = 4
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
            # metal-angle hook: noisy points fitted again in the first fit's arc length
            self.points, self.point_params, self._tck = _refit_in_arc_length(
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
        for _ in range(_NEWTON_ITERATIONS):
            new = self._newton_stationary(ur, xr)
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

    def _newton_stationary(self, u, xy):
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


def _refit_in_arc_length(pts, first, first_length, noise_mm, nominal=None):
    """Noisy points' smoothing spline in a parameter that is the curve's arc length: each
    point's foot on the first fit ``first`` (a smoothing spline in the chord length between
    consecutive points), measured as that fit's arc length; the points re-ordered along it.
    Given the ``nominal`` Profile and a change of the points' density, the points are then
    fitted by least squares on the knots of _knots_from_nominal. Returns the points, their
    parameters and the spline.

    Why (docs/airfoil.md, "Input and representation"): where points lie closer than their noise
    (the planned edges: 2 um apart, 3.9 um noise) the chord length between consecutive points
    is mostly noise -- a parameter running at up to 3x the arc length, as a random walk -- and
    a parametric fit in it reads the curve biased round the edges: Rotor 67's 10 % section
    planned, a perfect part, metal angles +19 / +5 mdeg over 24 scans (one outlet 0.33 deg
    off), -2.4 / -1.3 mdeg in this parameter with the budget below (bound ~6 mdeg)."""
    n_table = int(np.clip(first_length / _FOOT_TABLE_MM, 4 * len(pts), _FOOT_TABLE_MAX))
    table_u = np.linspace(0.0, first_length, n_table + 1)
    table = np.column_stack(splev(table_u, first))
    arc = np.concatenate([[0.0], np.cumsum(_norms(np.diff(table, axis=0)))])
    foot = table_u[_nearest_sample(table[:-1], arc[:-1], pts)]
    for _ in range(_FOOT_NEWTON):
        p, d1, d2 = (np.column_stack(splev(foot, first, der=k)) for k in range(3))
        g = np.einsum("ij,ij->i", p - pts, d1)
        h = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", p - pts, d2)
        h = np.where(h > 0, h, np.einsum("ij,ij->i", d1, d1))
        foot = np.mod(foot - g / h, first_length)
    s = np.interp(foot, table_u, arc)
    order = np.argsort(s, kind="stable")
    s, pts = s[order], pts[order]
    # the parameter must increase strictly: of points with one foot, the first is kept
    keep = np.concatenate([[True], np.diff(s) > 1e-12 * arc[-1]])
    s, pts = s[keep], pts[keep]
    foot = foot[order][keep]
    # The budget: the points' own noise about the first fit (their normal residuals'
    # consecutive differences, in which the first fit's smooth error cancels; RMS, unbiased
    # for any noise distribution), never more than the noise given.
    p, d1 = (np.column_stack(splev(foot, first, der=k)) for k in range(2))
    residual = _cross2(d1, pts - p) / _norms(d1)
    sigma = min(float(noise_mm), float(np.sqrt(np.mean(np.diff(residual) ** 2) / 2.0)))
    closed = np.vstack([pts, pts[:1]])
    s = s - s[0]           # the loop's parameter starts at its first point, as the first fit's
    u = np.concatenate([s, [arc[-1]]])
    tck, _ = splprep([closed[:, 0], closed[:, 1]], u=u, s=len(pts) * sigma ** 2, per=1, k=3,
                     quiet=1)
    # Of pure noise a least-squares spline with `free` coefficients leaves (N - free) sigma^2
    # and a smoothing one more (its penalty keeps part of them stiff): the budget is taken
    # between, (N - _FREE_SHARE free) sigma^2. The excess of a budget of N sigma^2 is what
    # the fit spends on the edges (double-circular-arc section at 2 um, 40 scans: inlet +5.1
    # mdeg at N, +4.1 here, +3.4 at N - free, where a rigidly moved demo section's max
    # thickness moved by 0.17 um: too little smoothing follows the points' small changes).
    free = len(tck[0]) - 7
    tck, _ = splprep([closed[:, 0], closed[:, 1]], u=u,
                     s=(len(pts) - _FREE_SHARE * free) * sigma ** 2, per=1, k=3, quiet=1)
    knots = None if nominal is None else \
        _knots_from_nominal(pts, u, tck[0], nominal, float(noise_mm))
    if knots is not None:
        tck, _ = splprep([closed[:, 0], closed[:, 1]], u=u, t=knots, task=-1, per=1, k=3,
                         quiet=1)
    return pts, s, tck


def _knots_from_nominal(pts, u, own_knots, nominal, noise_mm):
    """Periodic knots for noisy section points ``pts`` (parameters ``u``, the loop's length
    last): the points' own smoothing spline's knots ``own_knots`` and, where the points thin
    out (their spacing over a run of _SPACING_RUN gaps either side more than _SPARSE_SPACING
    times its median), FITPACK's knots for the nominal profile at the points' feet (noise-free,
    so placed where the shape's error still falls steeply with each knot; a budget of
    _NOMINAL_KNOT_SHARE N noise^2), thinned to at least _KNOT_SPAN_POINTS points a span. None
    when it adds no knot: points spread evenly, or at random (a cloud's band about the plane,
    whose single gaps vary widely but not its runs of them).

    Why (docs/airfoil.md, "Where the points thin out"): a planned section holds its points a
    few micrometres apart round the edges and 0.1 mm apart beyond; the smoothing spline
    spends its residual budget where the points are many and puts too few knots where they
    thin out, 0.6-3 mm from the edges, and stays stiff there: the demo's 70 % section read its
    edge thicknesses 1 and 2 mm from the edges 3-10 um off, 15-45 standard errors over 24 scans
    at the rig's noise (least squares on its own knots the same). The nominal's knots
    everywhere were tried too: 20 um spans round the edges let the noise bend the curve, and
    a camber line looped (an edge thickness 0.98 mm over)."""
    gaps = np.diff(u)
    if len(gaps) < 4 * _SPACING_RUN:
        return None
    run = 2 * _SPACING_RUN + 1
    spacing = np.convolve(np.concatenate([gaps[-_SPACING_RUN:], gaps, gaps[:_SPACING_RUN]]),
                          np.full(run, 1.0 / run), mode="valid")
    sparse = spacing > _SPARSE_SPACING * np.median(spacing)
    if not sparse.any():
        return None
    _, exact = nominal.closest(pts)
    closed = np.vstack([exact, exact[:1]])
    # (full_output: FITPACK's note that so small a budget was met only roughly is returned,
    # not warned -- the knots are what is taken)
    (shape, _), *_ = splprep([closed[:, 0], closed[:, 1]], u=u,
                             s=_NOMINAL_KNOT_SHARE * len(pts) * noise_mm ** 2, per=1, k=3,
                             quiet=1, full_output=1)
    wanted = shape[0][3:-3]
    wanted = wanted[sparse[np.clip(np.searchsorted(u, wanted) - 1, 0, len(gaps) - 1)]]
    if not len(wanted):
        return None
    length = u[-1]
    joined = np.unique(np.concatenate([wanted, own_knots[3:-3]]))
    kept, last = [], 0
    for knot, at in zip(joined, np.searchsorted(u, joined)):
        if 0.0 < knot < length and at - last >= _KNOT_SPAN_POINTS:
            kept.append(knot)
            last = at
    while kept and len(u) - 1 - np.searchsorted(u, kept[-1]) < _KNOT_SPAN_POINTS:
        kept.pop()
    full = np.concatenate([[0.0], kept, [length]])
    return np.concatenate([full[-4:-1] - length, full, full[1:4] + length])


_NEAR_BLOCK, _NEAR_BLOCKS = 32, 8      # _nearest_sample: samples a block, blocks looked at


def _nearest_sample(table, arc, pts):
    """The index of each point's nearest row of ``table`` (samples along a curve, ``arc``
    their arc lengths): a k-d tree's answer, without a tree of the whole table (10^5 samples:
    its build cost 7 ms a section). The table is cut into blocks of _NEAR_BLOCK consecutive
    samples, each within ``reach`` (the largest block's arc length) of its first sample; a
    tree of the first samples gives each point its _NEAR_BLOCKS nearest blocks, and of those
    every block whose first sample is within the nearest one's distance plus ``reach`` (no
    other can hold a nearer sample) is searched sample by sample. A point whose last block
    looked at is still that near (blocks further may count) asks a tree of the whole table."""
    n, m = len(table), len(pts)
    size = _NEAR_BLOCK
    nb = -(-n // size)
    pad = nb * size - n        # the last block filled up with copies of the last sample
    full = np.concatenate([table, np.repeat(table[-1:], pad, axis=0)]) if pad else table
    blocks = full.reshape(nb, size, 2)
    starts = np.arange(nb) * size
    reach = float((arc[np.minimum(starts + size - 1, n - 1)] - arc[starts]).max())
    reach = reach * (1.0 + 1e-9) + 1e-12      # (a chord is never longer than its arc)
    k = min(_NEAR_BLOCKS, nb)
    dk, ik = cKDTree(blocks[:, 0]).query(pts, k=k)
    dk, ik = dk.reshape(m, k), ik.reshape(m, k)
    near = dk <= dk[:, :1] + reach
    sure = ~near[:, -1] if k < nb else np.ones(m, bool)
    pi, pj = np.nonzero(near & sure[:, None])
    block = ik[pi, pj]
    c = blocks[block]
    dx = c[..., 0] - pts[pi, 0:1]
    dy = c[..., 1] - pts[pi, 1:2]
    d2 = dx * dx + dy * dy
    arg = d2.argmin(axis=1)
    best = d2[np.arange(len(pi)), arg]
    idx = np.minimum(block * size + arg, n - 1)     # (a copy is never before its sample)
    # each point's nearest of its blocks' (of equal distances, the lowest index)
    order = np.lexsort((idx, best, pi))
    first = order[np.concatenate([[True], pi[order][1:] != pi[order][:-1]])] \
        if len(order) else order
    out = np.empty(m, dtype=np.intp)
    out[pi[first]] = idx[first]
    if not sure.all():
        # (a midpoint-split tree: built in 2/3 of the time of a balanced one, the same
        # nearest)
        out[~sure] = cKDTree(table, balanced_tree=False, compact_nodes=False) \
            .query(pts[~sure])[1]
    return out


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


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / _norms(v)[..., None]


def _norms(v):
    """Lengths of vectors along the last axis: np.linalg.norm's sum of squares, without its
    per-call overhead (the hot loops call it tens of thousands of times)."""
    return np.sqrt(np.einsum("...i,...i->...", v, v))


def _angle_deg(direction, axis):
    cross = axis[0] * direction[1] - axis[1] * direction[0]
    return float(np.degrees(np.arctan2(cross, np.dot(axis, direction))))


def _cross2(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


# ---------------------------------------------------------------- inscribed circles

@dataclass
class _Side:
    lo: float     # unwrapped parameter range of the side, lo < hi
    hi: float
    u: np.ndarray
    xy: np.ndarray
    tree: cKDTree


def _side_range(profile, lo, hi):
    """A side's unwrapped parameter range, lo < hi (as _side's)."""
    return _Range(lo, hi + profile.length if hi <= lo else hi)


def _side(profile, lo, hi):
    side = _side_range(profile, lo, hi)
    lo, hi = side.lo, side.hi
    u = profile.dense_u.copy()
    u = np.where(u < lo, u + profile.length, u)
    keep = (u >= lo) & (u <= hi)
    u = np.sort(u[keep])
    xy = profile.eval(u)
    return _Side(lo, hi, u, xy, cKDTree(xy))


def _refine_centres(profile, a, b, centre):
    """Centres equidistant from sides a and b (the medial axis between them), by Newton on
    d_a - d_b along its gradient (the difference of the unit vectors from the feet). The feet
    are global nearest points at the start and the end, Newton-tracked in between."""
    c = centre.copy()
    ua, ub = None, None
    # Each centre stops once its own |d_a - d_b| < 1e-11 mm (its last step taken): a settled
    # centre's further steps are below that, and the run's cost is the unsettled ones'.
    run = np.arange(len(c))
    for _ in range(30):
        ua, ub, fa, fb = _feet(profile, a, b, c[run], ua, ub)
        cr = c[run]
        va, vb = cr - fa, cr - fb
        da, db = _norms(va), _norms(vb)
        g = va / da[:, None] - vb / db[:, None]
        g2 = np.einsum("ij,ij->i", g, g)
        f = da - db
        ok = g2 > 1e-12
        cr[ok] -= (f[ok] / g2[ok])[:, None] * g[ok]
        c[run] = cr
        going = np.abs(f) >= 1e-11
        if not going.any():
            break
        run, ua, ub = run[going], ua[going], ub[going]
    ua, ub, fa, fb = _feet(profile, a, b, c)
    return c, ua, ub, fa, fb


def _feet(profile, a, b, xy, ua=None, ub=None):
    """The feet of ``xy`` on side a and on side b: from the nearest side samples (or from ua,
    ub), by Newton kept within each side's range; both sides in one run (half the calls)."""
    if ua is None:
        ua = a.u[a.tree.query(xy)[1]]
        ub = b.u[b.tree.query(xy)[1]]
    n = len(xy)
    lo = np.concatenate([np.full(n, a.lo), np.full(n, b.lo)])
    hi = np.concatenate([np.full(n, a.hi), np.full(n, b.hi)])
    u, foot = profile.closest(np.vstack([xy, xy]), np.concatenate([ua, ub]), lo, hi)
    return u[:n], u[n:], foot[:n], foot[n:]


_SEED_ROWS = 32            # _seed_radii: feet per block (its arrays stay in the cache)


def _seed_radii(fa, inward, q):
    """The largest circle tangent at each foot ``fa`` (inward normal ``inward``) that no point
    of ``q`` enters: min over q of |q - fa|^2 / (2 (q - fa) . inward), over the q ahead of the
    tangent (0 when none is). The feet a block at a time in preallocated arrays: the same
    arithmetic, a quarter of the time of one (feet, q) array per quantity."""
    n, m = len(fa), len(q)
    out = np.empty(n)
    qx, qy = q[None, :, 0], q[None, :, 1]
    rows = max(1, min(_SEED_ROWS, n))
    bufs = [np.empty((rows, m)) for _ in range(4)]
    ahead = np.empty((rows, m), dtype=bool)
    for k in range(0, n, rows):
        r = min(rows, n - k)
        dx, dy, num, den = (x[:r] for x in bufs)
        ok = ahead[:r]
        np.subtract(qx, fa[k:k + r, 0:1], out=dx)
        np.subtract(qy, fa[k:k + r, 1:2], out=dy)
        np.multiply(dx, dx, out=num)             # num = dx^2 + dy^2
        np.multiply(dy, dy, out=den)
        num += den
        np.multiply(dx, inward[k:k + r, 0:1], out=den)    # den = 2 (dx n_x + dy n_y)
        dy *= inward[k:k + r, 1:2]
        den += dy
        den *= 2.0
        np.greater(den, 1e-12, out=ok)
        dx.fill(np.inf)
        np.divide(num, den, out=dx, where=ok)
        dx.min(axis=1, out=out[k:k + r])
    return np.where(np.isfinite(out), out, 0.0)


def _circles_from_feet(profile, a, b, ua0):
    """Inscribed circles seeded at feet ua0 on side a: the largest circle tangent there that no
    point of b enters, refined to be exactly equidistant from both sides. Returns centres,
    radii, feet parameters on a, and whether each is a circle of the camber line."""
    fa = profile.eval(ua0)
    inward = -profile.outward_normal(ua0)
    r0 = _seed_radii(fa, inward, b.xy[::_SEED_STRIDE])
    centre = fa + r0[:, None] * inward
    c, ua, ub, fa, fb = _refine_centres(profile, a, b, centre)
    r = _norms(fa - c)
    va, vb = _unit(fa - c), _unit(fb - c)
    contact = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", va, vb), -1, 1)))
    tol = 1e-9 * profile.length
    interior = (ua > a.lo + tol) & (ua < a.hi - tol) & (ub > b.lo + tol) & (ub < b.hi - tol)
    # A circle of the camber line leaves the profile between its two contacts, round the
    # nearer edge; the edge circle itself (an exact circular edge) runs along it there.
    via_lo = (ua - a.lo) + (b.hi - ub) < (a.hi - ua) + (ub - b.lo)
    mid = np.where(via_lo, (ua + ub - profile.length) / 2.0, (ua + ub) / 2.0)
    gap = _norms(profile.eval(mid) - c) - r
    # Inscribed: no point of the profile nearer than the contacts (a foot stuck at a local
    # stationary point next to a closer edge would make a circle that crosses the profile).
    nearest = _norms(profile.closest(c)[1] - c)
    inscribed = nearest > r - 1e-9 * np.maximum(r, 1.0)
    ok = ((r0 > 0) & interior & inscribed & (contact >= MIN_CONTACT_ANGLE_DEG)
          & (gap > _EDGE_GAP * r))
    return c, r, ua, ok


def _medial_axis(profile, a, b):
    """Inscribed circles between sides a and b, ordered from a's start to its end, from feet
    clustered towards a's ends; each end of the run of camber-line circles is then closed in
    on by rounds of finer feet, so the run reaches the edges to a small fraction of a step."""
    t = (1.0 - np.cos(np.linspace(0.0, np.pi, _FEET))) / 2.0
    feet = a.lo + (a.hi - a.lo) * t[1:-1]
    c, r, ua, ok = _circles_from_feet(profile, a, b, feet)
    # The camber line is the longest run of camber-line circles; a stray one seeded on an edge
    # (a degenerate bisector that slid onto the axis) does not start it.
    edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(int), [0]])))
    starts, stops = edges[::2], edges[1::2]
    # metal-angle hook: a lone circle mid-locus that fails (a foot refined onto a wrong
    # stationary point) must not cut the camber line in two -- its longer half alone put
    # the metal angle's window on half the locus (28 mdeg on the demo blade's 90 % section
    # under a 0.2 um deviation); two runs apart by at most _RUN_GAP failed circles are one
    # when each is at least _RUN_MIN circles. Near a noisy edge circles fail here and there
    # too: Rotor 67's 10 % TE, planned, one scan in 24 ended its locus 0.8 mm short of the
    # edge when short runs were not joined (the outlet angle 0.30 deg off); a stray among
    # them is the end window's to drop (_end_quartic).
    merged = []
    for first, stop in zip(starts, stops):
        left, right = merged[-1][1] - merged[-1][2] if merged else 0, stop - first
        if merged and first - merged[-1][1] <= _RUN_GAP \
                and min(left, right) >= _RUN_MIN:
            merged[-1] = [merged[-1][0], stop, first]
        else:
            merged.append([first, stop, first])
    starts = np.array([m[0] for m in merged], dtype=int)
    stops = np.array([m[1] for m in merged], dtype=int)
    longest = int(np.argmax(stops - starts)) if len(starts) else 0
    if not len(starts) or stops[longest] - starts[longest] < 4:
        raise InputError("airfoil profile: fewer than 4 inscribed circles between its sides; "
                         "not an airfoil-like closed profile")
    run = starts[longest] + np.flatnonzero(ok[starts[longest]:stops[longest]])
    # The two ends' rounds are independent: each round closes in on both at once (one
    # vectorised call for the feet of both ends).
    brackets = {}
    for end, (inner, outer) in enumerate(((run[0], run[0] - 1), (run[-1], run[-1] + 1))):
        u_out = feet[outer] if 0 <= outer < len(feet) else (a.lo if outer < 0 else a.hi)
        brackets[end] = (feet[inner], u_out)
    by_end = {0: [], 1: []}
    for _ in range(_END_ROUNDS):
        if not brackets:
            break
        ends = sorted(brackets)
        subs = [np.linspace(*brackets[end], _END_FEET) for end in ends]
        cs, rs, uas, oks = _circles_from_feet(profile, a, b, np.concatenate(subs))
        for j, (end, sub) in enumerate(zip(ends, subs)):
            part = slice(j * _END_FEET, (j + 1) * _END_FEET)
            ok = oks[part]
            by_end[end].append((cs[part][ok], rs[part][ok], uas[part][ok]))
            n_run = len(ok) if ok.all() else int(np.argmin(ok))
            if n_run == 0 or n_run == len(ok):
                del brackets[end]
            else:
                brackets[end] = (sub[n_run - 1], sub[n_run])
    found = [(c[run], r[run], ua[run])] + by_end[0] + by_end[1]
    c = np.vstack([f[0] for f in found])
    r = np.concatenate([f[1] for f in found])
    order = np.argsort(np.concatenate([f[2] for f in found]))
    c, r = c[order], r[order]
    # Near a circular edge the feet crowd at the edge's tangency points and their order may
    # differ from the centres' by far below a micrometre: walking out from the middle, keep
    # the centres that go on in the direction of the axis.
    # (a walk centre by centre: in Python floats, a numpy call per centre cost more)
    mid = len(c) // 2
    keep = [mid, mid + 1]
    cl = c.tolist()
    for step in (1, -1):
        chain = keep if step == 1 else keep[::-1]
        i = chain[-1] + step
        while 0 <= i < len(c):
            (lx, ly), (bx, by), (x, y) = cl[chain[-1]], cl[chain[-2]], cl[i]
            dx, dy = x - lx, y - ly
            if dx * (lx - bx) + dy * (ly - by) > 0 and math.sqrt(dx * dx + dy * dy) > 1e-9:
                chain.append(i)
            i += step
        keep = chain if step == 1 else chain[::-1]
    keep = np.array(keep)
    return _thin(c[keep], r[keep])


def _thin(c, r):
    """Centres at least _MCL_SPACING_MM apart, both end centres kept: the closing-in rounds
    pack centres far closer than their sub-nanometre scatter allows a tangent to be taken."""
    cl = c.tolist()       # (Python floats: a numpy call per centre cost more)

    def apart(i, j):
        dx, dy = cl[i][0] - cl[j][0], cl[i][1] - cl[j][1]
        return math.sqrt(dx * dx + dy * dy)

    keep = [0]
    for i in range(1, len(c)):
        if apart(i, keep[-1]) >= _MCL_SPACING_MM:
            keep.append(i)
    if keep[-1] != len(c) - 1:
        if len(keep) > 1 and apart(len(c) - 1, keep[-1]) < _MCL_SPACING_MM:
            keep[-1] = len(c) - 1
        else:
            keep.append(len(c) - 1)
    return c[keep], r[keep]


# ---------------------------------------------------------------- mean camber line

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
        t = _unit(self._spline(inner, 1))
        before = s < self.le_extension
        after = s > self.le_extension + self.inner_length
        # The extensions run straight from the end centres to the edge points (which lie on
        # the end tangents but for the edge circle's centre's offset from them, _edge_point);
        # their tangents are the end tangents (the metal angles).
        p[before] = self.centres[0] + (s[before] - self.le_extension)[:, None] * self._le_dir
        t[before] = self.le_tangent
        p[after] = self.centres[-1] + (s[after] - self.le_extension
                                       - self.inner_length)[:, None] * self._te_dir
        t[after] = self.te_tangent
        return p, t

    def sample(self, n=400):
        return self.at(np.linspace(0.0, self.length, n))[0]


def _line_end(centres, radii, end, edge=None, window_pct=DEFAULT_METAL_ANGLE_WINDOW_PCT):
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
    c, r, s, sel, full = _end_quartic(c, r, edge, window_pct)
    skip = _END_SKIP * (r[-1] if edge is None else edge.radius)
    deriv = np.column_stack([np.polyder(full[:, k]) for k in range(2)])
    tangent = _unit(full[-2])
    # How far the last stretch turns from that tangent: the metal angle's definition spread.
    last = s >= -skip
    bend = 0.0
    if last.sum() >= 2 and np.linalg.norm(c[-1] - c[last][0]) > 0:
        chord = _unit(c[-1] - c[last][0])
        bend = float(np.degrees(np.arccos(np.clip(chord @ tangent, -1.0, 1.0))))
    if edge is not None:
        # The line ends on the fitted quartic (not at the last, least conditioned centre),
        # at its point abreast of the edge circle's centre, ahead of the last centre or behind.
        reach = 0.0
        for _ in range(8):
            p = np.array([np.polyval(full[:, k], reach) for k in range(2)])
            d = _unit(np.array([np.polyval(deriv[:, k], reach) for k in range(2)]))
            reach = float(np.clip(reach + (edge.center - p) @ d, s[sel][0], edge.radius))
        tip = np.array([np.polyval(full[:, k], reach) for k in range(2)])
        tangent = _unit(np.array([np.polyval(deriv[:, k], reach) for k in range(2)]))
        keep = s < reach - 1e-9
        c, r = np.vstack([c[keep], tip]), np.concatenate([r[keep], [edge.radius]])
    if end == 0:
        return c[::-1], r[::-1], tangent, bend
    return c, r, tangent, bend


def _arc_from_end(c):
    """Arc lengths along the centres, 0 at the last one and negative before it."""
    s = np.concatenate([[0.0], np.cumsum(_norms(np.diff(c, axis=0)))])
    return s - s[-1]


def _end_quartic(c, r, edge, window_pct):
    """The end window's quartic of the centres (ordered towards the end), the centres off the
    locus dropped first: a centre refined onto a wrong foot (inscribed, but 0.13 mm off the
    locus, once in 20 scans at sigma = 2 um) had tilted the end tangent by 49 mdeg. Returns the
    kept centres and radii, their arc lengths, the window's selection of them and the
    quartic's coefficients (np.polyfit's, one column per axis). On the exact nominal no centre
    is dropped: the fit, and so the angle, is the former rule's to the bit."""
    s = _arc_from_end(c)
    # The last stretch of the locus bends towards the centre of curvature of the edge's
    # tightest point when the edge is not a circle: it is left out of the fit.
    skip = _END_SKIP * (r[-1] if edge is None else edge.radius)

    def window_of(s):
        window = window_pct / 100.0 * -s[0]
        sel = (s >= -(skip + window)) & (s <= -skip)
        if sel.sum() < 2 * _END_DEGREE:
            sel = np.arange(len(s)) >= len(s) - 2 * _END_DEGREE
        return sel

    sel = window_of(s)
    for _ in range(_END_OUTLIER_ROUNDS):
        fit = np.polyfit(s[sel], c[sel], _END_DEGREE)
        off = _norms(c - np.column_stack([np.polyval(fit[:, k], s) for k in range(2)]))
        spread = 1.4826 * np.median(off[sel])
        stray = sel & (off > max(_END_OUTLIER_SIGMAS * spread, _END_OUTLIER_FLOOR_MM))
        if not stray.any():
            break
        c, r = c[~stray], r[~stray]
        s = _arc_from_end(c)
        sel = window_of(s)
    full = np.polyfit(s[sel], c[sel], _END_DEGREE)
    return c, r, s, sel, full


def _closed_end(profile, centres, radii, end, circle, notes, window_pct):
    """The line closed onto the fitted edge circle at one end (see _line_end) and its edge
    point; when the closed end's tangent does not meet the profile (a corner, a clipped
    section), the unclosed end, with a note saying so."""
    c, r, out, bend = _line_end(centres, radii, end, circle, window_pct)
    try:
        u, point = _ray_hit(profile, c[end], out)
    except InputError:
        c, r, out, bend = _line_end(centres, radii, end, window_pct=window_pct)
        u, point = _ray_hit(profile, c[end], out, behind=True)
        notes.append("the camber line's end at (%.4f, %.4f) mm could not be brought abreast "
                     "of its edge circle; it ends at its last inscribed circle"
                     % tuple(c[end]))
    if bend > _BEND_WARN_DEG:
        notes.append("the camber line turns %.2f deg from its end tangent within its last "
                     "half edge radius near (%.4f, %.4f) mm (the edge is not a circle): the "
                     "metal angle there depends on the rule (docs/airfoil.md)"
                     % (bend, c[end][0], c[end][1]))
    return c, r, out, u, point


def _ray_hit(profile, origin, direction, behind=False):
    """First crossing of the ray origin + tau * direction (tau > 0) with the profile; with
    ``behind``, when there is none, the line's nearest crossing behind the origin."""
    p, q = profile.dense, np.roll(profile.dense, -1, axis=0)
    e = q - p
    den = _cross2(direction, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = _cross2(p - origin, e) / den
        lam = _cross2(p - origin, direction) / den
    ok = (np.abs(den) > 1e-15) & (lam >= 0) & (lam <= 1) & (tau > 0)
    if not np.any(ok):
        # metal-angle hook: an origin outside the profile (the camber locus's last centre in
        # a sharp corner of a noisy profile, which the smooth fit rounds off) crosses it
        # first just behind itself: that crossing, for the edge the circle is fitted about
        # (Rotor 67's 90 % TE, planned: 2-7 scans in 24 lost the whole section, the centre
        # 25-60 um outside the fit).
        ok = behind & (np.abs(den) > 1e-15) & (lam >= 0) & (lam <= 1) & (tau <= 0)
        tau = np.where(ok, -tau, tau)
    if not np.any(ok):
        raise InputError("airfoil profile: the camber line's end tangent leaves the profile "
                         "without crossing it; the profile is not closed around it")
    i = np.flatnonzero(ok)[np.argmin(tau[ok])]
    return _line_hit(profile, origin, direction, profile.dense_u[i]
                     + lam[i] * (profile.length / len(profile.dense)))


# The edge point on noisy points (docs/airfoil.md, "LE and TE points"): the input points'
# distances from the edge circle's centre, a weighted local quadratic in their angle from the
# camber line's direction over +-_EDGE_POINT_DEG (biweight), read at angle 0.
_EDGE_POINT_DEG = 15.0


def _edge_point(profile, circle, outward, noise_mm, u_line, p_line):
    """The edge point: where the ray from the edge circle's centre along the camber line's
    outward end direction meets the profile. Noise-free, the profile is the interpolating
    spline (its exact crossing). On noisy points it is the input points themselves seen from
    the centre: their distance as a local quadratic in the angle from the ray, weighted by a
    biweight that falls to zero at +-_EDGE_POINT_DEG (so a point entering or leaving moves it
    by nothing), when at least _ZONE_MIN_POINTS points weigh in; else the smoothing spline's
    crossing. The smoothing spline's knots -- FITPACK's, re-chosen by the data -- change with
    every micrometre the points move and tilt its edges by micrometres; the input points and
    the circle fitted to them (_edge_circle) do not jump. Returns (parameters, points) as
    _ray_hit; (u_line, p_line), the extended camber line's crossing, when the ray misses."""
    centre = np.asarray(circle.center, dtype=float)
    direction = _unit(np.asarray(outward, dtype=float))
    if noise_mm > 0:
        v = profile.points - centre
        ang = np.arctan2(_cross2(direction, v), v @ direction)
        x = ang / np.radians(_EDGE_POINT_DEG)
        near = np.abs(x) < 1.0
        if near.sum() >= _ZONE_MIN_POINTS:
            sw = 1.0 - x[near] ** 2          # the square root of the biweight
            q = np.polyfit(x[near], _norms(v[near]), 2, w=sw)
            point = centre + q[-1] * direction
            u, _ = profile.closest(point)
            return u, point[None, :]
    try:
        return _ray_hit(profile, centre, direction)
    except InputError:
        return u_line, p_line


def _line_hit(profile, origin, direction, u):
    """Newton on cross(S(u) - origin, direction) = 0 from u: the crossing of a line."""
    u = np.atleast_1d(np.asarray(u, dtype=float))
    origin = np.atleast_2d(origin)
    direction = np.atleast_2d(direction)
    for _ in range(_NEWTON_ITERATIONS):
        p, d1 = profile.eval01(u)
        f = _cross2(p - origin, direction)
        df = _cross2(d1, direction)
        u = u - f / np.where(np.abs(df) > 1e-15, df, 1e-15)
    return u, profile.eval(u)


def _thickness_normal(profile, mcl, s):
    """Thickness normal to the camber line at arc lengths s: the chord of the profile cut by
    the camber line's normal there (nearest crossing on each side)."""
    m, t = mcl.at(s)
    n = np.column_stack([-t[:, 1], t[:, 0]])
    out = np.full(len(s), np.nan)
    p, q = profile.dense, np.roll(profile.dense, -1, axis=0)
    e = q - p
    h = profile.length / len(profile.dense)
    # every station against every dense segment at once (rows: stations), _cross2's
    # arithmetic element by element
    pm = p[None, :, :] - m[:, None, :]
    n0, n1 = n[:, 0:1], n[:, 1:2]
    den = n0 * e[None, :, 1] - n1 * e[None, :, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = _cross2(pm, e[None]) / den
        lam = (pm[..., 0] * n1 - pm[..., 1] * n0) / den
    ok = (np.abs(den) > 1e-15) & (lam >= 0) & (lam <= 1)
    plus, minus = ok & (tau > 0), ok & (tau < 0)
    found = np.flatnonzero(plus.any(axis=1) & minus.any(axis=1))
    if len(found):
        # the nearest crossing on each side: the first of the least positive tau, of the
        # greatest negative one
        ip = np.argmin(np.where(plus[found], tau[found], np.inf), axis=1)
        im = np.argmax(np.where(minus[found], tau[found], -np.inf), axis=1)
        seg = np.column_stack([ip, im]).ravel()
        rows = np.repeat(found, 2)
        starts = profile.dense_u[seg] + lam[rows, seg] * h
        # every crossing's Newton run in one call (each runs its fixed steps alone)
        _, xy = _line_hit(profile, m[rows], n[rows], starts)
        out[found] = _norms(xy[0::2] - xy[1::2])
    return out


# The max-thickness position (docs/airfoil.md, "Thickness"): the vertex of a weighted
# least-squares quartic of the exact inscribed radii against their centres' projection on the
# nose-tail chord, over +-_MAX_POS_WINDOW of the chord about the vertex itself (biweight),
# _MAX_POS_SAMPLES circles a round.
_MAX_POS_WINDOW = 0.05
_MAX_POS_SAMPLES = 61
_MAX_POS_ROUNDS = 20


def _max_thickness_position(profile, a, b, mcl, s0, c0, window, le, chord_dir):
    """The max-thickness position along the chord (mm from ``le``) and the inscribed circle's
    centre there: a fixed point of "fit the radius's quartic over +-window about x, move x to
    its vertex", from the largest circle (arc length s0 along ``mcl``, its refined centre
    c0). The abscissae are the refined centres' own projections and the weights fall
    smoothly to zero at the window's ends, so the vertex is a continuous function of the
    points -- the largest circle's own position jumps between the flat maximum's local
    maxima."""
    half = min(float(window), 0.45 * mcl.length)
    grid = np.linspace(-1.1, 1.1, _MAX_POS_SAMPLES)
    s = float(s0)
    x = float((c0 - le) @ chord_dir)
    slope = 1.0                       # ds / dx along the camber line, re-estimated each round
    for _ in range(_MAX_POS_ROUNDS):
        seeds, _ = mcl.at(np.clip(s + slope * half * grid, 0.0, mcl.length))
        cs, _, _, fs, _ = _refine_centres(profile, a, b, seeds)
        r, t = _norms(fs - cs), ((cs - le) @ chord_dir - x) / half
        inside = np.abs(t) < 1.0
        if inside.sum() < 2 * _END_DEGREE:
            break
        q = np.polyfit(t[inside], r[inside], 4, w=1.0 - t[inside] ** 2)
        roots = np.roots(np.polyder(q))
        roots = roots[np.abs(roots.imag) < 1e-12].real
        roots = roots[(np.abs(roots) < 1.0) & (np.polyval(np.polyder(q, 2), roots) < 0)]
        if not len(roots):
            break
        step = half * float(roots[np.argmin(np.abs(roots))])
        slope = float(np.polyfit(t * half, s + slope * half * grid, 1)[0])
        s, x = s + slope * step, x + step
        if abs(step) < 1e-9:
            break
    seed, _ = mcl.at(s)
    return x, _refine_centres(profile, a, b, seed)[0][0]


# ---------------------------------------------------------------- extents and chords

def _support(profile, direction, sign):
    """The profile point furthest along sign * direction (Newton on S'(u).d = 0)."""
    proj = sign * (profile.dense @ direction)
    u = np.array([profile.dense_u[np.argmax(proj)]])
    for _ in range(_NEWTON_ITERATIONS):
        _, d1, d2 = profile.eval3(u)
        g = d1 @ direction
        h = d2 @ direction
        u = u - g / np.where(np.abs(h) > 1e-15, h, 1e-15)
    return profile.eval(u)[0]


def extent(profile, direction):
    """Length of the profile's projection on ``direction`` (its caliper width along it)."""
    d = _unit(direction)
    return float((_support(profile, d, 1) - _support(profile, d, -1)) @ d)


_PAIR_ROWS = 64


def _farthest_column(xy):
    """j of the first (row-major) pair (i, j) of points furthest apart: the argmax of the
    (n, n) matrix of x^2 + y^2 (two planes: a sum over a length-2 last axis is numpy's slow
    case), a block of _PAIR_ROWS rows at a time in two preallocated arrays (the same
    arithmetic, a third of the time of whole-matrix temporaries)."""
    n = len(xy)
    rows = max(1, min(_PAIR_ROWS, n))
    x, y = xy[None, :, 0], xy[None, :, 1]
    bx, by = np.empty((rows, n)), np.empty((rows, n))
    best, where = None, 0
    for k in range(0, n, rows):
        r = min(rows, n - k)
        dx, dy = bx[:r], by[:r]
        np.subtract(xy[k:k + r, 0:1], x, out=dx)
        np.subtract(xy[k:k + r, 1:2], y, out=dy)
        np.square(dx, out=dx)
        np.square(dy, out=dy)
        dx += dy
        a = int(np.argmax(dx))
        if best is None or dx.flat[a] > best:      # (a tie: the earlier pair, as argmax)
            best, where = dx.flat[a], a % n
    return where


def _farthest_pair(profile):
    """Maximum Feret (caliper) diameter: the two profile points furthest apart. Each end is the
    point of the curve furthest from the other: the furthest dense sample, then Newton steps
    kept within one sample spacing (a step must not run off to the nearest point, which is
    stationary too)."""
    hull = profile.dense[profile.hull_vertices()]
    hull = hull[::max(1, len(hull) // 400)]
    j = _farthest_column(hull)
    spacing = profile.length / len(profile.dense)
    uj = profile.nearest_param(hull[j])

    def furthest_from(u_other):
        p = profile.eval(u_other)[0]
        v = profile.dense - p
        u = profile.dense_u[[int(np.argmax(np.einsum("ij,ij->i", v, v)))]]
        start = u.copy()
        for _ in range(_NEWTON_ITERATIONS):
            new = np.clip(profile._newton_stationary(u, p), start - spacing, start + spacing)
            done = abs(new[0] - u[0]) < 1e-13 * profile.length
            u = new
            if done:
                break
        return u

    ui = furthest_from(uj)
    for _ in range(6):
        before = (ui[0], uj[0])
        uj = furthest_from(ui)
        ui = furthest_from(uj)
        if abs(ui[0] - before[0]) < 1e-13 * profile.length \
                and abs(uj[0] - before[1]) < 1e-13 * profile.length:
            break   # each end the furthest point from the other: the pair is settled
    return ui[0], uj[0], profile.eval(ui)[0], profile.eval(uj)[0]


def _tangent_from(profile, point, u):
    """Newton on cross(S(u) - point, S'(u)) = 0: where a line from ``point`` touches."""
    u = np.atleast_1d(float(u))
    for _ in range(_NEWTON_ITERATIONS):
        p, d1, d2 = profile.eval3(u)
        d = p - point
        step = _cross2(d, d1) / np.where(np.abs(_cross2(d, d2)) > 1e-15, _cross2(d, d2), 1e-15)
        u = u - step
        if abs(step[0]) < 1e-13 * profile.length:
            break
    return u[0]


def _pressure_bitangent(profile, pressure, le_u, te_u):
    """The line touching the profile at both edges across the pressure side, as (point near
    the LE, point near the TE), or None when the pressure side is not concave."""
    hull = np.sort(profile.hull_vertices())
    hu = profile.dense_u[hull]
    gaps = np.diff(np.concatenate([hu, [hu[0] + profile.length]]))
    k = int(np.argmax(np.where(_in_range(hu + gaps / 2, pressure, profile.length), gaps, 0)))
    if gaps[k] < 0.2 * (pressure.hi - pressure.lo):
        return None
    u1, u2 = hu[k], hu[k] + gaps[k]
    for _ in range(20):
        before = (u1, u2)
        u1 = _tangent_from(profile, profile.eval([u2])[0], u1)
        u2 = _tangent_from(profile, profile.eval([u1])[0], u2)
        if max(abs(u1 - before[0]), abs(u2 - before[1])) < 1e-12 * profile.length:
            break
    p1, p2 = profile.eval([u1])[0], profile.eval([u2])[0]
    le = profile.eval([le_u])[0]
    if np.linalg.norm(p1 - le) > np.linalg.norm(p2 - le):
        p1, p2 = p2, p1
    return p1, p2


def _in_range(u, side, length):
    u = np.mod(u - side.lo, length)
    return u <= side.hi - side.lo


# ---------------------------------------------------------------- edge circles

@dataclass
class CircleFit2D:
    center: np.ndarray
    radius: float
    rms: float
    n_points: int
    zone_deg: float


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


def _edge_circle(profile, end_centre, outward, edge_u, zone_deg):
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
        xy, key = _zone_points(profile, lo, hi)
        zone = (lo, hi)
        earlier = [k for k, (kk, _) in enumerate(seen) if key is not None and kk == key]
        if earlier:
            if earlier[-1] == len(seen) - 1:      # the same points: the same fit, converged
                break
            cycle = [fit for _, fit in seen[earlier[-1]:]]
            centre, radius, rms, n = max(cycle, key=lambda f: f[3])
            return CircleFit2D(centre, radius, rms, n, zone_deg)
        centre, radius, rms = fit_circle_2d(xy)
        seen.append((key, (centre, radius, rms, len(xy))))
    centre, radius, rms, n = seen[-1][1]
    return CircleFit2D(centre, radius, rms, n, zone_deg)


def _zone_points(profile, lo, hi):
    """The input points in the parameter range [lo, hi] (unwrapped) when there are at least
    _ZONE_MIN_POINTS of them -- measured points fit without any smoothing's bias -- else the
    profile curve resampled finely over it. Returns the points and a key of the input points
    taken (None for a resampled curve, which moves with the range)."""
    u = np.mod(profile.point_params - lo, profile.length)
    inside = u <= hi - lo
    if inside.sum() >= _ZONE_MIN_POINTS:
        return profile.points[inside], np.flatnonzero(inside).tobytes()
    return profile.eval(np.linspace(lo, hi, _ZONE_SAMPLES)), None


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
    seen_near = _unit(profile.dense[near] - centre) @ outward >= cos_zone
    ahead_near = np.flatnonzero(~seen_near[_ZONE_WINDOW:])
    behind_near = np.flatnonzero(~seen_near[_ZONE_WINDOW::-1][1:])
    if 2 * _ZONE_WINDOW + 1 < n and len(ahead_near) and len(behind_near):
        ahead = int(ahead_near[0])               # first sample outside, going forwards
        behind = int(behind_near[0])             # first sample outside, going backwards
    else:
        seen = np.roll(_unit(profile.dense - centre) @ outward >= cos_zone, -i0)
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
        ok = (_unit(profile.eval(trial.ravel()) - centre) @ outward >= cos_zone)
        ok = ok.reshape(trial.shape)
        # the last grid point inside before the first one outside
        first_out = np.where(ok.all(axis=1), _ZONE_GRID - 1, np.argmin(ok, axis=1))
        a = a + step * first_out / _ZONE_GRID
        step = step / _ZONE_GRID
    return float(a[0]), float(a[1])


# ---------------------------------------------------------------- the characteristics

@dataclass
class Characteristics:
    """One section's characteristics (field names as result.json's ``airfoil`` block)."""
    chord_mm: float
    chord_method: str
    nose_tail_chord_mm: float
    caliper_chord_mm: float
    tangent_chord_mm: Optional[float]
    axial_chord_mm: float
    stagger_deg: float
    max_thickness_mm: float
    max_thickness_pos_pct: float
    max_thickness_center: np.ndarray
    thickness_stations_pct: list
    thickness_mm: list
    le_radius_mm: float
    te_radius_mm: float
    le_circle: CircleFit2D
    te_circle: CircleFit2D
    edge_offsets_mm: list
    le_thickness_mm: list
    te_thickness_mm: list
    inlet_angle_deg: float
    outlet_angle_deg: float
    area_mm2: float
    centroid_mm: np.ndarray
    le_point: np.ndarray
    te_point: np.ndarray
    chord_dir: np.ndarray
    engine_axis: np.ndarray
    le_rule: str
    mcl: CamberLine
    inscribed_centres: np.ndarray
    inscribed_radii: np.ndarray
    profile: Profile = field(repr=False)
    suction_range: tuple = ()     # unwrapped parameter ranges of the two sides
    pressure_range: tuple = ()
    warnings: list = field(default_factory=list)

    def edge_circles(self):
        """[("LE" or "TE", CircleFit2D)] of the edges whose radius is reported: an edge
        withheld by withhold_corner_edges (radius None) keeps its fit on the record, but a
        circle drawn for it would show a radius the result says is not measurable."""
        return [(name, circle) for name, circle, radius in
                (("LE", self.le_circle, self.le_radius_mm),
                 ("TE", self.te_circle, self.te_radius_mm)) if radius is not None]

    def as_dict(self):
        return {
            "chord_mm": self.chord_mm, "chord_method": self.chord_method,
            "nose_tail_chord_mm": self.nose_tail_chord_mm,
            "caliper_chord_mm": self.caliper_chord_mm,
            "tangent_chord_mm": self.tangent_chord_mm,
            "axial_chord_mm": self.axial_chord_mm, "stagger_deg": self.stagger_deg,
            "max_thickness_mm": self.max_thickness_mm,
            "max_thickness_pos_pct": self.max_thickness_pos_pct,
            "thickness_stations_pct": list(self.thickness_stations_pct),
            "thickness_mm": list(self.thickness_mm),
            "le_radius_mm": self.le_radius_mm, "te_radius_mm": self.te_radius_mm,
            "edge_zone_deg": self.le_circle.zone_deg,
            "edge_offsets_mm": list(self.edge_offsets_mm),
            "le_thickness_mm": list(self.le_thickness_mm),
            "te_thickness_mm": list(self.te_thickness_mm),
            "inlet_angle_deg": self.inlet_angle_deg, "outlet_angle_deg": self.outlet_angle_deg,
            "area_mm2": self.area_mm2, "centroid_mm": self.centroid_mm.tolist(),
            "le_point_mm": self.le_point.tolist(), "te_point_mm": self.te_point.tolist(),
            "le_rule": self.le_rule, "warnings": list(self.warnings),
        }


# ---------------------------------------------------------------- a computed section kept

def characteristics_state(ch):
    """A Characteristics as JSON-ready data, its profile left out (the caller keeps the points
    it was made from: characteristics_from_state rebuilds it). Floats are written as Python
    floats, whose JSON text (repr) reads back to the same bits, so a state read back is the
    computed section to the bit (an uncertainty task file keeps its nominal cuts so)."""
    state = {}
    for f in dataclasses.fields(Characteristics):
        if f.name == "profile":
            continue
        state[f.name] = _state_value(getattr(ch, f.name))
    return state


def characteristics_from_state(state, profile):
    """The Characteristics of ``state`` (characteristics_state) on ``profile``: the Profile of
    the points the state was computed from. A state missing a field or holding a value of the
    wrong kind raises InputError."""
    try:
        values = {f.name: _value_of_state(state[f.name])
                  for f in dataclasses.fields(Characteristics) if f.name != "profile"}
        return Characteristics(profile=profile, **values)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise InputError("airfoil characteristics state: damaged (%s: %s)"
                         % (type(exc).__name__, exc))


def _state_value(v):
    if isinstance(v, np.ndarray):
        if v.dtype.kind == "f" and not np.all(np.isfinite(v)):
            return {"ndarray": [_state_value(x) for x in v.tolist()], "dtype": v.dtype.str}
        return {"ndarray": v.tolist(), "dtype": v.dtype.str}
    if isinstance(v, CircleFit2D):
        return {"circle": {f.name: _state_value(getattr(v, f.name))
                           for f in dataclasses.fields(CircleFit2D)}}
    if isinstance(v, CamberLine):
        return {"camber_line": {name: _state_value(getattr(v, name)) for name in
                                ("le", "centres", "te", "le_tangent", "te_tangent")}}
    if isinstance(v, tuple):
        return {"tuple": [_state_value(x) for x in v]}
    if isinstance(v, list):
        return [_state_value(x) for x in v]
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        # JSON has no NaN or infinity (a thickness station off the profile is NaN)
        return float(v) if math.isfinite(v) else {"float": repr(float(v))}
    if v is None or isinstance(v, str):
        return v
    raise TypeError("no state for a %s" % type(v).__name__)


def _value_of_state(v):
    if isinstance(v, dict):
        if "ndarray" in v:
            return np.array(_value_of_state(v["ndarray"]), dtype=np.dtype(v["dtype"]))
        (kind, body), = v.items()
        if kind == "circle":
            return CircleFit2D(**{k: _value_of_state(x) for k, x in body.items()})
        if kind == "camber_line":
            return CamberLine(**{k: _value_of_state(x) for k, x in body.items()})
        if kind == "tuple":
            return tuple(_value_of_state(x) for x in body)
        if kind == "float":
            return float(body)
        raise ValueError("unknown kind %r" % kind)
    if isinstance(v, list):
        return [_value_of_state(x) for x in v]
    return v


def characteristics(profile, engine_axis=(1.0, 0.0), chord_method="nose-tail",
                    stations_pct=(), edge_offsets_mm=DEFAULT_EDGE_OFFSETS_MM,
                    edge_zone_deg=DEFAULT_EDGE_ZONE_DEG, le_hint=None, noise_mm=0.0,
                    le_upstream=None, metal_angle_window_pct=DEFAULT_METAL_ANGLE_WINDOW_PCT):
    """All characteristics of one section. ``profile``: a Profile or an ordered (N, 2) array;
    ``engine_axis``: a 2D direction in the section plane, pointing downstream; ``le_hint``: a
    point near the leading edge (e.g. on the CAD's named LE face); ``le_upstream``: a 2D
    direction pointing upstream (the LE is the end furthest along it); with neither, the LE is
    the blunter end, or the end upstream along the engine axis when the two edge radii agree
    within their uncertainty (``le_rule`` says which rule decided, docs/airfoil.md)."""
    if not isinstance(profile, Profile):
        profile = Profile(profile, noise_mm)
    if chord_method not in CHORD_METHODS:
        raise InputError("chord method: %r is not one of %s" % (chord_method,
                                                                 ", ".join(CHORD_METHODS)))
    axis = np.asarray(engine_axis, dtype=float).reshape(2)
    if not np.all(np.isfinite(axis)) or np.linalg.norm(axis) < 1e-12:
        raise InputError("engine axis: %s must be a finite non-zero 2D direction" % axis)
    axis = _unit(axis)
    L = profile.length
    if not (np.isfinite(metal_angle_window_pct) and 0 < metal_angle_window_pct <= 100):
        raise InputError("metal angle window: %r %% of the camber line must be in (0, 100]"
                         % (metal_angle_window_pct,))

    # Sides split at the caliper diameter's ends (the edges of an airfoil), then the circles.
    cal_u1, cal_u2, cal_p1, cal_p2 = _farthest_pair(profile)
    caliper = float(np.linalg.norm(cal_p2 - cal_p1))
    u1, u2 = sorted([cal_u1 % L, cal_u2 % L])
    side_a, side_b = _side(profile, u1, u2), _side(profile, u2, u1 + L)
    centres, radii = _medial_axis(profile, side_a, side_b)

    # Camber line end tangents, extended to the profile: the two edge points.
    # First the edge circles about the locus's ends, then the ends closed onto circular edges.
    out_a = _line_end(centres, radii, 0, window_pct=metal_angle_window_pct)[2]
    out_b = _line_end(centres, radii, -1, window_pct=metal_angle_window_pct)[2]
    circle_a = _edge_circle(profile, centres[0], out_a,
                            _ray_hit(profile, centres[0], out_a, behind=True)[0][0],
                            edge_zone_deg)
    circle_b = _edge_circle(profile, centres[-1], out_b,
                            _ray_hit(profile, centres[-1], out_b, behind=True)[0][0],
                            edge_zone_deg)
    notes = []
    centres, radii, out_a, ua_end, end_a = _closed_end(profile, centres, radii, 0, circle_a,
                                                       notes, metal_angle_window_pct)
    centres, radii, out_b, ub_end, end_b = _closed_end(profile, centres, radii, -1, circle_b,
                                                       notes, metal_angle_window_pct)
    circle_a = _edge_circle(profile, circle_a.center, out_a, ua_end[0], edge_zone_deg)
    circle_b = _edge_circle(profile, circle_b.center, out_b, ub_end[0], edge_zone_deg)
    # The edge points: from each edge circle's centre along the camber line's end direction.
    ua_end, end_a = _edge_point(profile, circle_a, out_a, noise_mm, ua_end, end_a)
    ub_end, end_b = _edge_point(profile, circle_b, out_b, noise_mm, ub_end, end_b)
    t0, t1 = -out_a, out_b
    a_is_le, le_rule = _leading_end(end_a[0], end_b[0], circle_a, circle_b, axis, le_hint,
                                    le_upstream, noise_mm)
    if a_is_le:
        le, te, le_u, te_u = end_a[0], end_b[0], ua_end[0], ub_end[0]
        le_circle, te_circle = circle_a, circle_b
    else:
        centres, radii = centres[::-1], radii[::-1]
        le, te, le_u, te_u = end_b[0], end_a[0], ub_end[0], ua_end[0]
        le_circle, te_circle = circle_b, circle_a
    mcl = CamberLine(le, centres, te, t0 if a_is_le else -t1, t1 if a_is_le else -t0)

    nose_tail = float(np.linalg.norm(te - le))
    chord_dir = (te - le) / nose_tail
    # The two sides between the edge points; the suction side is the longer one (convex).
    # (their parameter ranges only: no samples or tree of them is wanted)
    s1, s2 = _side_range(profile, le_u % L, te_u % L), _side_range(profile, te_u % L,
                                                                   le_u % L + L)
    suction, pressure = (s1, s2) if (s1.hi - s1.lo) >= (s2.hi - s2.lo) else (s2, s1)

    bitangent = _pressure_bitangent(profile, pressure, le_u, te_u)
    tangent_chord = None if bitangent is None else extent(profile, bitangent[1] - bitangent[0])
    chord = {"nose-tail": nose_tail, "caliper": caliper, "tangent": tangent_chord}[chord_method]
    if chord is None:
        raise InputError("chord method tangent: the pressure side is not concave, no line "
                         "touches the profile at both edges across it")

    # Largest inscribed circle: the radius along the camber line is flat at its maximum, so
    # it is zoomed in on twice by exact circles at 9 arc lengths and a parabola through them.
    k = int(np.clip(np.argmax(radii), 1, len(radii) - 2))
    s_c = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(centres, axis=0), axis=1))])
    lo_s, hi_s = s_c[k - 1], s_c[k + 1]
    for _ in range(2):
        s_try = np.linspace(lo_s, hi_s, 9)
        seeds, _ = mcl.at(mcl.le_extension + s_try)
        cs, _, _, fs, _ = _refine_centres(profile, side_a, side_b, seeds)
        r_try = _norms(fs - cs)
        a2, a1, _ = np.polyfit(s_try - s_try[4], r_try, 2)
        s_max = s_try[4] + (-a1 / (2 * a2) if a2 < 0 else 0.0)
        s_max = float(np.clip(s_max, lo_s, hi_s))
        half = (hi_s - lo_s) / 8.0
        lo_s, hi_s = s_max - half, s_max + half
    seed, _ = mcl.at(mcl.le_extension + s_max)
    c_max, _, _, fa, _ = _refine_centres(profile, side_a, side_b, seed)
    max_thickness = 2.0 * float(np.linalg.norm(fa[0] - c_max[0]))
    # Its position: the vertex of the radius's local quartic (continuous in the points).
    x_pos, c_pos = _max_thickness_position(profile, side_a, side_b, mcl,
                                           mcl.le_extension + s_max, c_max[0],
                                           _MAX_POS_WINDOW * nose_tail, le, chord_dir)
    max_pos = 100.0 * x_pos / nose_tail

    stations = [float(p) for p in stations_pct]
    offsets = [float(d) for d in edge_offsets_mm]
    # the stations' and both edges' thicknesses in one call (each its own crossings)
    s_all = np.concatenate([_stations_to_arc(mcl, le, chord_dir, nose_tail, stations),
                            np.array(offsets), mcl.length - np.array(offsets)])
    thk = _thickness_normal(profile, mcl, s_all).tolist()
    n_st, n_off = len(stations), len(offsets)
    thickness = thk[:n_st]
    le_thk, te_thk = thk[n_st:n_st + n_off], thk[n_st + n_off:]

    area, centroid = area_centroid(profile)
    warnings = _corner_warnings(profile, le, te, nose_tail) + notes
    le_radius, te_radius = le_circle.radius, te_circle.radius
    for name in _corner_edges(profile, le, te, nose_tail):
        # A corner's radius is zero: the circle fitted about the camber line's end (kept, for
        # a scan plan's edge spacing) is the window's, not the part's.
        warnings.append("%s is a corner, not a rounded edge: its radius is not reported (the "
                        "circle fitted there, %.4f mm, is not the part's)"
                        % (name, (le_circle if name == "LE" else te_circle).radius))
        if name == "LE":
            le_radius = None
        else:
            te_radius = None
    return Characteristics(
        chord_mm=float(chord), chord_method=chord_method, nose_tail_chord_mm=nose_tail,
        caliper_chord_mm=caliper, tangent_chord_mm=tangent_chord,
        axial_chord_mm=extent(profile, axis), stagger_deg=_angle_deg(chord_dir, axis),
        max_thickness_mm=max_thickness, max_thickness_pos_pct=max_pos,
        max_thickness_center=c_pos, thickness_stations_pct=stations, thickness_mm=thickness,
        le_radius_mm=le_radius, te_radius_mm=te_radius, le_circle=le_circle,
        te_circle=te_circle, edge_offsets_mm=offsets, le_thickness_mm=le_thk,
        te_thickness_mm=te_thk, inlet_angle_deg=_angle_deg(mcl.le_tangent, axis),
        outlet_angle_deg=_angle_deg(mcl.te_tangent, axis), area_mm2=area,
        centroid_mm=centroid, le_point=le, te_point=te, chord_dir=chord_dir, engine_axis=axis,
        le_rule=le_rule, mcl=mcl, inscribed_centres=centres, inscribed_radii=radii,
        profile=profile, suction_range=(suction.lo, suction.hi),
        pressure_range=(pressure.lo, pressure.hi), warnings=warnings)


def _leading_end(end_a, end_b, circle_a, circle_b, axis, le_hint, le_upstream, noise_mm):
    """Whether end a is the LE, and the rule that decided (docs/airfoil.md)."""
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
    if abs(circle_a.radius - circle_b.radius) > LE_RADIUS_SIGMAS * sigma:
        return bool(circle_a.radius > circle_b.radius), "larger edge radius"
    return bool((end_a - end_b) @ axis <= 0), "upstream along the engine axis"


def edge_radius_sigma(circle, noise_mm=0.0):
    """1-sigma of a fitted edge radius: sigma_R = s / sqrt(n) * f(alpha) (docs/airfoil.md),
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
    radius_sigma_mm at the points' noise: n = (noise / sigma_R * f(alpha))^2 (issue 15 item 7)."""
    f = circle_radius_factor(np.radians(zone_deg))
    return int(np.ceil((float(noise_mm) / float(radius_sigma_mm) * f) ** 2))


def edge_spacing_mm(radius_mm, noise_mm, radius_sigma_mm, zone_deg=DEFAULT_EDGE_ZONE_DEG):
    """Point spacing along an edge of radius radius_mm giving the zone those points: its arc
    2 alpha r over edge_points_needed."""
    arc = 2.0 * np.radians(zone_deg) * float(radius_mm)
    return arc / edge_points_needed(noise_mm, radius_sigma_mm, zone_deg)


def _corner_edges(profile, le, te, chord):
    """{"LE" and/or "TE": the corner}: the edges that are a corner of the input points (one
    within 2 % of the chord of the edge point, _corner_warnings's rule)."""
    pts = profile.points[profile.corners]
    out = {}
    for name, p in (("LE", le), ("TE", te)):
        near = np.linalg.norm(pts - p, axis=1) < 0.02 * chord
        if near.any():
            out[name] = pts[near][0]
    return out


def _corner_warnings(profile, le, te, chord):
    """One line per corner of the input points: the spline rounds a corner off over a point
    spacing, so an edge radius, edge point and chord read there are not the part's."""
    out = []
    for i in profile.corners:
        p = profile.points[i]
        where = ("at the LE" if np.linalg.norm(p - le) < 0.02 * chord else
                 "at the TE" if np.linalg.norm(p - te) < 0.02 * chord else "on a side")
        out.append("corner %s at (%.4f, %.4f) mm: the profile is not smooth there; "
                   "characteristics near it (edge radius, edge point, chords, metal angle) "
                   "are not trustworthy" % (where, p[0], p[1]))
    return out


def withhold_corner_edges(measured, nominal):
    """The measured characteristics with the metal angle and edge radius of every edge that
    is a corner of the nominal (a corner of its exact cut within 2 % of the chord of that edge
    point, the rule of its "corner at the LE/TE" warning) set to None, and a warning saying
    why. A corner has no edge circle and no camber-line end for a tangent; the nominal's
    value is its cut's, read at the corner's exact vertex, while a measured profile's smooth
    fit rounds the corner off over the points' spacing and noise, and the same rule then
    reads the rounding (Rotor 67's 90 % TE, planned scans of a perfect part: 0.006-12 deg off,
    1 sigma 2.6 deg over 22 scans). docs/airfoil.md, "Sharp edges"."""
    corners = _corner_edges(nominal.profile, nominal.le_point, nominal.te_point,
                            nominal.nose_tail_chord_mm)
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


def _stations_to_arc(mcl, le, chord_dir, chord, stations_pct):
    """Camber-line arc lengths whose points project on the chord at the given % of it."""
    if not stations_pct:
        return np.zeros(0)
    s = np.linspace(0.0, mcl.length, 2001)
    x = (mcl.at(s)[0] - le) @ chord_dir
    out = []
    for pct in stations_pct:
        target = pct / 100.0 * chord
        if not (x.min() <= target <= x.max()):
            raise InputError("thickness station %g %% lies outside the chord" % pct)
        si = float(np.interp(target, x, s))
        for _ in range(8):
            p, t = mcl.at([si])
            si -= float((p[0] - le) @ chord_dir - target) / float(t[0] @ chord_dir)
        out.append(si)
    return np.array(out)


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


# ---------------------------------------------------------------- measured against nominal

def order_by_nominal(points, nominal):
    """Unordered measured points of a section, ordered by their foot on the nominal."""
    pts = np.asarray(points, dtype=float)
    u, _ = nominal.closest(pts)
    return pts[np.argsort(np.mod(u, nominal.length))]


def signed_deviation(points, nominal):
    """Signed normal distance of each point from the nominal profile (+ outside, material
    excess) and the feet's parameters."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    u, foot = nominal.closest(pts)
    return np.einsum("ij,ij->i", pts - foot, nominal.outward_normal(u)), u


@dataclass
class SectionFit:
    """The measured section's position against the nominal: measured = R(twist) (nominal -
    pivot) + pivot + shift."""
    shift_mm: np.ndarray
    twist_deg: float
    pivot: np.ndarray
    rms_before_mm: float
    rms_after_mm: float
    iterations: int


def _rot(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


def fit_section(points, nominal, pivot=None):
    """2D least-squares fit (shift 2 + twist) of measured points onto the nominal profile by
    point-to-curve Gauss-Newton; twist about ``pivot`` (default the nominal's centroid)."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
        raise InputError("section fit: need an (N, 2) array of at least 3 points")
    pivot = area_centroid(nominal)[1] if pivot is None else np.asarray(pivot, float).reshape(2)
    theta, t = 0.0, np.zeros(2)
    before = signed_deviation(pts, nominal)[0]
    it = 0
    for it in range(1, 60):
        moved = (pts - pivot) @ _rot(theta).T + pivot + t
        dev, u = signed_deviation(moved, nominal)
        n = nominal.outward_normal(u)
        arm = moved - pivot - t
        # d(moved)/d(theta) is arm turned by +90 degrees.
        J = np.column_stack([n, n[:, 1] * arm[:, 0] - n[:, 0] * arm[:, 1]])
        step, *_ = np.linalg.lstsq(J, -dev, rcond=None)
        t, theta = t + step[:2], theta + step[2]
        if np.linalg.norm(step) < 1e-13:
            break
    after = signed_deviation((pts - pivot) @ _rot(theta).T + pivot + t, nominal)[0]
    # The fit maps measured onto nominal; the section's own pose is its inverse.
    twist = -theta
    shift = -_rot(twist) @ t
    return SectionFit(shift, float(np.degrees(twist)), pivot, float(np.sqrt(np.mean(before ** 2))),
                      float(np.sqrt(np.mean(after ** 2))), it)


def contour(points, nominal_chars, fit=None):
    """Contour error per zone (LE, TE, suction, pressure, all). form_location_mm: twice the
    largest |deviation| before any fit (the width of a zone centred on the nominal that holds
    the points); form_mm: max - min deviation after the section's own 2D fit (least squares,
    not minimum zone)."""
    nominal = nominal_chars.profile
    pts = np.asarray(points, dtype=float)
    if fit is None:
        fit = fit_section(pts, nominal)
    before, u = signed_deviation(pts, nominal)
    theta = -np.radians(fit.twist_deg)
    t = -_rot(theta) @ fit.shift_mm
    after = signed_deviation((pts - fit.pivot) @ _rot(theta).T + fit.pivot + t, nominal)[0]
    zone = contour_zones(nominal_chars, u)
    out = {}
    for name in ZONES + ("all",):
        sel = np.ones(len(pts), bool) if name == "all" else zone == name
        if not sel.any():
            out[name] = {"n": 0, "form_mm": None, "form_location_mm": None}
            continue
        out[name] = {"n": int(sel.sum()),
                     "form_mm": float(after[sel].max() - after[sel].min()),
                     "form_location_mm": float(2.0 * np.abs(before[sel]).max()),
                     "min_mm": float(before[sel].min()), "max_mm": float(before[sel].max())}
    return out


def contour_zones(chars, u):
    """'LE', 'TE', 'suction' or 'pressure' for feet at parameters u on the nominal."""
    p = chars.profile.eval(u)
    x = (p - chars.le_point) @ chars.chord_dir / chars.nose_tail_chord_mm
    on_suction = _in_range(u, _Range(*chars.suction_range), chars.profile.length)
    zone = np.where(on_suction, "suction", "pressure").astype(object)
    zone[x <= CONTOUR_EDGE_FRACTION] = "LE"
    zone[x >= 1.0 - CONTOUR_EDGE_FRACTION] = "TE"
    return zone


@dataclass
class _Range:
    lo: float
    hi: float


def lean_bow(heights_mm, shifts_mm):
    """Per blade: lean is the line through the innermost and outermost sections' shifts
    (its slope per mm of span and its angle), bow each section's shift from that line."""
    h = np.asarray(heights_mm, dtype=float).reshape(-1)
    s = np.asarray(shifts_mm, dtype=float).reshape(len(h), 2)
    if len(h) < 2 or np.ptp(h) <= 0:
        raise InputError("lean/bow: need at least two sections at different heights")
    i, o = int(np.argmin(h)), int(np.argmax(h))
    slope = (s[o] - s[i]) / (h[o] - h[i])
    line = s[i] + (h - h[i])[:, None] * slope
    bow = s - line
    mag = np.linalg.norm(bow, axis=1)
    return {"lean_mm_per_mm": slope.tolist(),
            "lean_deg": float(np.degrees(np.arctan(np.linalg.norm(slope)))),
            "bow_mm": bow.tolist(), "bow_magnitude_mm": mag.tolist(),
            "largest_bow_section": int(np.argmax(mag))}

