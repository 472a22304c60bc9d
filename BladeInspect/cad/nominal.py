"""The nominal CAD as arrays: every face as an exact (rational) B-spline, dense samples, and the
exact signed point-to-CAD distance with an OpenCASCADE fallback for the cases the fast path
cannot decide.

Faces are converted with ``Face.toNurbs()`` (BRepBuilderAPI_NurbsConvert): planes, cylinders,
spheres, surfaces of revolution and offsets become exact rational B-splines, and the face's
trimming curves are carried into the new parameterisation. ``Surface.toBSpline()`` is not
used: for analytic surfaces it is an approximation (degree 14 for a cylinder, ~1e-10 off).

Fast path of ``signed_distance``: core.closest (a k-d tree over the samples, Newton on the
candidate faces); a point it cannot decide goes to OCC (``Shape.distToShape``), point by
point. The fraction that did is reported.
"""

import numpy as np

import FreeCAD
import Part

from ..core import bspline
from ..core.bspline import SurfaceData
from ..core.closest import DistanceResult, FaceDomain, FaceSet, Samples, point_in_domain
from ..core.edges import CurveData, FaceEdges, evaluate_curve
from ..core.errors import InputError
from ..core.raycast import Tessellation
from ..core.trim import TrimDomain
from .orient import face_sides, side_warnings
from .raycast import cast, face_meshes

# Samples per face and per direction at least, whatever the spacing.
MIN_SAMPLES_PER_SIDE = 12
# Total samples aimed at when no spacing is given.
DEFAULT_SAMPLE_COUNT = 60000
# Points per trimming edge when discretising its pcurve, at first and at most.
PCURVE_SAMPLES = 400
MAX_PCURVE_SAMPLES = 102400
# Aimed chord error of the discretised trimming curves, relative to the face's size in 3D.
CHORD_TARGET = 1e-6


def _flat_knots(knots, mults):
    return np.repeat(np.asarray(knots, float), np.asarray(mults, int))


def surface_data_from_bspline(bs, u_range, v_range, closed_u=False, closed_v=False):
    """SurfaceData of a Part.BSplineSurface (a periodic one is made non-periodic on a copy)."""
    bs = bs.copy()
    if bs.isUPeriodic():
        bs.setUNotPeriodic()
    if bs.isVPeriodic():
        bs.setVNotPeriodic()
    poles = np.array([[[p.x, p.y, p.z] for p in row] for row in bs.getPoles()], dtype=float)
    weights = np.array(bs.getWeights(), dtype=float)
    return SurfaceData(
        degree_u=bs.UDegree, degree_v=bs.VDegree,
        knots_u=_flat_knots(bs.getUKnots(), bs.getUMultiplicities()),
        knots_v=_flat_knots(bs.getVKnots(), bs.getVMultiplicities()),
        poles=poles, weights=weights, u_range=np.array(u_range[:2], float),
        v_range=np.array(v_range[:2], float), closed_u=closed_u, closed_v=closed_v)


def _nurbs_face(face):
    """The face with an exact B-spline surface and its pcurves in that surface's parameters."""
    if isinstance(face.Surface, Part.BSplineSurface):
        return face
    converted = face.toNurbs().Faces
    if len(converted) != 1 or not isinstance(converted[0].Surface, Part.BSplineSurface):
        raise InputError("CAD face of type %s could not be converted to a B-spline"
                         % type(face.Surface).__name__)
    return converted[0]


def _surface_of_face(nface):
    u0, u1, v0, v1 = nface.ParameterRange
    bs = nface.Surface
    closed = []
    for periodic, period, lo, hi in ((bs.isUPeriodic(), bs.UPeriod, u0, u1),
                                     (bs.isVPeriodic(), bs.VPeriod, v0, v1)):
        closed.append(bool(periodic and abs((hi - lo) - period()) <= 1e-9 * max(1.0, period())))
    surf = surface_data_from_bspline(bs, (u0, u1), (v0, v1), closed_u=closed[0], closed_v=closed[1])
    # Wrapping is only safe when the box is exactly the knot range of the non-periodic copy.
    p, q = surf.degree_u, surf.degree_v
    if surf.closed_u and (abs(surf.knots_u[p] - u0) > 1e-9 or abs(surf.knots_u[-p - 1] - u1) > 1e-9):
        surf.closed_u = False
    if surf.closed_v and (abs(surf.knots_v[q] - v0) > 1e-9 or abs(surf.knots_v[-q - 1] - v1) > 1e-9):
        surf.closed_v = False
    return surf


