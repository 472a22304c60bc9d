"""Truths computed on a dense exact profile (points on the CAD's own B-spline), by brute force
with numpy/scipy: no code of BladeInspect. Lengths in mm, angles in degrees counter-clockwise
from +x (the engine axis) about +z."""
import numpy as np
from scipy.optimize import minimize
from scipy.spatial import Voronoi, cKDTree


def area(loop):
    x, y = np.asarray(loop, float).T
    return float(0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def perimeter(loop):
    return float(np.sum(np.linalg.norm(np.roll(loop, -1, axis=0) - loop, axis=1)))


def extent(loop, direction=(1.0, 0.0)):
    d = np.asarray(direction, float)
    p = np.asarray(loop, float) @ (d / np.linalg.norm(d))
    return float(p.max() - p.min())


class Distance:
    """Distance from points to the closed polyline (segments, not just vertices)."""

    def __init__(self, loop):
        self.a = np.asarray(loop, float)
        self.b = np.roll(self.a, -1, axis=0)
        self.tree = cKDTree(self.a)

    def __call__(self, p):
        p = np.atleast_2d(p)
        _, idx = self.tree.query(p, k=6)
        idx = np.minimum(idx, len(self.a) - 1)    # a non-finite point gets "no neighbour"
        best = np.full(len(p), np.inf)
        for j in range(idx.shape[1]):
            for seg in (idx[:, j], (idx[:, j] - 1) % len(self.a)):
                a, b = self.a[seg], self.b[seg]
                ab = b - a
                t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.einsum("ij,ij->i", ab, ab),
                            0, 1)
                best = np.minimum(best, np.linalg.norm(p - (a + t[:, None] * ab), axis=1))
        return best


def largest_inscribed_circle(loop):
    """(diameter, centre) of the largest circle inside the counter-clockwise loop: the
    Voronoi vertices of its dense points approximate the medial axis; those on the inner side
    of their nearest boundary point are inside; Nelder-Mead on the exact distance to the
    segments refines the best few."""
    loop = np.asarray(loop, float)
    dist = Distance(loop)
    v = Voronoi(loop[::max(1, len(loop) // 3000)]).vertices
    lo, hi = loop.min(axis=0), loop.max(axis=0)
    v = v[np.all((v > lo) & (v < hi), axis=1)]
    d, i = dist.tree.query(v)
    t = np.roll(loop, -1, axis=0) - np.roll(loop, 1, axis=0)
    n_out = np.column_stack([t[:, 1], -t[:, 0]])
    inside = np.einsum("ij,ij->i", v - loop[i], n_out[i]) < 0
    v, d = v[inside], d[inside]
    best = None
    for k in np.argsort(d)[-5:]:
        res = minimize(lambda c: -dist(c)[0] if np.all(np.isfinite(c)) else np.inf, v[k],
                       method="Nelder-Mead", options=dict(xatol=1e-9, fatol=1e-12,
                                                          maxiter=2000))
        if not np.isfinite(res.fun):
            continue
        if best is None or -res.fun > best[0]:
            best = (-res.fun, res.x)
    return 2.0 * float(best[0]), best[1]


def offset_loop(loop, d):
    """A smooth counter-clockwise loop moved outward by d along its normals (second-order
    normals of the dense loop; for loops whose curvature radius is everywhere above d)."""
    loop = np.asarray(loop, float)
    t = np.roll(loop, -1, axis=0) - np.roll(loop, 1, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    n = np.column_stack([t[:, 1], -t[:, 0]])      # outward for a counter-clockwise loop
    return loop + d * n


def rotate(loop, angle_deg, centre=(0.0, 0.0)):
    a = np.radians(angle_deg)
    R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    c = np.asarray(centre, float)
    return (np.asarray(loop, float) - c) @ R.T + c


def brute(loop):
    """Characteristics the corpus computes itself on every exact profile."""
    t, _ = largest_inscribed_circle(loop)
    return {"area_mm2": area(loop), "axial_chord_mm": extent(loop), "max_thickness_mm": t}
