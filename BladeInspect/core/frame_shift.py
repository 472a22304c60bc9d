"""How far the robust fit's frame is from the least-squares frame of every point it measured.

The robust ICP (core.icp) gives no weight to readings far from the surface, so a real defect
does not tilt the part. A form error over a wide region (a twist, a size error) is rejected
the same way, and the part is then aligned to the rest alone: every value read in the fitted
frame (angles, position) carries that choice. The least-squares frame of all the counted
points is one Gauss-Newton step of the point-to-plane linearisation away from the fitted pose,
d_i + n_i . (dt + dw x (p_i - c)), taken here with and without the rejected points; the
difference of the two steps is the shift the rejected points would bring (the steps share the
linearisation's residual error, so it cancels)."""
import numpy as np


def least_squares_shift(points, normals, deviation, weights, counted, inlier):
    """(dw rad (3,), dt mm (3,), c (3,)): the small rigid motion about c, the counted points'
    centroid, that takes the fit of the ``inlier`` points to the weighted least-squares fit of
    all the ``counted`` points. ``deviation``: signed distances at the fitted pose; ``weights``:
    the readings' noise weights without the robust factor."""
    p = np.asarray(points, dtype=float)
    n = np.asarray(normals, dtype=float)
    d = np.asarray(deviation, dtype=float)
    w = np.asarray(weights, dtype=float)
    counted = np.asarray(counted, dtype=bool) & np.isfinite(d) & (w > 0)
    inlier = np.asarray(inlier, dtype=bool) & counted
    c = p[counted].mean(axis=0)
    J = np.hstack([np.cross(p - c, n), n])

    def step(mask):
        sw = np.sqrt(w[mask])
        x, *_ = np.linalg.lstsq(J[mask] * sw[:, None], -d[mask] * sw, rcond=None)
        return x

    x = step(counted) - step(inlier)
    return x[:3], x[3:], c