def _pcurve_values(curve):
    """A function of parameters t (N,) -> (N, 2) points of a face's curve in its surface's
    (u, v): in numpy for B-splines and lines (what NurbsConvert leaves), else by OCC."""
    if isinstance(curve, Part.Geom2d.BSplineCurve2d) and not curve.isPeriodic():
        weights = np.array(curve.getWeights(), dtype=float)
        data = CurveData(degree=curve.Degree,
                         knots=_flat_knots(curve.getKnots(), curve.getMultiplicities()),
                         poles=np.array([[q.x, q.y] for q in curve.getPoles()], dtype=float),
                         weights=weights if curve.isRational() else None,
                         t_range=np.array([curve.FirstParameter, curve.LastParameter]))
        return lambda t: evaluate_curve(data, t, order=0)[0]
    if isinstance(curve, Part.Geom2d.Line2d):
        origin = np.array([curve.Location.x, curve.Location.y])
        direction = np.array([curve.Direction.x, curve.Direction.y])
        return lambda t: origin + np.asarray(t)[:, None] * direction
    return lambda t: np.array([[q.x, q.y] for q in (curve.value(x) for x in t)])


def _pcurve_polyline(values, a, b, chord_target):
    """(points (K, 2), largest chord error) of a polyline on a pcurve ``values`` over [a, b]:
    PCURVE_SAMPLES uniform segments, each one whose midpoint is farther than ``chord_target``
    from its chord split in four, until none is or the edge has MAX_PCURVE_SAMPLES segments
    (refined where the curve bends only: a uniform refinement that meets the target at the
    sharpest bend costs the whole curve that density)."""
    t = np.linspace(a, b, PCURVE_SAMPLES + 1)
    pts = values(t)
    mids = values(0.5 * (t[1:] + t[:-1]))
    while True:
        chord = np.linalg.norm(mids - 0.5 * (pts[1:] + pts[:-1]), axis=1)
        bad = np.flatnonzero(chord > chord_target)
        if not len(bad) or len(t) - 1 + 3 * len(bad) > MAX_PCURVE_SAMPLES:
            return pts, float(chord.max())
        # Each bad segment [t0, t1] gets nodes at its quarters (its midpoint already known)
        # and midpoints at its eighths.
        t0, h = t[bad], t[bad + 1] - t[bad]
        new_t = t0[:, None] + h[:, None] * np.array([0.25, 0.75])
        new_mid = t0[:, None] + h[:, None] * np.array([0.125, 0.375, 0.625, 0.875])
        vals = values(np.concatenate([new_t.ravel(), new_mid.ravel()]))
        q = vals[:2 * len(bad)].reshape(-1, 2, 2)
        m = vals[2 * len(bad):].reshape(-1, 4, 2)
        # Every segment becomes 1 (good) or 4 (bad) segments; rebuild nodes and midpoints.
        per = np.ones(len(t) - 1, int)
        per[bad] = 4
        seg_start = np.concatenate([[0], np.cumsum(per)])
        n_seg = seg_start[-1]
        t_new = np.empty(n_seg + 1)
        p_new = np.empty((n_seg + 1, 2))
        m_new = np.empty((n_seg, 2))
        good = np.flatnonzero(per == 1)
        t_new[seg_start[good]], p_new[seg_start[good]] = t[good], pts[good]
        m_new[seg_start[good]] = mids[good]
        k = seg_start[bad]
        t_new[k], p_new[k] = t0, pts[bad]
        t_new[k + 1], p_new[k + 1] = new_t[:, 0], q[:, 0]
        t_new[k + 2], p_new[k + 2] = t0 + 0.5 * h, mids[bad]
        t_new[k + 3], p_new[k + 3] = new_t[:, 1], q[:, 1]
        for j in range(4):
            m_new[k + j] = m[:, j]
        t_new[-1], p_new[-1] = t[-1], pts[-1]
        t, pts, mids = t_new, p_new, m_new


