"""Rigid transforms as 4x4 homogeneous matrices acting on row-stacked points (N,3).

Quaternions are unit (w, x, y, z); rotation vectors are axis * angle in radians.
"""

import numpy as np


def make_transform(R, t):
    T = np.eye(4)
    T[:3, :3] = np.asarray(R, dtype=float)
    T[:3, 3] = np.asarray(t, dtype=float)
    return T


def apply_transform(T, pts):
    T = np.asarray(T, dtype=float)
    pts = np.asarray(pts, dtype=float)
    return pts @ T[:3, :3].T + T[:3, 3]


def invert_transform(T):
    T = np.asarray(T, dtype=float)
    R = T[:3, :3]
    return make_transform(R.T, -R.T @ T[:3, 3])


def rotation_matrix_from_quaternion(q):
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([
        [w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z],
    ])


def quaternion_from_rotation(R):
    """Unit quaternion (w >= 0) of a rotation matrix.

    Taken as the top eigenvector of the symmetric 4x4 matrix whose quadratic form is
    trace(R^T R(q)) (Bar-Itzhack): stable for every angle, including 180 degrees, where the
    usual trace-based formula divides by ~0.
    """
    R = np.asarray(R, dtype=float)
    (xx, xy, xz), (yx, yy, yz), (zx, zy, zz) = R
    K = np.array([
        [xx + yy + zz, zy - yz, xz - zx, yx - xy],
        [zy - yz, xx - yy - zz, xy + yx, xz + zx],
        [xz - zx, xy + yx, yy - xx - zz, yz + zy],
        [yx - xy, xz + zx, yz + zy, zz - xx - yy],
    ]) / 3.0
    vals, vecs = np.linalg.eigh(K)
    q = vecs[:, np.argmax(vals)]
    return q if q[0] >= 0 else -q


def rotation_from_vector(omega):
    """Rodrigues' formula: the rotation by |omega| radians about omega."""
    omega = np.asarray(omega, dtype=float)
    angle = np.linalg.norm(omega)
    K = np.array([[0.0, -omega[2], omega[1]],
                  [omega[2], 0.0, -omega[0]],
                  [-omega[1], omega[0], 0.0]])
    if angle < 1e-8:
        # Second-order series: exact to rounding for such angles, no 0/0.
        return np.eye(3) + K + 0.5 * K @ K
    return (np.eye(3) + np.sin(angle) / angle * K
            + (1.0 - np.cos(angle)) / angle ** 2 * K @ K)


def random_rotation(rng):
    """Uniform on SO(3): a normalised 4D Gaussian is a uniform unit quaternion (Haar measure)."""
    q = rng.standard_normal(4)
    return rotation_matrix_from_quaternion(q / np.linalg.norm(q))


def random_transform(rng, max_translation):
    """Uniform rotation, translation uniform in the ball of radius ``max_translation``."""
    direction = rng.standard_normal(3)
    direction /= np.linalg.norm(direction)
    radius = max_translation * rng.uniform() ** (1.0 / 3.0)
    return make_transform(random_rotation(rng), radius * direction)


def corner_displacement(T_est, T_true, corners):
    """The pose error: the largest distance between where the two transforms put a corner."""
    corners = np.asarray(corners, dtype=float)
    diff = apply_transform(T_est, corners) - apply_transform(T_true, corners)
    return float(np.max(np.linalg.norm(diff, axis=1)))
