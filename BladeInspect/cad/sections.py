"""Section curves: plane cuts of a CAD shape as dense ordered polylines (the nominal profiles
a CMM measures; docs/maintainers.md "Words")."""
import numpy as np

import FreeCAD
import Part

from ..core import background
from ..core.errors import InputError

DEFAULT_SPACING = 0.02  # mm between polyline points: chord sag < 1 um at a 0.05 mm radius


def cut(shape, point, normal, spacing=DEFAULT_SPACING):
    """The intersection of ``shape`` with the plane through ``point`` with ``normal``.

    Returns a list of (K, 3) polylines, each ordered along its curve with points at most
    ``spacing`` apart (plus every vertex). A closed loop repeats its first point at the end,
    so its arc length is the loop's perimeter. InputError when the plane misses the shape."""
    point, normal = _plane(point, normal, spacing)
    return [_join(pieces, closed) for pieces, closed in _wire_pieces(shape, point, normal,
                                                                      spacing)]


def _plane(point, normal, spacing):
    """(point, unit normal) of a section plane; InputError on a bad plane or spacing."""
    point = np.asarray(point, dtype=float).reshape(3)
    normal = np.asarray(normal, dtype=float).reshape(3)
    length = np.linalg.norm(normal)
    if not np.all(np.isfinite(point)) or not np.isfinite(length) or length < 1e-12:
        raise InputError("section plane: point %s and normal %s must be finite, the normal "
                         "non-zero" % (point.tolist(), normal.tolist()))
    if not spacing > 0:
        raise InputError("section spacing: must be positive, got %r" % spacing)
    return point, normal / length


def _wire_pieces(shape, point, normal, spacing):
    """For each wire of the cut: (its edges' point lists in order, closed)."""
    wires = _slice(shape, point, normal)
    if not wires:
        raise InputError("section plane through %s with normal %s misses the shape"
                         % (np.round(point, 6).tolist(), np.round(normal, 6).tolist()))
    out = []
    for group in Part.sortEdges([e for w in wires for e in w.Edges]):
        wire = Part.Wire(group)
        out.append(([_edge_points(e, spacing) for e in wire.OrderedEdges], wire.isClosed()))
    return out


def _join(pieces, closed):
    """One polyline of a wire's edges' points (each edge's last point is the next's first)."""
    pts = np.vstack([p[:-1] for p in pieces] + [pieces[-1][-1:]])
    if closed:
        pts[-1] = pts[0]
    return pts


# Newton's stopping rule for a point of the exact cut: on the plane and at its slice point's
# place along the curve to this (mm), far below the micrometre the cut is promised to.
EXACT_TOL = 1e-10
EXACT_ITERATIONS = 30
# A Newton point farther than this from its slice point (mm) is another branch of the cut
# (the far side of a thin profile), not the point: the slice strays micrometres, never this.
EXACT_REACH = 0.05


def exact_cut(shape, point, normal, spacing=DEFAULT_SPACING):
    """``cut``'s polylines with every point moved onto the exact intersection of its face and
    the plane, and the face each point lies on: (polylines, faces), faces a list of (K,) int
    arrays of indices into shape.Faces.

    OCC's slice approximates the intersection of B-spline faces by curves that stray up to
    20 um from it (worst near a trailing edge); its points only start Newton's method, which
    solves S(u, v) . n = d on the face the slice's edge lies on, with the point held at its
    place along the curve (its offset along the curve's tangent n x N kept), continued from
    point to point along the edge. A point Newton cannot settle (a face the plane only
    grazes) keeps its slice position."""
    point, normal = _plane(point, normal, spacing)
    faces = list(shape.Faces)
    d = float(point @ normal)
    polylines, faces_of = [], []
    for pieces, closed in _wire_pieces(shape, point, normal, spacing):
        exact, which = [], []
        for pts in pieces:
            background.tick()    # a GUI's event loop turns between the pieces
            k = _nearest_face(faces, pts[len(pts) // 2])
            exact.append(_onto_face(faces[k].Surface, pts, normal, d))
            which.append(np.full(len(pts), k, dtype=int))
        polylines.append(_join(exact, closed))
        faces_of.append(np.concatenate([w[:-1] for w in which] + [which[-1][-1:]]))
    return polylines, faces_of


def _onto_face(surf, pts, normal, d):
    out = pts.copy()
    n = FreeCAD.Vector(*normal)
    try:
        bounds = surf.bounds()
    except Exception:
        bounds = (-np.inf, np.inf, -np.inf, np.inf)
    uv = None
    for k, p in enumerate(pts):
        target = FreeCAD.Vector(*p)
        got = None if uv is None else _newton(surf, bounds, uv, target, n, d)
        if got is None or np.linalg.norm(got[1] - p) > EXACT_REACH:
            try:
                uv = surf.parameter(target)
            except Exception:
                uv = None
            got = None if uv is None else _newton(surf, bounds, uv, target, n, d)
        if got is not None and np.linalg.norm(got[1] - p) <= EXACT_REACH:
            uv, out[k] = got
    return out


def _nearest_face(faces, p):
    vertex = Part.Vertex(FreeCAD.Vector(*p))
    best, best_d = 0, np.inf
    for i, face in enumerate(faces):
        box = face.BoundBox
        box.enlarge(0.1)        # the slice strays micrometres off the face
        if box.isValid() and not box.isInside(vertex.Point):
            continue
        dist = face.distToShape(vertex)[0]
        if dist < best_d:
            best, best_d = i, dist
    return best


def _newton(surf, bounds, uv, target, n, d):
    """((u, v), xyz) of the point of surf on the plane x . n = d at target's place along the
    curve (target - S) . T = 0, T = n x N, (u, v) kept within ``bounds``; None when it does
    not settle on the surface."""
    u, v = uv
    u0, u1, v0, v1 = bounds
    for _ in range(EXACT_ITERATIONS):
        s = surf.value(u, v)
        su = surf.getDN(u, v, 1, 0)
        sv = surf.getDN(u, v, 0, 1)
        tangent = n.cross(su.cross(sv))
        if tangent.Length < 1e-12:
            return None
        tangent.normalize()
        r1 = (s - target).dot(tangent)
        r2 = s.dot(n) - d
        a, b, c, e = su.dot(tangent), sv.dot(tangent), su.dot(n), sv.dot(n)
        det = a * e - b * c
        if abs(r1) < EXACT_TOL and abs(r2) < EXACT_TOL:
            return (u, v), np.array([s.x, s.y, s.z])
        if abs(det) < 1e-18:
            return None
        du = (-r1 * e + b * r2) / det
        dv = (-a * r2 + c * r1) / det
        u = min(max(u + du, u0), u1)
        v = min(max(v + dv, v0), v1)
    return None


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