def _face_domain(nface, surf, planar):
    (u0, u1), (v0, v1) = surf.u_range, surf.v_range
    su, sv = u1 - u0, v1 - v0
    tol_u, tol_v = 1e-9 * max(1.0, su), 1e-9 * max(1.0, sv)
    # The margin is a uv distance in every direction, so the chord error is aimed at in uv,
    # scaled by the faster parameter's length per unit: in 3D it is then at most
    # CHORD_TARGET of the face's size across the boundary (an error aimed at relative to the
    # larger parameter range alone is ~100x that along a cylinder's angle in radians).
    lu, lv = _extent(surf)
    speed = max(lu / max(su, 1e-300), lv / max(sv, 1e-300))
    chord_target = CHORD_TARGET * (max(lu, lv) / speed if speed > 0 else max(su, sv))
    polylines = []
    max_chord = 0.0
    on_box = True
    for wire in nface.Wires:
        for edge in wire.Edges:
            pc = nface.curveOnSurface(edge)
            if pc is None:
                raise InputError("CAD face has an edge without a curve on its surface")
            curve, a, b = pc
            pts, chord = _pcurve_polyline(_pcurve_values(curve), a, b, chord_target)
            max_chord = max(max_chord, chord)
            on_u = (np.all(np.abs(pts[:, 0] - u0) <= tol_u) or np.all(np.abs(pts[:, 0] - u1) <= tol_u))
            on_v = (np.all(np.abs(pts[:, 1] - v0) <= tol_v) or np.all(np.abs(pts[:, 1] - v1) <= tol_v))
            if not (on_u or on_v):
                on_box = False
            polylines.append(pts)
            # A seam edge is listed once but bounds the domain on both sides of the period.
            if surf.closed_u and on_u:
                polylines.append(pts + [su if np.abs(pts[0, 0] - u0) <= tol_u else -su, 0.0])
            if surf.closed_v and on_v:
                polylines.append(pts + [0.0, sv if np.abs(pts[0, 1] - v0) <= tol_v else -sv])
    # A Part.Plane's (u, v) are lengths along orthonormal axes, and NurbsConvert keeps them.
    planar_scale = 1.0 if planar else None
    if on_box:
        return FaceDomain(None, 0.0, planar_scale)
    segments = np.concatenate([np.stack([p[:-1], p[1:]], axis=1) for p in polylines])
    margin = 4.0 * max_chord + 1e-9 * max(su, sv)
    return FaceDomain(TrimDomain(segments), margin, planar_scale)


def curve_data_of_edge(edge):
    """CurveData of an edge of a NURBS-converted face (its 3D curve an exact B-spline), or
    None for a degenerate edge (a point)."""
    if edge.Degenerated:
        return None
    curve = edge.Curve
    if not isinstance(curve, Part.BSplineCurve):
        raise InputError("CAD edge of type %s is not a B-spline after conversion"
                         % type(curve).__name__)
    curve = curve.copy()
    if curve.isPeriodic():
        curve.setNotPeriodic()
    weights = np.array(curve.getWeights(), dtype=float)
    return CurveData(degree=curve.Degree,
                     knots=_flat_knots(curve.getKnots(), curve.getMultiplicities()),
                     poles=np.array([[q.x, q.y, q.z] for q in curve.getPoles()], dtype=float),
                     weights=weights if curve.isRational() else None,
                     t_range=np.array(edge.ParameterRange, dtype=float))


