"""Least-squares fits of spheres, planes and circles in space to measured points.

Each fit minimises the sum of squared *geometric* distances (orthogonal to the surface or
curve), which is the maximum-likelihood fit when the point errors are isotropic and normal; an
algebraic fit (linear in its unknowns, biased on partial arcs and caps) only supplies the start
of the Gauss-Newton iterations. Optional weights are inverse variances (the sensor's SNR, see
docs/contracts.md "The sensor and its noise"). Degenerate input raises InputError.
"""

from typing import NamedTuple

import numpy as np

from .errors import InputError

MAX_ITERATIONS = 100


class SphereFit(NamedTuple):
    center: np.ndarray            # (3,)
    radius: float
    residuals: np.ndarray         # (N,) signed distance to the sphere, + outside
    covariance: np.ndarray        # (3,3) of the centre, or (4,4) centre then radius when free
    iterations: int


class PlaneFit(NamedTuple):
    point: np.ndarray             # (3,) weighted centroid, a point of the plane
    normal: np.ndarray            # (3,) unit, its largest component positive
    residuals: np.ndarray         # (N,) signed distance along the normal


class CircleFit(NamedTuple):
    center: np.ndarray            # (3,)
    normal: np.ndarray            # (3,) unit normal of the circle's plane, largest component > 0
    radius: float
    residuals: np.ndarray         # (N,) distance of each point to the circle
    iterations: int


def _as_points(points, minimum, what):
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise InputError("%s: points must be an (N, 3) array, got shape %s" % (what, pts.shape))
    if len(pts) < minimum:
        raise InputError("%s: at least %d points are needed, got %d" % (what, minimum, len(pts)))
    if not np.all(np.isfinite(pts)):
        raise InputError("%s: points contain NaN or infinite coordinates" % what)
    return pts


def _as_weights(weights, n, what):
    if weights is None:
        return np.ones(n)
    w = np.asarray(weights, dtype=float)
    if w.shape != (n,) or not np.all(np.isfinite(w)) or np.any(w < 0) or not np.any(w > 0):
        raise InputError("%s: weights must be N finite non-negative numbers, not all zero" % what)
    return w


def _canonical_sign(normal):
    """A normal's sign is arbitrary in a fit; fix it so that equal planes give equal normals."""
    return normal if normal[np.argmax(np.abs(normal))] > 0 else -normal


def _gauss_newton_step(J, r, w):
    """Weighted least-squares step solving J dx = -r, via lstsq for rank safety."""
    sw = np.sqrt(w)
    dx, _, rank, _ = np.linalg.lstsq(J * sw[:, None], -r * sw, rcond=None)
    return dx, rank


def _residual_variance(r, w, n_params):
    dof = max(len(r) - n_params, 1)
    return float(np.sum(w * r * r) / dof)


# ---------------------------------------------------------------- sphere

def _algebraic_hypersphere(pts, w, what):
    """Kasa's fit of a circle (2D points) or sphere (3D): |p|^2 = 2 c.p + (R^2 - |c|^2) is
    linear in c and the constant."""
    dim = pts.shape[1]
    A = np.column_stack([2.0 * pts, np.ones(len(pts))])
    b = np.einsum("ij,ij->i", pts, pts)
    sw = np.sqrt(w)
    sol, _, rank, _ = np.linalg.lstsq(A * sw[:, None], b * sw, rcond=None)
    if rank < dim + 1:
        raise InputError("%s fit: the points are %s, no %s is defined"
                         % (what, "collinear" if dim == 2 else "coplanar or collinear", what))
    center = sol[:dim]
    return center, float(np.sqrt(max(sol[dim] + center @ center, 0.0)))


