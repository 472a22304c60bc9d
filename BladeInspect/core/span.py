"""The blade's span: the stacking direction and the extent along it that section heights are
percentages of. One rule for every caller, so that a CAD-planned section at 50 % and the
analysed section at 50 % are the same plane (the planner and the analysis once had a rule each,
3.3° apart on the demo blade and 19° on Rotor 67 when the planner chose its own axis, and both
measured the extent over every face, so a root block below the hub moved every section).

Inputs are the nominal's area-weighted surface samples (xyz, weight, face index, and their
normals for the geometric axis), its face roles, and which faces are planes; nothing here
knows FreeCAD.
"""
from dataclasses import dataclass

import numpy as np

from . import pca
from .errors import InputError
from .fitting import fit_plane

AIRFOIL_ROLES = ("suction", "pressure", "leading_edge", "trailing_edge")
# A planar face with no role counts as a hub or tip cap when it lies within this fraction of
# the airfoil's extent of the airfoil faces' ends: the airfoil faces' samples sit at cell
# centres and fall short of the ends, a cap lies on them, and a root block or a platform
# stands clear of them.
CAP_REACH = 0.02
# A hub fitted plane farther than this from square to the geometric axis is no reference.
HUB_SQUARE_COS = 0.9


@dataclass
class Span:
    axis: np.ndarray      # (3,) unit, hub -> tip
    lo: float             # extent along axis (of xyz @ axis), mm
    hi: float
    origin: np.ndarray    # (3,) area-weighted centroid of the airfoil faces


def airfoil_faces(roles, n_faces, planar_faces):
    """Faces that make the airfoil: the roles when named, else every face that is not a plane
    (a blade's hub and tip caps are planes), else every face."""
    roles = roles or {}
    faces = sorted({int(i) for name in AIRFOIL_ROLES for i in roles.get(name, ())})
    if faces:
        return faces
    planar = set(int(i) for i in planar_faces)
    return [i for i in range(n_faces) if i not in planar] or list(range(n_faces))


def span(xyz, weight, face, roles, planar_faces, n_faces, span_axis=None, normals=None):
    """The Span of a blade.

    Axis: ``span_axis`` when given; else, when the hub faces are named, the normal of the plane
    fitted to them (a swept or leaned blade's principal axis tilts by the sweep, while a CMM
    and the rig's rotary axis cut it square to the hub); else geometric_axis (the hub and tip
    caps' normal, or the stacking direction), never the longest extent: a turbine vane's chord
    is often longer than its span. It points from the hub to the tip when they are named,
    else so that its largest component is positive (+Z for a blade modelled along Z); a given
    axis is turned to point hub -> tip when those are named.
    ``normals``: the samples' unit normals (without them the stacking direction is the
    longest principal axis).
    Extent: the airfoil faces and the hub and tip caps (named, or unnamed planes lying at the
    airfoil's ends); never a root block, platform or fixture modelled with the blade."""
    xyz = np.asarray(xyz, dtype=float)
    weight = np.asarray(weight, dtype=float)
    face = np.asarray(face)
    roles = roles or {}
    on_airfoil = np.isin(face, airfoil_faces(roles, n_faces, planar_faces))
    on_hub = np.isin(face, [int(i) for i in roles.get("hub", ())])
    on_tip = np.isin(face, [int(i) for i in roles.get("tip", ())])
    if span_axis is not None:
        axis = np.asarray(span_axis, dtype=float).ravel()
        if axis.shape != (3,) or not np.all(np.isfinite(axis)) or np.linalg.norm(axis) == 0:
            raise InputError("span axis: need three finite numbers, not all zero, got %r"
                             % (span_axis,))
        axis = axis / np.linalg.norm(axis)
    else:
        normal = None if normals is None else np.asarray(normals, dtype=float)
        axis = geometric_axis(xyz, weight, face, on_airfoil, normal,
                              [] if (on_hub.any() or on_tip.any()) else planar_faces)
        if np.count_nonzero(on_hub) >= 3:
            try:
                hub_normal = fit_plane(xyz[on_hub]).normal
            except InputError:
                hub_normal = None
            if hub_normal is not None and abs(hub_normal @ axis) > HUB_SQUARE_COS:
                axis = np.asarray(hub_normal, dtype=float)
    if on_hub.any() and on_tip.any():
        if (xyz[on_tip].mean(axis=0) - xyz[on_hub].mean(axis=0)) @ axis < 0:
            axis = -axis
    elif span_axis is None and axis[np.argmax(np.abs(axis))] < 0:
        axis = -axis
    h = xyz @ axis
    lo, hi = float(h[on_airfoil].min()), float(h[on_airfoil].max())
    caps = on_hub | on_tip
    if not (on_hub.any() or on_tip.any()):
        reach = CAP_REACH * (hi - lo)
        for i in planar_faces:
            mine = face == int(i)
            if mine.any() and (np.all(np.abs(h[mine] - lo) <= reach)
                               or np.all(np.abs(h[mine] - hi) <= reach)):
                caps |= mine
    if caps.any():
        lo, hi = min(lo, float(h[caps].min())), max(hi, float(h[caps].max()))
    origin = np.average(xyz[on_airfoil], axis=0, weights=weight[on_airfoil])
    return Span(axis=axis, lo=lo, hi=hi, origin=origin)


def geometric_axis(xyz, weight, face, on_airfoil, normals=None, planar_faces=()):
    """The span direction from the blade's own faces (unsigned).

    Hub and tip caps first: planar faces that the airfoil faces' samples all lie on one side
    of and reach to within CAP_REACH of the airfoil's extent along that
    normal; the axis is the dominant direction of their area-weighted normals (the caps of an
    extruded blade are its span's normal exactly). Without caps: the stacking direction, the
    principal axis of the airfoil samples nearest to the direction the airfoil's normals spread
    least along (sum w n n^T's smallest eigenvector: a blade's surface normals lie nearly square
    to its span, but a twisted blade's tilt by its twist, 10 to 35 degrees on the demo blade
    and Rotor 67, so that direction only chooses among the principal axes, never replaces
    them); without normals the longest principal axis."""
    pts, w = xyz[on_airfoil], weight[on_airfoil]
    caps = _cap_normals(xyz, weight, face, pts, normals, planar_faces)
    if caps is not None:
        return caps
    axes = pca.principal_axes(pts, w).axes
    if normals is None:
        return axes[:, 0].copy()
    n = normals[on_airfoil]
    spread = np.linalg.eigh((n * w[:, None]).T @ n)[1][:, 0]
    return axes[:, int(np.argmax(np.abs(spread @ axes)))].copy()


def _cap_normals(xyz, weight, face, airfoil_pts, normals, planar_faces):
    if normals is None or not len(planar_faces):
        return None
    tensor = np.zeros((3, 3))
    for i in planar_faces:
        mine = face == int(i)
        if not mine.any():
            continue
        m = np.average(normals[mine], axis=0, weights=weight[mine])
        if np.linalg.norm(m) < 0.5:
            continue
        m = m / np.linalg.norm(m)
        d = (airfoil_pts - np.average(xyz[mine], axis=0, weights=weight[mine])) @ m
        reach = CAP_REACH * float(np.ptp(d))
        behind = -reach <= d.max() <= reach        # a cap closing the airfoil's end
        before = -reach <= d.min() <= reach        # a platform the airfoil stands on
        if np.ptp(d) > 0 and (behind or before):
            tensor += float(weight[mine].sum()) * np.outer(m, m)
    if not tensor.any():
        return None
    return np.linalg.eigh(tensor)[1][:, -1].copy()
