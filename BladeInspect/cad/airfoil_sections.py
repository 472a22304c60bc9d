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


class NotAirfoilSection(InputError):
    """The plane's cut is not the airfoil's profile (it runs over faces that are not blade
    faces): the section is refused, the run goes on."""


def airfoil_section(shape, origin, normal, engine_axis=(1.0, 0.0, 0.0),
                    spacing=AIRFOIL_SPACING, polylines=None, faces=None, blade_faces=None,
                    face_roles=None):
    """(ordered (N, 2) profile, PlaneFrame) of the CAD shape cut by the plane: the closed loop
    enclosing the largest area, without its repeated closing point, counter-clockwise about
    the normal; its points lie on the exact intersection of the faces and the plane
    (sections.exact_cut). InputError when the plane misses the shape or cuts no closed loop.
    ``polylines``, ``faces``: this plane's exact cut at ``spacing`` and its points' faces when
    already made (the section table's): the cut, half the airfoil stage's time without draws,
    is not made again. ``blade_faces``: indices of the faces that make the airfoil; a cut
    with a point on any other face (a hub, platform, root block, fillet or shroud, or a cap
    the plane crosses the blade through) raises NotAirfoilSection naming them, by
    ``face_roles`` ({index: role}) when given: such a loop is another profile than the
    airfoil's, and a loop beside it shares the plane's band of measured points with it."""
    frame = plane_frame(origin, normal, engine_axis)
    if not polylines:
        polylines, faces = sections.exact_cut(shape, frame.origin, frame.normal, spacing)
    if blade_faces is not None and faces is not None:
        _check_blade_faces(faces, blade_faces, face_roles or {})
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


def _check_blade_faces(faces, blade_faces, face_roles):
    found = set(int(i) for f in faces for i in np.asarray(f).ravel() if i >= 0)
    other = sorted(found - set(int(i) for i in blade_faces))
    if other:
        names = ", ".join("%d (%s)" % (i, face_roles.get(i, "no airfoil role")) for i in other)
        raise NotAirfoilSection("the plane's cut runs over face%s %s, not blade faces (hub, "
                                "platform, fillet, shroud or an end cap): not the airfoil's "
                                "profile" % ("s" if len(other) > 1 else "", names))
