"""The inscribed circles between a profile's two sides (its medial axis): the mean camber
line's centres and radii."""

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..errors import InputError
from .geometry import Range, norms, unit

# An inscribed circle belongs to the camber line only while its two contacts are at least this
# far apart as seen from its centre; closer, the circle sits in an edge and its centre is
# ill-conditioned (the bisector of two nearly parallel normals).
MIN_CONTACT_ANGLE_DEG = 60.0


_FEET = 300                 # feet on one side seeding the inscribed circles
_END_FEET = 17              # finer feet closing in on each end of the camber line
_END_ROUNDS = 3
_SEED_STRIDE = 4
_RUN_GAP = 2                 # failed circles a run of camber-line circles may step over,
_RUN_MIN = 2                 # between runs at least this long


_MCL_SPACING_MM = 0.05        # least spacing of the camber line's centres
# A camber-line circle clears the profile round the edge by this fraction of its radius; the
# camber line thus stops within 1e-4 r of an exact circular edge's centre.
_EDGE_GAP = 1e-4


@dataclass
class _Side:
    lo: float     # unwrapped parameter range of the side, lo < hi
    hi: float
    u: np.ndarray
    xy: np.ndarray
    tree: cKDTree


def side_range(profile, lo, hi):
    """A side's unwrapped parameter range, lo < hi (as side_samples's)."""
    return Range(lo, hi + profile.length if hi <= lo else hi)


def side_samples(profile, lo, hi):
    side = side_range(profile, lo, hi)
    lo, hi = side.lo, side.hi
    u = profile.dense_u.copy()
    u = np.where(u < lo, u + profile.length, u)
    keep = (u >= lo) & (u <= hi)
    u = np.sort(u[keep])
    xy = profile.eval(u)
    return _Side(lo, hi, u, xy, cKDTree(xy))


def refine_centres(profile, a, b, centre):
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
        da, db = norms(va), norms(vb)
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
    c, ua, ub, fa, fb = refine_centres(profile, a, b, centre)
    r = norms(fa - c)
    va, vb = unit(fa - c), unit(fb - c)
    contact = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", va, vb), -1, 1)))
    tol = 1e-9 * profile.length
    interior = (ua > a.lo + tol) & (ua < a.hi - tol) & (ub > b.lo + tol) & (ub < b.hi - tol)
    # A circle of the camber line leaves the profile between its two contacts, round the
    # nearer edge; the edge circle itself (an exact circular edge) runs along it there.
    via_lo = (ua - a.lo) + (b.hi - ub) < (a.hi - ua) + (ub - b.lo)
    mid = np.where(via_lo, (ua + ub - profile.length) / 2.0, (ua + ub) / 2.0)
    gap = norms(profile.eval(mid) - c) - r
    # Inscribed: no point of the profile nearer than the contacts (a foot stuck at a local
    # stationary point next to a closer edge would make a circle that crosses the profile).
    nearest = norms(profile.closest(c)[1] - c)
    inscribed = nearest > r - 1e-9 * np.maximum(r, 1.0)
    ok = ((r0 > 0) & interior & inscribed & (contact >= MIN_CONTACT_ANGLE_DEG)
          & (gap > _EDGE_GAP * r))
    return c, r, ua, ok


def medial_axis(profile, a, b):
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
    # A lone circle mid-locus that fails (a foot refined onto a wrong stationary point) must
    # not cut the camber line in two -- its longer half alone would put the metal angle's
    # window on half the locus; two runs apart by at most _RUN_GAP failed circles are one
    # when each is at least _RUN_MIN circles. Near a noisy edge circles fail here and there
    # too, and unjoined short runs would end the locus short of the edge; a stray among them
    # is the end window's to drop (camber._end_quartic).
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
