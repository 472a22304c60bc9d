"""The pose of a part from its datum faces, as a datum reference frame is built (ISO 5459,
ASME Y14.5): the primary datum plane fixes three degrees of freedom (the direction of its
normal: two rotations; the position along it), the secondary two (the rotation about the
primary normal; the position along its own normal made square to the primary), the tertiary
one (the position along the third axis, square to both).

Each datum is the least-squares plane of the measured points on that face (core.fitting.
fit_plane) and the plane of the CAD face's own samples. The frames

    e1 = n_A,   e2 = n_B - (n_B . e1) e1 (unit),   e3 = e1 x e2,
    origin = sum_k e_k (e_k . c_k),  c_A, c_B, c_C the planes' points,

are built alike for the measured and the CAD planes; the pose maps the measured frame onto
the CAD's. The tertiary plane's own normal enters only through the origin (its position along
e3), as the standard's hierarchy has it. numpy only.
"""

from dataclasses import dataclass

import numpy as np

from .errors import InputError
from .fitting import fit_plane

ORDER = ("primary", "secondary", "tertiary")
# A datum whose normal is within this of the datums before it fixes nothing new.
MIN_SINE = 0.1


@dataclass
class DatumPlane:
    normal: np.ndarray     # (3,) unit
    point: np.ndarray      # (3,) on the plane
    rms_mm: float          # flatness of the points about it (RMS)
    n_points: int


def plane_of(points, name="datum"):
    points = np.asarray(points, dtype=float)
    if len(points) < 3:
        raise InputError("%s: %d points on the face, at least 3 needed" % (name, len(points)))
    fit = fit_plane(points)
    return DatumPlane(normal=fit.normal, point=fit.point,
                      rms_mm=float(np.sqrt(np.mean(fit.residuals ** 2))), n_points=len(points))


def frame(planes, names=ORDER):
    """(3x3 rotation with rows e1 e2 e3, origin (3,)) of three DatumPlanes."""
    e1 = planes[0].normal / np.linalg.norm(planes[0].normal)
    b = planes[1].normal - (planes[1].normal @ e1) * e1
    if np.linalg.norm(b) < MIN_SINE:
        raise InputError("--datum-faces: the %s datum is parallel to the %s" % (names[1], names[0]))
    e2 = b / np.linalg.norm(b)
    e3 = np.cross(e1, e2)
    if abs(planes[2].normal @ e3) < MIN_SINE:
        raise InputError("--datum-faces: the %s datum does not fix the position along the "
                         "third axis (it is parallel to the %s or %s)" % (names[2], *names[:2]))
    axes = np.array([e1, e2, e3])
    origin = sum(axes[k] * (axes[k] @ planes[k].point) for k in range(3))
    return axes, origin


def datum_pose(measured_planes, cad_planes):
    """(4x4) rigid motion taking the measured datum frame onto the CAD's. The measured
    normals are turned to agree with the CAD's first (a plane fit's normal has no side)."""
    oriented = []
    for m, c in zip(measured_planes, cad_planes):
        sign = 1.0 if m.normal @ c.normal >= 0 else -1.0
        oriented.append(DatumPlane(sign * m.normal, m.point, m.rms_mm, m.n_points))
    A_m, o_m = frame(oriented)
    A_c, o_c = frame(cad_planes)
    R = A_c.T @ A_m
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = o_c - R @ o_m
    return T
