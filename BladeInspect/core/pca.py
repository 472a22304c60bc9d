"""Principal axes of a point set and the coarse poses they give (paper 3.1.3, eq. 3)."""

from dataclasses import dataclass
from itertools import product

import numpy as np

from .errors import InputError
from .transforms import make_transform


@dataclass
class PrincipalAxes:
    centroid: np.ndarray      # (3,)
    eigenvalues: np.ndarray   # (3,) descending
    axes: np.ndarray          # (3,3), column i is the axis of eigenvalue i; det +1


def principal_axes(points, weights=None):
    """Eigen-decomposition of the (weighted) covariance A = sum w (p - c)(p - c)^T / sum w.

    Weights matter when the points are not evenly spread, e.g. surface samples whose weight is
    the area they stand for: the axes are then those of the surface, not of the sampling.
    """
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 3:
        raise InputError("principal axes: need at least 3 points of shape (N, 3), got %s"
                         % (points.shape,))
    if weights is None:
        weights = np.ones(len(points))
    weights = np.asarray(weights, dtype=float)
    if weights.shape != (len(points),) or np.any(weights < 0) or weights.sum() <= 0:
        raise InputError("principal axes: weights must be (N,), non-negative, not all zero")
    w = weights / weights.sum()
    centroid = w @ points
    d = points - centroid
    cov = (d * w[:, None]).T @ d
    vals, vecs = np.linalg.eigh(cov)
    order = np.argsort(vals)[::-1]
    vals, vecs = vals[order], vecs[:, order]
    if np.linalg.det(vecs) < 0:
        vecs[:, 2] = -vecs[:, 2]
    return PrincipalAxes(centroid=centroid, eigenvalues=vals, axes=vecs)


def candidate_poses(measured, nominal):
    """The 4 measured -> nominal poses that match axis i to axis i with signs S (det S = +1).

    An eigenvector's sign is arbitrary, so each proper sign pattern is a possible pose:
    R = A_n S A_m^T, t = c_n - R c_m.
    """
    poses = []
    for signs in product((1.0, -1.0), repeat=3):
        if np.prod(signs) < 0:
            continue
        R = nominal.axes @ np.diag(signs) @ measured.axes.T
        poses.append(make_transform(R, nominal.centroid - R @ measured.centroid))
    return poses


def axes_warning(measured, nominal, min_ratio=1.1):
    """Text when consecutive eigenvalues of either set are within ``min_ratio`` of each other:
    those two axes can turn freely in their plane (a symmetric patch, or a narrow one whose two
    short extents are alike), so the candidates' rotations about the third are arbitrary."""
    problems = []
    for label, pa in (("measured", measured), ("nominal", nominal)):
        vals = np.asarray(pa.eigenvalues, dtype=float)
        for i in range(2):
            if vals[i] <= min_ratio * vals[i + 1]:
                problems.append("%s eigenvalues %d and %d (%.4g, %.4g) differ by less than a "
                                "factor %.3g" % (label, i + 1, i + 2, vals[i], vals[i + 1],
                                                 min_ratio))
    if not problems:
        return None
    return ("principal axes ambiguous: " + "; ".join(problems)
            + " - the coarse pose may be unreliable (symmetric or narrow scan)")
