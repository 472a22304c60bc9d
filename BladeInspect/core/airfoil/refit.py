"""A noisy profile's smoothing spline refitted in arc length, with the nominal's knots where
the points thin out (Profile's noisy-points path)."""

import numpy as np
from scipy.interpolate import splev, splprep
from scipy.spatial import cKDTree

from .geometry import cross2, norms

# Noisy points' feet on their first fit (refit_in_arc_length): a table of that curve this
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


def refit_in_arc_length(pts, first, first_length, noise_mm, nominal=None):
    """Noisy points' smoothing spline in a parameter that is the curve's arc length: each
    point's foot on the first fit ``first`` (a smoothing spline in the chord length between
    consecutive points), measured as that fit's arc length; the points re-ordered along it.
    Given the ``nominal`` Profile and a change of the points' density, the points are then
    fitted by least squares on the knots of _knots_from_nominal. Returns the points, their
    parameters and the spline.

    Why (docs/user-guide.md, "Input and representation"): where points lie closer than their noise
    (the planned edges: 2 um apart, 3.9 um noise) the chord length between consecutive points
    is mostly noise -- a parameter running at up to 3x the arc length, as a random walk -- and
    a parametric fit in it reads the curve biased round the edges (metal angles off by
    several times their bound on a perfect part; within it in this parameter with the budget
    below)."""
    n_table = int(np.clip(first_length / _FOOT_TABLE_MM, 4 * len(pts), _FOOT_TABLE_MAX))
    table_u = np.linspace(0.0, first_length, n_table + 1)
    table = np.column_stack(splev(table_u, first))
    arc = np.concatenate([[0.0], np.cumsum(norms(np.diff(table, axis=0)))])
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
    residual = cross2(d1, pts - p) / norms(d1)
    sigma = min(float(noise_mm), float(np.sqrt(np.mean(np.diff(residual) ** 2) / 2.0)))
    closed = np.vstack([pts, pts[:1]])
    s = s - s[0]           # the loop's parameter starts at its first point, as the first fit's
    u = np.concatenate([s, [arc[-1]]])
    tck, _ = splprep([closed[:, 0], closed[:, 1]], u=u, s=len(pts) * sigma ** 2, per=1, k=3,
                     quiet=1)
    # Of pure noise a least-squares spline with `free` coefficients leaves (N - free) sigma^2
    # and a smoothing one more (its penalty keeps part of them stiff): the budget is taken
    # between, (N - _FREE_SHARE free) sigma^2. The excess of a budget of N sigma^2 is what
    # the fit spends on the edges (biasing the metal angles); at N - free too little
    # smoothing follows the points' small changes (a rigidly moved section's max thickness
    # moves).
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

    Why (docs/user-guide.md, "Where the points thin out"): a planned section holds its points a
    few micrometres apart round the edges and 0.1 mm apart beyond; the smoothing spline
    spends its residual budget where the points are many and puts too few knots where they
    thin out, 0.6-3 mm from the edges, and stays stiff there: edge thicknesses 1 and 2 mm from
    the edges read many standard errors off (least squares on its own knots the same). Not the
    nominal's knots everywhere: their 20 um spans round the edges let the noise bend the curve
    (a camber line can loop)."""
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
