"""Extents and chords: the caliper (farthest pair), the support points, the tangent chord's
bitangent across the pressure side."""

import numpy as np

from .geometry import cross2, in_range, unit
from .profile import NEWTON_ITERATIONS

CHORD_METHODS = ("nose-tail", "caliper", "tangent")


def _support(profile, direction, sign):
    """The profile point furthest along sign * direction (Newton on S'(u).d = 0)."""
    proj = sign * (profile.dense @ direction)
    u = np.array([profile.dense_u[np.argmax(proj)]])
    for _ in range(NEWTON_ITERATIONS):
        _, d1, d2 = profile.eval3(u)
        g = d1 @ direction
        h = d2 @ direction
        u = u - g / np.where(np.abs(h) > 1e-15, h, 1e-15)
    return profile.eval(u)[0]


def extent(profile, direction):
    """Length of the profile's projection on ``direction`` (its caliper width along it)."""
    d = unit(direction)
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


def farthest_pair(profile):
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
        for _ in range(NEWTON_ITERATIONS):
            new = np.clip(profile.newton_stationary(u, p), start - spacing, start + spacing)
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
    for _ in range(NEWTON_ITERATIONS):
        p, d1, d2 = profile.eval3(u)
        d = p - point
        step = cross2(d, d1) / np.where(np.abs(cross2(d, d2)) > 1e-15, cross2(d, d2), 1e-15)
        u = u - step
        if abs(step[0]) < 1e-13 * profile.length:
            break
    return u[0]


def pressure_bitangent(profile, pressure, le_u, te_u):
    """The line touching the profile at both edges across the pressure side, as (point near
    the LE, point near the TE), or None when the pressure side is not concave."""
    hull = np.sort(profile.hull_vertices())
    hu = profile.dense_u[hull]
    gaps = np.diff(np.concatenate([hu, [hu[0] + profile.length]]))
    k = int(np.argmax(np.where(in_range(hu + gaps / 2, pressure, profile.length), gaps, 0)))
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
