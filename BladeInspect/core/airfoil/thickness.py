"""Thicknesses normal to the camber line, the stations along the chord and the
max-thickness position."""

import numpy as np

from ..errors import InputError
from .camber import END_DEGREE
from .geometry import cross2, norms
from .medial import refine_centres
from .profile import line_hit

def thickness_normal(profile, mcl, s):
    """Thickness normal to the camber line at arc lengths s: the chord of the profile cut by
    the camber line's normal there (nearest crossing on each side)."""
    m, t = mcl.at(s)
    n = np.column_stack([-t[:, 1], t[:, 0]])
    out = np.full(len(s), np.nan)
    p, q = profile.dense, np.roll(profile.dense, -1, axis=0)
    e = q - p
    h = profile.length / len(profile.dense)
    # every station against every dense segment at once (rows: stations), cross2's
    # arithmetic element by element
    pm = p[None, :, :] - m[:, None, :]
    n0, n1 = n[:, 0:1], n[:, 1:2]
    den = n0 * e[None, :, 1] - n1 * e[None, :, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = cross2(pm, e[None]) / den
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
        _, xy = line_hit(profile, m[rows], n[rows], starts)
        out[found] = norms(xy[0::2] - xy[1::2])
    return out


# The max-thickness position (docs/user-guide.md, "Thickness"): the vertex of a weighted
# least-squares quartic of the exact inscribed radii against their centres' projection on the
# nose-tail chord, over +-MAX_POS_WINDOW of the chord about the vertex itself (biweight),
# _MAX_POS_SAMPLES circles a round.
MAX_POS_WINDOW = 0.05
_MAX_POS_SAMPLES = 61
_MAX_POS_ROUNDS = 20


def max_thickness_position(profile, a, b, mcl, s0, c0, window, le, chord_dir):
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
        cs, _, _, fs, _ = refine_centres(profile, a, b, seeds)
        r, t = norms(fs - cs), ((cs - le) @ chord_dir - x) / half
        inside = np.abs(t) < 1.0
        if inside.sum() < 2 * END_DEGREE:
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
    return x, refine_centres(profile, a, b, seed)[0][0]


def stations_to_arc(mcl, le, chord_dir, chord, stations_pct):
    """Camber-line arc lengths whose points project on the chord at the given % of it."""
    if not stations_pct:
        return np.zeros(0)
    s = np.linspace(0.0, mcl.length, 2001)
    x = (mcl.at(s)[0] - le) @ chord_dir
    out = []
    for pct in stations_pct:
        target = pct / 100.0 * chord
        # (0 % and 100 % are the edge points, whose projections are 0 and the chord but for
        # rounding)
        slack = 1e-12 * chord
        if not (x.min() - slack <= target <= x.max() + slack):
            raise InputError("thickness station %g %% lies outside the chord" % pct)
        target = float(np.clip(target, x.min(), x.max()))
        si = float(np.interp(target, x, s))
        for _ in range(8):
            p, t = mcl.at([si])
            si -= float((p[0] - le) @ chord_dir - target) / float(t[0] @ chord_dir)
        out.append(si)
    return np.array(out)
