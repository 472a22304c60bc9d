"""The blade's span: the stacking direction and the extent along it that section heights are
percentages of. One rule for every caller, so that a CAD-planned section at 50 % and the
analysed section at 50 % are the same plane (the planner and the analysis once had a rule each,
3.3° apart on the demo blade and 19° on Rotor 67 when the planner chose its own axis, and both
measured the extent over every face, so a root block below the hub moved every section).

Inputs are the nominal's area-weighted surface samples (xyz, weight, face index), its face
roles, and which faces are planes; nothing here knows FreeCAD.
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
# A hub fitted plane farther than this from square to the principal axis is no reference.
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


def span(xyz, weight, face, roles, planar_faces, n_faces, span_axis=None):
    """The Span of a blade.

    Axis: ``span_axis`` when given; else, when the hub faces are named, the normal of the plane
    fitted to them (a swept or leaned blade's principal axis tilts by the sweep, while a CMM
    and the rig's rotary axis cut it square to the hub); else the longest principal axis of the
    airfoil faces' samples. It points from the hub to the tip when they are named, else so that
    its largest component is positive (+Z for a blade modelled along Z); a given axis is
    turned to point hub -> tip when those are named.
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
        axis = pca.principal_axes(xyz[on_airfoil], weight[on_airfoil]).axes[:, 0].copy()
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