def _face_edges(nface, domain):
    """core.edges.FaceEdges of a trimmed face (None for a face that fills its box)."""
    if domain.index is None:
        return None
    curves = [c for c in (curve_data_of_edge(e) for e in nface.Edges) if c is not None]
    return FaceEdges(curves) if curves else None


def _extent(surf, n=9):
    """Rough lengths of the face along u and along v (longest iso-curve of an n x n grid)."""
    u = np.linspace(*surf.u_range, n)
    v = np.linspace(*surf.v_range, n)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    (S,) = bspline.evaluate(surf, uu.ravel(), vv.ravel(), order=0)
    S = S.reshape(n, n, 3)
    lu = np.linalg.norm(np.diff(S, axis=0), axis=2).sum(axis=0).max()
    lv = np.linalg.norm(np.diff(S, axis=1), axis=2).sum(axis=1).max()
    return lu, lv


class Nominal:
    """The nominal CAD: faces, their exact surfaces, dense samples and the distance queries."""

    def __init__(self, shape, faces, nurbs_faces, surfaces, domains, reversed_, samples,
                 bbox_corners, roles, face_sides, edges=None):
        self.shape = shape
        self.faces = faces
        self.surfaces = surfaces
        self.samples = samples
        self.bbox_corners = bbox_corners
        self.roles = roles
        # cad.orient.FaceSide per face: how its outward side was decided
        self.face_sides = face_sides
        # The faces as arrays for the numeric kernels (core.closest, core.raycast).
        self.face_set = FaceSet(surfaces, domains, reversed_, samples, edges)
        self._nurbs_faces = nurbs_faces
        self._solids = list(shape.Solids)
        self._face_compound = Part.makeCompound(faces)
        self._edge_faces = None
        self._compound_edges = None
        self._tessellation = None

    @property
    def domains(self):
        """core.closest.FaceDomain per face: its trimmed domain in its SurfaceData's (u, v)."""
        return self.face_set.domains

    @property
    def reversed(self):
        """(F,) bool per face: its outward normal is -(Su x Sv)."""
        return self.face_set.reversed

    def nearest_sample(self, points):
        """Index into ``samples`` of each (N, 3) point's nearest sample."""
        return self.face_set.nearest_sample(points)

    def tessellation(self, deflection):
        """core.raycast.Tessellation of the faces at this chord deflection (mm), kept until a
        cast asks for another one (its per-direction grids are reused across casts)."""
        if self._tessellation is None or self._tessellation.deflection != deflection:
            self._tessellation = Tessellation(self.face_set, face_meshes(self.faces, deflection),
                                              deflection)
        return self._tessellation

    @property
    def cad_faces(self):
        """result.json's ``cad_faces``: per face, how its outward side was decided."""
        return [side.to_json() for side in self.face_sides]

    @property
    def face_side_warnings(self):
        """Lines for result.json's warnings: faces whose outside is a guess or a user's."""
        return side_warnings(self.face_sides)

    # ------------------------------------------------------------------ exact distance

    def signed_distance(self, points, start=None):
        """Exact signed distance of (N,3) points to the CAD faces -> DistanceResult.
        ``start``: a core.closest.FootStart of these points, e.g. a previous result's for the
        same points before they moved a little: it saves work, the answer is the same."""
        points = _as_points(points, "signed_distance: points")
        out, hard = self.face_set.closest(points, start)
        # OCC is only called afterwards, from this thread.
        if len(hard):
            self._occ_into(points[hard], out, hard, solid_test=False)
        return out

    # ------------------------------------------------------------------ OCC reference

    def signed_distance_occ(self, points):
        """The slow independent reference: per point, Shape.distToShape on all the faces; the
        sign from isInside for solids, else from the nearest face's normal (Face.normalAt)."""
        points = _as_points(points, "signed_distance_occ: points")
        n = len(points)
        out = DistanceResult(np.empty((n, 3)), np.empty(n, int), np.empty((n, 2)),
                             np.empty((n, 3)), np.empty(n), np.ones(n, bool))
        self._occ_into(points, out, np.arange(n))
        return out

    def _occ_into(self, points, out, rows, solid_test=True):
        # The fallback asks OCC only about the faces that may hold the closest point (the
        # independent reference, signed_distance_occ, about all of them).
        reach = None if solid_test else self.face_set.faces_within_reach(points)
        for k, (p, row) in enumerate(zip(points, rows)):
            d, f, c, nrm = self._occ_point(p, solid_test,
                                           None if reach is None else np.flatnonzero(reach[k]))
            out.closest[row] = c
            out.face[row] = f
            out.normal[row] = nrm
            out.distance[row] = d
            out.fallback[row] = True
        # Parameters on our SurfaceData: project the exact closest points (they are on face f).
        out.uv[rows] = self.face_set.parameters_of(out.closest, out.face, rows)

    def _occ_distance(self, vec, faces):
        """Shape.distToShape's (distance, closest point, (kind, index into the face compound's
        faces or edges, parameters)) of a point to the faces ``faces`` (None: all)."""
        vertex = Part.Vertex(vec)
        if faces is None or len(faces) == len(self.faces):
            dist, pairs, info = self._face_compound.distToShape(vertex)
            return dist, pairs[0][0], info[0][:3]
        best = None
        for f in faces:
            dist, pairs, info = self.faces[f].distToShape(vertex)
            if best is None or dist < best[0]:
                best = (dist, pairs[0][0], info[0][:3], f)
        dist, c, (kind, index, param), f = best
        if kind == "Face":
            index = f
        elif kind == "Edge":
            index = self._compound_edge_of(f, int(index))
        return dist, c, (kind, index, param)

    def _compound_edge_of(self, face_index, edge_index):
        """Index into the face compound's edges of edge ``edge_index`` of face ``face_index``."""
        if self._compound_edges is None:
            by_hash = {}
            for i, edge in enumerate(self._face_compound.Edges):
                by_hash.setdefault(edge.hashCode(), []).append((i, edge))
            self._compound_edges = [[next(i for i, other in by_hash[e.hashCode()] if e.isSame(other))
                                     for e in face.Edges] for face in self.faces]
        return self._compound_edges[face_index][edge_index]

    def _occ_point(self, p, solid_test=True, faces=None):
        """(signed distance, face, closest point, normal) of one point by OCC, against the
        faces ``faces`` (None: all; the others must be known to be farther). The sign comes
        from the solid's own inside test (9 ms a point on a blade, and wrong for about 1 in 600
        points 0.05 mm off Rotor 67's sides near the leading edge) or, without ``solid_test``,
        from the outward normal when the point lies along it from its closest point (a foot
        point inside a face, where that sign is exact) and from the pseudo-normal of an edge
        between two faces (the sum of their outward normals at the foot point, exact too)."""
        vec = FreeCAD.Vector(*p)
        # Against the faces, not the solid: a solid is at distance 0 from any point inside it.
        dist, c, (kind, index, param) = self._occ_distance(vec, faces)
        c = np.array(c, dtype=float)
        diff = p - c
        pseudo = None if solid_test or kind != "Edge" else self._edge_pseudo_normal(int(index), c)
        if kind == "Face":
            face_index = int(index)
            face_normal = np.array(self.faces[face_index].normalAt(*param), dtype=float)
        elif pseudo is not None:
            (f0, n0), (f1, n1) = pseudo
            face_normal = n0 + n1
            # Report the face whose side of the edge the point is on.
            face_index = f0 if abs(np.dot(diff, n0)) >= abs(np.dot(diff, n1)) else f1
        else:
            face_index, face_normal = self._nearest_face_at(c, p)
        along_normal = ((kind == "Face" and abs(np.dot(diff, face_normal))
                         >= (1.0 - 1e-9) * dist * np.linalg.norm(face_normal))
                        or (pseudo is not None and abs(np.dot(diff, face_normal))
                            >= 1e-6 * dist * np.linalg.norm(face_normal)))
        if self._solids and (solid_test or not along_normal):
            inside = any(s.isInside(vec, 1e-9, True) for s in self._solids)
            sign = -1.0 if inside else 1.0
        else:
            sign = -1.0 if np.dot(diff, face_normal) < 0 else 1.0
        if kind == "Face" or dist <= 1e-12:
            nrm = face_normal / np.linalg.norm(face_normal)
        else:
            nrm = sign * diff / dist
        return sign * dist, face_index, c, nrm

    def _edge_pseudo_normal(self, edge_index, c):
        """((face, outward unit normal at c), (face, normal)) of the two faces meeting at an
        edge of the face compound, or None (a seam, a free or non-manifold edge)."""
        if self._edge_faces is None:
            by_hash = {}
            for f, face in enumerate(self.faces):
                for e in face.Edges:
                    by_hash.setdefault(e.hashCode(), []).append((f, e))
            self._edge_faces = [sorted({f for f, e in by_hash.get(edge.hashCode(), ())
                                        if e.isSame(edge)})
                                for edge in self._face_compound.Edges]
        faces = self._edge_faces[edge_index]
        if len(faces) != 2:
            return None
        out = []
        for f in faces:
            face = self.faces[f]
            n = np.array(face.normalAt(*face.Surface.parameter(FreeCAD.Vector(*c))), dtype=float)
            length = np.linalg.norm(n)
            if not length > 0:
                return None
            out.append((f, n / length))
        return out

    def _nearest_face_at(self, c, p):
        """The face an edge/vertex point belongs to that is nearest to p, and its normal there;
        ties (the faces meeting at the edge) average their normals."""
        vc = Part.Vertex(FreeCAD.Vector(*c))
        vp = Part.Vertex(FreeCAD.Vector(*p))
        best, best_d, normals = None, np.inf, []
        for i, face in enumerate(self.faces):
            if face.distToShape(vc)[0] > 1e-7:
                continue
            dp, _, info = face.distToShape(vp)
            if info[0][0] == "Face":
                nrm = np.array(face.normalAt(*info[0][2]), dtype=float)
            else:
                uv = face.Surface.parameter(FreeCAD.Vector(*c))
                nrm = np.array(face.normalAt(*uv), dtype=float)
            normals.append(nrm)
            if dp < best_d:
                best, best_d = i, dp
        if best is None:
            return int(np.argmin([f.distToShape(vc)[0] for f in self.faces])), np.zeros(3)
        return best, np.sum(normals, axis=0)

    # ------------------------------------------------------------------ rays

    def raycast(self, origins, directions, deflection=None):
        """First hit of each ray o + t d (t >= 0) on the CAD faces -> (t (N,) NaN on a miss,
        face (N,) -1 on a miss, outward normal (N,3)). Directions need not be unit: t is in
        units of |d| (mm for unit directions). See core.raycast for the method."""
        return cast(self, origins, directions, deflection)


