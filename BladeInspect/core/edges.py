"""A trimmed face's boundary edges as arrays: closest points on them, vectorised.

When Newton's foot point on a face's surface lands outside the face's trimmed domain, the
face's closest point lies on its boundary: on one of its edges. Each edge is kept as its exact
3D curve (a rational B-spline, CurveData; the curve OpenCASCADE's own point-to-edge distance
uses) and a dense polyline on it; each polyline's nearest vertex gives the start on that edge, Newton on
the curve (clamped to the edge's parameter range) the exact closest point. A closest point at
an edge's end is a vertex of the face, where more than two faces may meet: it is reported as
such (``at_end``) so that the caller can leave the point to an exact solver.
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .bspline import basis_derivatives, find_span

# Polyline vertices per knot span of an edge's curve, and per edge at least.
SAMPLES_PER_SPAN = 8
MIN_SAMPLES_PER_EDGE = 256
# Newton iterations at most, and the step (mm along the curve) below which it has converged.
MAX_ITER = 30
STEP_TOL = 1e-12
# Another edge within this of the nearest one, elsewhere, leaves the point undecided (mm).
RIVAL_MM = 1e-9
# Polyline vertices between two of an edge's, for its vertex_reach, and a factor on it.
ARC_SUBDIVISIONS = 8
ARC_SAFETY = 1.25


@dataclass
class CurveData:
    degree: int
    knots: np.ndarray          # flat, with multiplicity
    poles: np.ndarray          # (n, 3), or (n, 2) for a curve in a surface's (u, v)
    weights: np.ndarray        # (n,) or None for a polynomial curve
    t_range: np.ndarray        # (2,) the edge's parameter range


def evaluate_curve(curve, t, order=2):
    """[C, C', ...] up to the order-th derivative (order <= 2; each (N, dimension)) of a
    curve at parameters t."""
    t = np.asarray(t, dtype=float)
    p = curve.degree
    span = find_span(curve.knots, p, t)
    ders = basis_derivatives(curve.knots, p, span, t, order)          # (N, order+1, p+1)
    idx = span[:, None] - p + np.arange(p + 1)[None]                  # (N, p+1)
    if curve.weights is None:
        return list(np.einsum("nkr,nrd->knd", ders, curve.poles[idx]))
    w = curve.weights[idx]
    hom = np.concatenate([curve.poles[idx] * w[..., None], w[..., None]], axis=2)
    a = np.einsum("nkr,nrd->knd", ders, hom)
    out = [a[0][:, :-1] / a[0][:, -1:]]
    if order >= 1:
        out.append((a[1][:, :-1] - a[1][:, -1:] * out[0]) / a[0][:, -1:])
    if order >= 2:
        out.append((a[2][:, :-1] - 2.0 * a[1][:, -1:] * out[1] - a[2][:, -1:] * out[0])
                   / a[0][:, -1:])
    return out


def project_on_curve(curve, points, t0):
    """(t, closest point, converged, at_end) of Newton on |C(t) - p|^2 from t0, clamped to
    the curve's range."""
    a, b = curve.t_range
    t = np.clip(np.asarray(t0, dtype=float), a, b)
    conv = np.zeros(len(t), bool)
    for _ in range(MAX_ITER):
        c0, c1, c2 = evaluate_curve(curve, t)
        r = c0 - points
        g = np.einsum("ij,ij->i", r, c1)
        speed2 = np.einsum("ij,ij->i", c1, c1)
        h = speed2 + np.einsum("ij,ij->i", r, c2)
        h = np.where(h > 0, h, speed2)
        t_new = np.clip(t - g / np.where(h > 0, h, 1.0), a, b)
        conv = np.abs(t_new - t) * np.sqrt(speed2) <= STEP_TOL * max(1.0, np.abs(points).max())
        t = t_new
        if conv.all():
            break
    c0 = evaluate_curve(curve, t, order=0)[0]
    eps = 1e-12 * (b - a)
    return t, c0, conv, (t <= a + eps) | (t >= b - eps)


def curve_polyline(curve):
    """Parameters of a dense polyline on the curve: SAMPLES_PER_SPAN per knot span in range."""
    a, b = curve.t_range
    knots = np.unique(np.clip(curve.knots, a, b))
    if len(knots) < 2:
        knots = np.array([a, b])
    per = max(SAMPLES_PER_SPAN, int(np.ceil(MIN_SAMPLES_PER_EDGE / (len(knots) - 1))))
    s = np.linspace(0.0, 1.0, per + 1)[:-1]
    t = (knots[:-1, None] + s[None] * np.diff(knots)[:, None]).ravel()
    return np.append(t, b)


def vertex_reach(curve, t):
    """How far a point of the curve can be from the nearest of its polyline's vertices (at
    parameters t): half the longest arc between two vertices, the arcs measured as the length
    of a polyline ARC_SUBDIVISIONS times as dense (an arc is longer than any polyline inscribed
    in it; ARC_SAFETY covers the difference, which is of order (segment x curvature)^2)."""
    s = np.linspace(0.0, 1.0, ARC_SUBDIVISIONS + 1)
    dense = (t[:-1, None] + s[None] * np.diff(t)[:, None]).ravel()
    x = evaluate_curve(curve, dense, order=0)[0].reshape(len(t) - 1, ARC_SUBDIVISIONS + 1, -1)
    arcs = np.linalg.norm(np.diff(x, axis=1), axis=2).sum(axis=1)
    return 0.5 * ARC_SAFETY * float(arcs.max()) if len(arcs) else 0.0


class FaceEdges:
    """A face's boundary edges: their curves and a k-d tree over each one's polyline."""

    def __init__(self, curves):
        self.curves = list(curves)
        self.vertex_t = [curve_polyline(c) for c in self.curves]
        self.trees = [cKDTree(evaluate_curve(c, t, order=0)[0])
                      for c, t in zip(self.curves, self.vertex_t)]
        self.reach = np.array([vertex_reach(c, t) for c, t in zip(self.curves, self.vertex_t)])

    def closest(self, points):
        """(distance (N,), closest point (N, 3), exact (N,) bool) of each point to the
        boundary: Newton on every edge from its polyline's nearest vertex, the nearest edge
        wins; exact is False where Newton did not converge, the winner is at an edge's end
        (a vertex) or another edge comes within a hair of it elsewhere."""
        n, n_edges = len(points), len(self.curves)
        # Edges that cannot come within RIVAL_MM of the nearest are not projected on (their
        # closest points are neither the winner nor its rival): an edge is at least its
        # nearest vertex's distance less its vertex_reach away, and at most that distance.
        dist = np.full((n_edges, n), np.inf)
        closest = np.zeros((n_edges, n, 3))
        exact = np.zeros((n_edges, n), bool)
        vertex_d, vertex_i = np.empty((n_edges, n)), np.empty((n_edges, n), int)
        for e, tree in enumerate(self.trees):
            vertex_d[e], vertex_i[e] = tree.query(points)
        lower = vertex_d - self.reach[:, None]
        done = np.zeros((n_edges, n), bool)
        bound = vertex_d.min(axis=0)
        while True:
            todo = ~done & (lower <= bound + RIVAL_MM)
            if not todo.any():
                break
            for e in np.flatnonzero(todo.any(axis=1)):
                rows = np.flatnonzero(todo[e])
                p = points[rows]
                _, c, conv, at_end = project_on_curve(self.curves[e], p,
                                                      self.vertex_t[e][vertex_i[e, rows]])
                closest[e, rows] = c
                dist[e, rows] = np.linalg.norm(c - p, axis=1)
                exact[e, rows] = conv & ~at_end
            done |= todo
            # Newton need not descend: an edge above its vertex bound may still be the winner.
            bound = dist.min(axis=0)
        win = np.argmin(dist, axis=0)
        cols = np.arange(n)
        best, c = dist[win, cols], closest[win, cols]
        rival = ((dist < best + RIVAL_MM)
                 & (np.linalg.norm(closest - c, axis=2) > 1e-7)).any(axis=0)
        return best, c, exact[win, cols] & ~rival
