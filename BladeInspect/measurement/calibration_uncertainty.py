"""The rig calibration's own uncertainty: how well `calibrate` knows the rotary axis,
and what that means at the part.

The axis is a line: four parameters, (x, z) where it crosses the machine plane y = 0 and its
tilts from +Y about machine Z and about X (radians). Each sphere centre comes from a known-radius
fit of its cap with a covariance from that fit's residuals and Jacobian
(core.fitting.fit_sphere); the centres are independent (fresh readings at every angle). The
axis follows from the centres by the circle fit (core.fitting.fit_circle_3d), so its covariance
is J C J^T with J the circle fit's derivative with respect to the centres (central differences)
and C the centres' block-diagonal covariance.

At the part: a table-frame point q, read at rotary angle a through an axis off by d, is placed
at K.table_point(K'.machine_point_of_table(q, a), a) instead of q (K believed, K' true): an
error G(q, a) d, linear in d. Its variance along a direction, averaged over the three machine
directions (a surface normal of unknown orientation) and over the calibration's angles, at the
sphere's table position (where the part is mounted), is ``at_part_mm`` squared. The rigid part of
that error that the registration absorbs is not subtracted, yet the figure is an average, not a
bound at every reading: a tilt's error grows along the axis. On the demo loop's scan (16264
readings at 22 angles), each reading's error along its normal after the take-up
(inspection.uncertainty.calibration_fields) is 0.14 um at the median, 0.23 um at the 95th
percentile and 0.35 um at most, against at_part_mm 0.22 um. The deviations' term uses the
figure (beside ~3.4 um of noise it moves their U by under 0.1 %); the airfoil draws use the
fields of ``error_fields``.
"""

from dataclasses import dataclass

import numpy as np

from ..core import fitting
from ..rig.kinematics import RigKinematics

PARAMETERS = ("axis_x_mm", "axis_z_mm", "tilt_about_z_rad", "tilt_about_x_rad")
# Central-difference step for the centres (mm) and the axis parameters: far above rounding, far
# below any curvature of the circle fit over the centres' micrometre errors.
CENTRE_STEP_MM = 1e-4
PARAMETER_STEP = 1e-6


def axis_parameters(centres):
    """(4,) axis parameters (module notes) of the circle through the centres, the normal
    taken along +Y."""
    circle = fitting.fit_circle_3d(np.asarray(centres, dtype=float))
    o, n = circle.center, circle.normal
    n = n if n[1] > 0 else -n
    point = o - (o[1] / n[1]) * n
    return np.array([point[0], point[2], np.arctan2(n[0], n[1]), np.arctan2(n[2], n[1])])


def kinematics_with(kinematics, parameters):
    """A copy of ``kinematics`` with the axis of these parameters."""
    import copy
    x, z, tz, tx = parameters
    direction = np.array([np.tan(tz), 1.0, np.tan(tx)])
    out = copy.deepcopy(kinematics)
    out.axis_point = np.array([x, 0.0, z])
    out.axis_direction = direction / np.linalg.norm(direction)
    return out


@dataclass
class CalibrationUncertainty:
    parameters: np.ndarray        # (4,) PARAMETERS
    covariance: np.ndarray        # (4, 4)
    at_part_mm: float             # 1 sigma at the part (module notes)
    circle_chi2_per_dof: float    # circle residuals against the centres' covariance: ~1

    def to_json(self):
        return {"calibration_uncertainty_mm": float(self.at_part_mm),
                "calibration_parameters": list(PARAMETERS),
                "calibration_parameter_values": self.parameters.tolist(),
                "calibration_covariance": self.covariance.tolist(),
                "calibration_uncertainty_method":
                    "sphere centres' fit covariance propagated through the circle fit (J C J^T);"
                    " at the part: RMS over the calibration angles and the three machine "
                    "directions at the sphere's table position, 1 sigma",
                "calibration_circle_chi2_per_dof": float(self.circle_chi2_per_dof)}


