"""The rigid take-up of a reading bias (numpy only).

A reading bias b common to every reading (the sensor's stated accuracy, a systematic error)
lengthens each reading alike: point i moves by b along its beam, and its signed distance to
the surface by b beta_i, beta_i = beam_i . n_i. A weighted least-squares rigid registration
then moves the points back by what a rigid motion can take up, b r, r the weighted least-squares
fit of beta by the motion's normal parts:

    r = argmin_r sum_i w_i (beta_i - J_i r)^2,   J_i = [n_i, (p_i - c) x n_i],

r = (t mm, w rad) per unit bias, translation then rotation, the rigid motion
p -> p + t + w x (p - c) about the centre c (the same convention as core.icp's Jacobian and the
pose covariance about result.center). What is left of the bias in a residual is
s_i = beta_i - J_i r (``left_over``): the defect test's allowance (core.icp) and the systematic
term's coefficient (inspection.uncertainty.systematic_coefficients).

r depends on the centre (the same motion about another centre has another t); s does not: the
columns of J about any centre span the same space.

Edge feet. A point whose beam meets its normal more obliquely than the sensor reads at all
(|beam . n| < cos(max_incidence)) was not read along that normal: its foot is on a face's edge
(a reading just past the CAD's end, its normal p - c), whose distance does not follow J under a
motion of tens of um. It takes up nothing (``takes_part``). One such point past the demo blade's
hub end, at core.weights' grazing floor (41 against a median weight of 0.6), held two thirds of
the take-up's weakest direction (the span screw) and made the take-up along it 3.7 where the
fit's is 11.5 mm per mm of bias (docs/maintainers.md).
"""

import numpy as np


def rigid_jacobian(points, normals, center):
    """(N, 6) J_i = [n_i, (p_i - c) x n_i]: the change of each signed distance under the rigid
    motion (t, w) about ``center``."""
    points = np.asarray(points, dtype=float)
    normals = np.asarray(normals, dtype=float)
    return np.hstack([normals, np.cross(points - np.asarray(center, dtype=float), normals)])


def beam_normal(normals, beams):
    """(N,) beta_i = beam_i . n_i: a point's distance change per unit lengthening of its
    reading."""
    return np.einsum("ij,ij->i", np.asarray(beams, dtype=float),
                     np.asarray(normals, dtype=float))


def takes_part(points, normals, beams, weights, max_incidence_rad=None):
    """(N,) bool: the points that take part in the take-up: positive finite weight, finite
    point, normal and beta, and (with ``max_incidence_rad``) not an edge foot,
    |beta_i| >= cos(max_incidence_rad)."""
    beta = beam_normal(normals, beams)
    w = np.asarray(weights, dtype=float)
    with np.errstate(invalid="ignore"):
        keep = (np.isfinite(w) & (w > 0) & np.isfinite(beta)
                & np.all(np.isfinite(np.asarray(points, dtype=float)), axis=1))
        if max_incidence_rad is not None:
            keep &= np.abs(beta) >= np.cos(max_incidence_rad)
    return keep


def take_up(points, normals, beams, weights, center, max_incidence_rad=None):
    """(6,) r = (t mm, w rad) per unit reading bias: the weighted least-squares rigid motion
    about ``center`` whose normal parts J_i r best fit beta_i = beam_i . n_i (module
    docstring), over the points ``takes_part`` keeps. A pose direction those points do not
    measure takes up nothing (minimum-norm solution, rcond 1e-12); r = 0 without any point.

    points, normals, beams: (N, 3), one frame (normals and beams unit); weights (N,);
    max_incidence_rad: the sensor's largest incidence (None: no point is an edge foot)."""
    keep = takes_part(points, normals, beams, weights, max_incidence_rad)
    return take_up_of(points, normals, beams, weights, center, keep)


def take_up_of(points, normals, displacements, weights, center, keep):
    """(6,) the weighted least-squares rigid motion (take_up's r) whose normal parts best fit
    those of the points' ``displacements`` (N, 3), any small error field linear in one
    parameter (a unit reading bias: the beams; an axis error's field,
    inspection.uncertainty.calibration_fields), over the points ``keep``."""
    if not np.any(keep):
        return np.zeros(6)
    normals = np.asarray(normals, dtype=float)[keep]
    beta = beam_normal(normals, np.asarray(displacements, dtype=float)[keep])
    w = np.asarray(weights, dtype=float)[keep]
    J = rigid_jacobian(np.asarray(points, dtype=float)[keep], normals, center)
    JW = J.T * w
    return np.linalg.lstsq(JW @ J, JW @ beta, rcond=1e-12)[0]


def left_over(points, normals, beams, r, center):
    """(N,) s_i = beta_i - J_i r: what is left of a unit reading bias in each point's residual
    once the rigid motion r (about ``center``, take_up's) has taken up its part (NaN where a
    point, normal or beam is not finite)."""
    return beam_normal(normals, beams) - rigid_jacobian(points, normals, center) @ r