def fit_sphere(points, radius=None, weights=None):
    """Sphere through the points by geometric least squares.

    With ``radius`` given (a reference sphere of calibrated diameter) only the centre is fitted:
    on a cap seen from one side the free radius and the centre's depth are strongly correlated,
    and fixing the known radius removes that correlation from the centre.
    """
    known = radius is not None
    pts = _as_points(points, 4, "sphere fit")
    w = _as_weights(weights, len(pts), "sphere fit")
    if known and not (np.isfinite(radius) and radius > 0):
        raise InputError("sphere fit: radius must be a positive number, got %r" % (radius,))
    center_shift = np.average(pts, axis=0, weights=w)
    local = pts - center_shift
    c, r_alg = _algebraic_hypersphere(local, w, "sphere")
    R = float(radius) if known else r_alg
    n_params = 3 if known else 4
    iterations = 0
    for iterations in range(1, MAX_ITERATIONS + 1):
        v = local - c
        dist = np.linalg.norm(v, axis=1)
        if np.any(dist == 0):
            raise InputError("sphere fit: a point coincides with the centre estimate")
        u = v / dist[:, None]
        r = dist - R
        J = -u if known else np.column_stack([-u, -np.ones(len(pts))])
        dx, rank = _gauss_newton_step(J, r, w)
        if rank < n_params:
            raise InputError("sphere fit: the points do not determine a sphere")
        c = c + dx[:3]
        if not known:
            R += dx[3]
        if np.linalg.norm(dx) < 1e-13 * max(1.0, R):
            break
    v = local - c
    dist = np.linalg.norm(v, axis=1)
    r = dist - R
    u = v / dist[:, None]
    J = -u if known else np.column_stack([-u, -np.ones(len(pts))])
    normal_matrix = (J * w[:, None]).T @ J
    covariance = np.linalg.inv(normal_matrix) * _residual_variance(r, w, n_params)
    return SphereFit(center=c + center_shift, radius=float(R), residuals=r,
                     covariance=covariance, iterations=iterations)


# ---------------------------------------------------------------- plane

def fit_plane(points, weights=None):
    """Plane minimising the weighted squared normal distances: through the weighted centroid,
    normal along the smallest principal axis of the weighted scatter."""
    pts = _as_points(points, 3, "plane fit")
    w = _as_weights(weights, len(pts), "plane fit")
    point = np.average(pts, axis=0, weights=w)
    d = (pts - point) * np.sqrt(w)[:, None]
    _, s, vt = np.linalg.svd(d, full_matrices=False)
    if s[1] <= 1e-12 * max(s[0], 1e-300):
        raise InputError("plane fit: the points are collinear, no plane is defined")
    normal = _canonical_sign(vt[2])
    return PlaneFit(point=point, normal=normal, residuals=(pts - point) @ normal)


# ---------------------------------------------------------------- circle in space

def orthonormal_pair(normal):
    """Two unit vectors completing ``normal`` (unit) to a right-handed orthonormal frame."""
    helper = np.eye(3)[np.argmin(np.abs(normal))]
    e1 = np.cross(normal, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(normal, e1)


def fit_circle_3d(points, weights=None):
    """Circle in space minimising the squared distances of the points to the circle itself.

    Each point contributes two residuals, its height above the circle's plane and its radial
    distance in that plane minus the radius; their squares add up to the squared distance to
    the circle. Start: best plane, then Kasa's circle in it. The normal is parametrised by two
    small tilts about an orthonormal pair re-based every iteration, so it stays a unit vector.
    """
    pts = _as_points(points, 3, "circle fit")
    w = _as_weights(weights, len(pts), "circle fit")
    plane = fit_plane(pts, w)
    n = plane.normal
    e1, e2 = orthonormal_pair(n)
    local = pts - plane.point
    c2, R = _algebraic_hypersphere(np.column_stack([local @ e1, local @ e2]), w, "circle")
    c = c2[0] * e1 + c2[1] * e2
    ww = np.concatenate([w, w])
    iterations = 0
    for iterations in range(1, MAX_ITERATIONS + 1):
        v = local - c
        h = v @ n
        inplane = v - h[:, None] * n
        rho = np.linalg.norm(inplane, axis=1)
        if np.any(rho == 0):
            raise InputError("circle fit: a point lies on the circle's axis")
        u = inplane / rho[:, None]
        # Unknowns: centre (3), tilts of the normal towards e1 and e2, radius.
        J_h = np.column_stack([np.tile(-n, (len(pts), 1)), v @ e1, v @ e2,
                               np.zeros(len(pts))])
        J_rho = np.column_stack([-u, -h * (u @ e1), -h * (u @ e2), -np.ones(len(pts))])
        J = np.vstack([J_h, J_rho])
        r = np.concatenate([h, rho - R])
        dx, rank = _gauss_newton_step(J, r, ww)
        if rank < 6:
            raise InputError("circle fit: the points do not determine a circle")
        c = c + dx[:3]
        n = n + dx[3] * e1 + dx[4] * e2
        n /= np.linalg.norm(n)
        e1, e2 = orthonormal_pair(n)
        R += dx[5]
        if np.linalg.norm(dx) < 1e-13 * max(1.0, R):
            break
    v = local - c
    h = v @ n
    rho = np.linalg.norm(v - h[:, None] * n, axis=1)
    residuals = np.hypot(h, rho - R)
    return CircleFit(center=c + plane.point, normal=_canonical_sign(n), radius=float(R),
                     residuals=residuals, iterations=iterations)