def parameter_covariance(centres, centre_covariances):
    """(4, 4) covariance of axis_parameters(centres) for independent centres."""
    centres = np.asarray(centres, dtype=float)
    base = axis_parameters(centres)
    J = np.zeros((4, centres.size))
    for k in range(centres.size):
        step = np.zeros(centres.size)
        step[k] = CENTRE_STEP_MM
        plus = axis_parameters(centres + step.reshape(centres.shape))
        minus = axis_parameters(centres - step.reshape(centres.shape))
        J[:, k] = (plus - minus) / (2.0 * CENTRE_STEP_MM)
    C = np.zeros((centres.size, centres.size))
    for i, cov in enumerate(centre_covariances):
        C[3 * i:3 * i + 3, 3 * i:3 * i + 3] = np.asarray(cov, dtype=float)[:3, :3]
    return base, J @ C @ J.T


def error_jacobian(kinematics, parameters, table_point, angle_deg):
    """(3, 4): the table-frame error of ``table_point`` read at ``angle_deg`` per unit error of
    each axis parameter (module notes)."""
    return error_fields(kinematics, parameters, np.reshape(table_point, (1, 3)),
                        [float(angle_deg)])[0]


def error_fields(kinematics, parameters, table_points, angles_deg):
    """(N, 3, 4): error_jacobian of each table-frame point (N, 3) read at its own angle (N,),
    one pass of the central differences per distinct angle (a scan's readings come at a few
    dozen rotary angles)."""
    q = np.asarray(table_points, dtype=float).reshape(-1, 3)
    angles = np.asarray(angles_deg, dtype=float).reshape(-1)
    if len(angles) != len(q):
        raise ValueError("error_fields: %d points, %d angles" % (len(q), len(angles)))
    parameters = np.asarray(parameters, dtype=float)
    believed = kinematics_with(kinematics, parameters)
    moved = []
    for k in range(4):
        step = np.zeros(4)
        step[k] = PARAMETER_STEP
        moved.append([kinematics_with(kinematics, parameters + sign * step)
                      for sign in (1.0, -1.0)])
    G = np.zeros((len(q), 3, 4))
    for angle in np.unique(angles):
        at = angles == angle
        for k, (plus, minus) in enumerate(moved):
            placed = [believed.table_point(true.machine_point_of_table(q[at], angle), angle)
                      for true in (plus, minus)]
            G[at, :, k] = (placed[0] - placed[1]) / (2.0 * PARAMETER_STEP)
    return G


def at_part_mm(kinematics, parameters, covariance, table_point, angles_deg):
    """1 sigma of a reading's error along an unknown direction at ``table_point``, RMS over the
    angles (module notes)."""
    variances = [np.trace(G @ covariance @ G.T) / 3.0
                 for G in (error_jacobian(kinematics, parameters, table_point, a)
                           for a in angles_deg)]
    return float(np.sqrt(np.mean(variances)))


def calibration_uncertainty(centres, centre_covariances, angles_deg, kinematics=None,
                            table_point=(0.0, 0.0, 0.0)):
    """CalibrationUncertainty of an axis fitted to these centres (module notes)."""
    kinematics = kinematics if kinematics is not None else RigKinematics()
    centres = np.asarray(centres, dtype=float)
    parameters, covariance = parameter_covariance(centres, centre_covariances)
    circle = fitting.fit_circle_3d(centres)
    # The circle's residuals are distances (2 per centre in the fit, 6 parameters): compare their
    # sum of squares with what the centres' own scatter predicts, isotropically.
    mean_var = np.mean([np.trace(np.asarray(c)[:3, :3]) / 3.0 for c in centre_covariances])
    dof = max(2 * len(centres) - 6, 1)
    chi2 = float(np.sum(circle.residuals ** 2) / (mean_var * dof)) if mean_var > 0 else np.nan
    return CalibrationUncertainty(
        parameters=parameters, covariance=covariance,
        at_part_mm=at_part_mm(kinematics, parameters, covariance, table_point, angles_deg),
        circle_chi2_per_dof=chi2)