def _as_points(points, what):
    points = np.asarray(points, dtype=float)
    if points.ndim == 1 and points.size == 3:
        points = points[None]
    if points.ndim != 2 or points.shape[1] != 3:
        raise InputError("%s must be (N, 3), got shape %s" % (what, points.shape))
    if not np.all(np.isfinite(points)):
        raise InputError("%s contain NaN or infinite coordinates" % what)
    return points


def _bbox_corners(shape):
    try:
        bb = shape.optimalBoundingBox()
    except Exception:          # older OCC builds lack it; the plain box is only looser
        bb = shape.BoundBox
    xs, ys, zs = (bb.XMin, bb.XMax), (bb.YMin, bb.YMax), (bb.ZMin, bb.ZMax)
    return np.array([[x, y, z] for x in xs for y in ys for z in zs], dtype=float)


def _sample_face(surf, domain, reverse, spacing):
    lu, lv = _extent(surf)
    nu = max(MIN_SAMPLES_PER_SIDE, int(np.ceil(lu / spacing)))
    nv = max(MIN_SAMPLES_PER_SIDE, int(np.ceil(lv / spacing)))
    (u0, u1), (v0, v1) = surf.u_range, surf.v_range
    du, dv = (u1 - u0) / nu, (v1 - v0) / nv
    # Cell centres: never on a boundary or a degenerate pole.
    u = u0 + (np.arange(nu) + 0.5) * du
    v = v0 + (np.arange(nv) + 0.5) * dv
    uu, vv = np.meshgrid(u, v, indexing="ij")
    uv = np.column_stack([uu.ravel(), vv.ravel()])
    if domain.index is not None:
        inside, _ = point_in_domain(domain, uv)
        uv = uv[inside]
    # The power-basis patches (which Newton's projection builds anyway): cheaper than de
    # Boor's recurrence.
    S, Su, Sv = surf.power_patches().evaluate(uv[:, 0], uv[:, 1], order=1)
    nrm = np.cross(Su, Sv)
    area = np.linalg.norm(nrm, axis=1)
    keep = area > 0
    nrm = nrm[keep] / area[keep, None]
    if reverse:
        nrm = -nrm
    return S[keep], nrm, uv[keep], area[keep] * du * dv


