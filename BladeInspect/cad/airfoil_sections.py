"""The CAD nominal's airfoil profile in a section plane, as core.airfoil takes it: an ordered
2D loop of points and the plane frame that maps it back to the CAD frame.

The frame's x axis is the engine axis projected into the plane (so core.airfoil's default
engine axis (1, 0) is the CAD's engine axis), its y axis normal x x; angles measured in the
2D frame are counter-clockwise about the plane normal."""
from dataclasses import dataclass

import numpy as np

from ..core.errors import InputError
from . import sections

# The cut's own spacing: the interpolating spline through it misses a G1 junction of an edge
# circle and a flank by about h^2 times the curvature jump / 8 -- nanometres.
AIRFOIL_SPACING = sections.DEFAULT_SPACING


@dataclass
class PlaneFrame:
    origin: np.ndarray     # (3,) CAD frame
    e1: np.ndarray         # (3,) unit, the engine axis in the plane
    e2: np.ndarray         # (3,) unit, normal x e1
    normal: np.ndarray     # (3,) unit

    def to_2d(self, xyz):
        d = np.atleast_2d(np.asarray(xyz, dtype=float)) - self.origin
        return np.column_stack([d @ self.e1, d @ self.e2])

    def to_3d(self, xy):
        xy = np.atleast_2d(np.asarray(xy, dtype=float))
        return self.origin + xy[:, :1] * self.e1 + xy[:, 1:2] * self.e2

    def vector_to_3d(self, v):
        v = np.atleast_2d(np.asarray(v, dtype=float))
        return v[:, :1] * self.e1 + v[:, 1:2] * self.e2


def plane_frame(origin, normal, engine_axis=(1.0, 0.0, 0.0)):
    """The section plane's frame with x along the engine axis projected into the plane."""
    origin = np.asarray(origin, dtype=float).reshape(3)
    normal = np.asarray(normal, dtype=float).reshape(3)
    axis = np.asarray(engine_axis, dtype=float).reshape(3)
    if not (np.all(np.isfinite(normal)) and np.linalg.norm(normal) > 1e-12
            and np.all(np.isfinite(axis)) and np.linalg.norm(axis) > 1e-12):
        raise InputError("section plane: normal %s and engine axis %s must be finite and "
                         "non-zero" % (normal.tolist(), axis.tolist()))
    normal = normal / np.linalg.norm(normal)
    axis = axis / np.linalg.norm(axis)
    in_plane = axis - (axis @ normal) * normal
    if np.linalg.norm(in_plane) < 1e-6:
        raise InputError("engine axis %s is normal to the section plane; it has no direction "
                         "in it" % np.round(axis, 6).tolist())
    e1 = in_plane / np.linalg.norm(in_plane)
    return PlaneFrame(origin, e1, np.cross(normal, e1), normal)


def airfoil_section(shape, origin, normal, engine_axis=(1.0, 0.0, 0.0),
                    spacing=AIRFOIL_SPACING, polylines=None):
    """(ordered (N, 2) profile, PlaneFrame) of the CAD shape cut by the plane: the closed loop
    enclosing the largest area (the airfoil; other loops, e.g. of a fillet or a shroud, are
    left out), without its repeated closing point, counter-clockwise about the normal.
    InputError when the plane misses the shape or cuts no closed loop. ``polylines``: this
    plane's cut at ``spacing`` when already made (the section table's): OCC's slice, half the
    airfoil stage's time without draws, is not run again."""
    frame = plane_frame(origin, normal, engine_axis)
    if not polylines:
        polylines = sections.cut(shape, frame.origin, frame.normal, spacing)
    loops = [p for p in polylines
             if len(p) >= 4 and np.linalg.norm(p[-1] - p[0]) < 1e-9]
    if not loops:
        raise InputError("section plane through %s with normal %s cuts no closed profile"
                         % (np.round(frame.origin, 6).tolist(),
                            np.round(frame.normal, 6).tolist()))
    flat = [frame.to_2d(p[:-1]) for p in loops]
    areas = [_signed_area(xy) for xy in flat]
    best = int(np.argmax(np.abs(areas)))
    xy = flat[best]
    return (xy if areas[best] > 0 else xy[::-1].copy()), frame


def _signed_area(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
