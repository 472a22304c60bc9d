"""Section curves: plane cuts of a CAD shape as dense ordered polylines (the nominal profiles
a CMM measures; docs/maintainers.md "Words")."""
import numpy as np

import FreeCAD
import Part

from ..core.errors import InputError

DEFAULT_SPACING = 0.02  # mm between polyline points: chord sag < 1 um at a 0.05 mm radius


def cut(shape, point, normal, spacing=DEFAULT_SPACING):
    """The intersection of ``shape`` with the plane through ``point`` with ``normal``.

    Returns a list of (K, 3) polylines, each ordered along its curve with points at most
    ``spacing`` apart (plus every vertex). A closed loop repeats its first point at the end,
    so its arc length is the loop's perimeter. InputError when the plane misses the shape."""
    point = np.asarray(point, dtype=float).reshape(3)
    normal = np.asarray(normal, dtype=float).reshape(3)
    length = np.linalg.norm(normal)
    if not np.all(np.isfinite(point)) or not np.isfinite(length) or length < 1e-12:
        raise InputError("section plane: point %s and normal %s must be finite, the normal "
                         "non-zero" % (point.tolist(), normal.tolist()))
    if not spacing > 0:
        raise InputError("section spacing: must be positive, got %r" % spacing)
    normal = normal / length
    wires = _slice(shape, point, normal)
    if not wires:
        raise InputError("section plane through %s with normal %s misses the shape"
                         % (np.round(point, 6).tolist(), np.round(normal, 6).tolist()))
    polylines = []
    for group in Part.sortEdges([e for w in wires for e in w.Edges]):
        wire = Part.Wire(group)
        pts = np.vstack([_edge_points(e, spacing)[:-1] for e in wire.OrderedEdges]
                        + [_edge_points(wire.OrderedEdges[-1], spacing)[-1:]])
        if wire.isClosed():
            pts[-1] = pts[0]
        polylines.append(pts)
    return polylines


def _edge_points(edge, spacing):
    """Points along ``edge`` in the wire's direction, at most ``spacing`` apart.

    Evaluated at parameters spread evenly in arc length (from a fine parameter sampling):
    OCC's own Distance discretisation is ~50x slower for the same points."""
    first, last = edge.ParameterRange
    probe = np.linspace(first, last, 1001)
    xyz = np.array([tuple(edge.valueAt(t)) for t in probe])
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xyz, axis=0), axis=1))])
    # The margin covers the probe polygon being shorter than the curve.
    n = max(2, int(np.ceil(1.05 * arc[-1] / spacing)) + 1)
    params = np.interp(np.linspace(0.0, arc[-1], n), arc, probe)
    pts = np.array([tuple(edge.valueAt(t)) for t in params])
    if edge.Orientation == "Reversed":
        pts = pts[::-1]
    return pts


def _slice(shape, point, normal):
    d = float(np.dot(point, normal))
    try:
        return list(shape.slice(FreeCAD.Vector(*normal), d))
    except Exception:
        pass
    # Slicing refuses some shapes (e.g. loose face compounds): intersect with a plane face
    # larger than the shape and chain the resulting edges into wires.
    half = shape.BoundBox.DiagonalLength + 1.0
    plane = Part.Plane(FreeCAD.Vector(*point), FreeCAD.Vector(*normal))
    edges = shape.section(plane.toShape(-half, half, -half, half)).Edges
    if not edges:
        return []
    return [Part.Wire(group) for group in Part.sortEdges(edges)]