def nominal_from_shape(shape, roles=None, sample_spacing=None, flip_faces=()):
    """Nominal of a solid, shell or compound of (open) faces.

    sample_spacing: distance between samples in mm; by default chosen so the whole CAD gets
    about DEFAULT_SAMPLE_COUNT samples (at least MIN_SAMPLES_PER_SIDE^2 per face).
    Faces outside a closed solid are turned outward by cad.orient's rule (``flip_faces``:
    indices whose side the user reverses); ``Nominal.face_sides`` says how each was decided.
    The faces the Nominal keeps (and, for a shape without solids, its shape) carry the
    decided orientations, so the fast path (``reversed``), OCC's ``normalAt`` in the fallback
    and the ray caster all see the same outward side.
    """
    if shape is None or shape.isNull() or len(shape.Faces) == 0:
        raise InputError("CAD shape has no faces")
    if sample_spacing is not None and not (np.isfinite(sample_spacing) and sample_spacing > 0):
        raise InputError("sample_spacing: expected a positive length in mm, got %r" % (sample_spacing,))
    faces = list(shape.Faces)
    nurbs, surfaces, domains, reversed_ = [], [], [], []
    for face in faces:
        nface = _nurbs_face(face)
        surf = _surface_of_face(nface)
        nurbs.append(nface)
        surfaces.append(surf)
        domains.append(_face_domain(nface, surf, isinstance(face.Surface, Part.Plane)))
        reversed_.append(face.Orientation == "Reversed")
    sides = face_sides(shape, faces, surfaces, domains, reversed_, flip_faces)
    flipped = [s.index for s in sides if s.flip]
    for i in flipped:
        faces[i] = faces[i].reversed()
        nurbs[i] = nurbs[i].reversed()
        reversed_[i] = not reversed_[i]
    if flipped and not shape.Solids:
        shape = Part.makeCompound(faces)
    if sample_spacing is None:
        area = sum(f.Area for f in faces)
        sample_spacing = max(np.sqrt(area / DEFAULT_SAMPLE_COUNT), 1e-6)
    parts = [_sample_face(surfaces[i], domains[i], reversed_[i], sample_spacing)
             for i in range(len(faces))]
    samples = Samples(
        xyz=np.concatenate([p[0] for p in parts]),
        normal=np.concatenate([p[1] for p in parts]),
        face=np.concatenate([np.full(len(p[0]), i) for i, p in enumerate(parts)]),
        uv=np.concatenate([p[2] for p in parts]),
        weight=np.concatenate([p[3] for p in parts]))
    edges = [_face_edges(nurbs[i], domains[i]) for i in range(len(faces))]
    return Nominal(shape, faces, nurbs, surfaces, domains, reversed_, samples,
                   _bbox_corners(shape), {k: list(v) for k, v in (roles or {}).items()}, sides,
                   edges)
