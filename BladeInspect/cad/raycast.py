"""Rays on the nominal: the OCC side of core.raycast. The faces' tessellation comes from
``Face.tessellate``; the few rays core.raycast cannot decide are intersected by OCC
(``Shape.section`` with the ray as an edge)."""

import numpy as np

import FreeCAD
import Part

from ..core import raycast as kernel


def face_meshes(faces, deflection):
    """Per face (index, vertices (V, 3), triangles (T, 3)) of OCC's tessellation within
    ``deflection`` mm, for core.raycast.Tessellation."""
    meshes = []
    for i, f in enumerate(faces):
        pts, facets = f.tessellate(deflection)
        xyz = np.array([[p.x, p.y, p.z] for p in pts], dtype=float).reshape(-1, 3)
        meshes.append((i, xyz, np.array(facets, dtype=int).reshape(-1, 3)))
    return meshes


def cast(nominal, origins, directions, deflection=None):
    """Nominal.raycast: core.raycast.cast on the nominal's kept tessellation, OCC for the rest."""
    kernel.check_rays(origins, directions)
    if deflection is None:
        deflection = kernel.default_deflection(nominal.bbox_corners)
    tess = nominal.tessellation(deflection)
    return kernel.cast(nominal.face_set, tess, nominal.bbox_corners, origins, directions,
                       lambda o, d, t_far: _occ_ray(nominal, o, d, t_far))


def _occ_ray(nominal, o, d, t_far):
    """Exact first hit by OCC: section of the shape with the ray as an edge."""
    a = FreeCAD.Vector(*o)
    b = FreeCAD.Vector(*(o + t_far * d))
    if (b - a).Length < 1e-12:
        return np.nan, -1, np.full(3, np.nan)
    section = nominal.shape.section(Part.LineSegment(a, b).toShape())
    best = None
    for vert in section.Vertexes:
        p = np.array([vert.X, vert.Y, vert.Z])
        t = float(np.dot(p - o, d) / np.dot(d, d))
        if best is None or t < best[0]:
            best = (t, vert)
    if best is None:
        return np.nan, -1, np.full(3, np.nan)
    t, vert = best
    _, _, info = nominal.shape.distToShape(vert)
    if info[0][0] == "Face":
        f = int(info[0][1])
        nrm = np.array(nominal.faces[f].normalAt(*info[0][2]), dtype=float)
    else:
        f = -1
        nrm = np.full(3, np.nan)
        for i, face in enumerate(nominal.faces):
            dd, _, finfo = face.distToShape(vert)
            if dd < 1e-7:
                uv = finfo[0][2] if finfo[0][0] == "Face" else face.Surface.parameter(vert.Point)
                f, nrm = i, np.array(face.normalAt(*uv), dtype=float)
                break
    return t, f, nrm / np.linalg.norm(nrm)

