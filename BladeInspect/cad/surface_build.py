"""B-spline surfaces through section grids, and closing two blade sides into a solid.

Shared by the demo blade and the section-table blades (Rotor 67). The interpolation is done
here in numpy rather than with ``Part.BSplineSurface().interpolate`` so that the parameters
are ours: two sides built with the same spanwise parameters through the same leading- and
trailing-edge points get bit-identical boundary curves, and sewing them needs no tolerance.
"""
import numpy as np
from scipy.interpolate import make_interp_spline

import FreeCAD
import Part

from ..core.errors import InputError


def _knots_mults(t):
    """Unique knots and their multiplicities from a flat knot vector."""
    knots, mults = [], []
    for value in t:
        if knots and abs(value - knots[-1]) <= 1e-12 * max(1.0, abs(value)):
            mults[-1] += 1
        else:
            knots.append(float(value))
            mults.append(1)
    return knots, mults


def interpolate_grid(points, u_params, v_params, degree=3):
    """A B-spline surface through ``points`` (nv, nu, 3): row k is a curve along u at v_params[k].

    Clamped, not-a-knot interpolation in both directions (degree lowered when there are too
    few points). Returns a ``Part.BSplineSurface`` with S(u_params[i], v_params[k]) equal to
    points[k, i].
    """
    grid = np.asarray(points, dtype=float)
    u = np.asarray(u_params, dtype=float)
    v = np.asarray(v_params, dtype=float)
    if grid.ndim != 3 or grid.shape[2] != 3 or grid.shape[:2] != (len(v), len(u)):
        raise InputError("surface grid: expected (%d, %d, 3) points, got %s"
                         % (len(v), len(u), grid.shape))
    if len(u) < 2 or len(v) < 2 or np.any(np.diff(u) <= 0) or np.any(np.diff(v) <= 0):
        raise InputError("surface grid: parameters must increase strictly, at least 2 each way")
    du = min(degree, len(u) - 1)
    dv = min(degree, len(v) - 1)
    along_u = make_interp_spline(u, grid, k=du, axis=1)
    poles_u = along_u.c  # (n_poles_u, nv, 3): scipy puts the spline axis first
    along_v = make_interp_spline(v, poles_u, k=dv, axis=1)
    poles = along_v.c  # (n_poles_v, n_poles_u, 3)
    uknots, umults = _knots_mults(along_u.t)
    vknots, vmults = _knots_mults(along_v.t)
    surface = Part.BSplineSurface()
    surface.buildFromPolesMultsKnots(
        [[FreeCAD.Vector(*poles[j, i]) for j in range(poles.shape[0])]
         for i in range(poles.shape[1])],
        umults, vmults, uknots, vknots, False, False, du, dv)
    return surface


def close_sides(side_a, side_b, cap_edges_start, cap_edges_end, planar_caps):
    """Sew two side faces and two caps into a solid (outward normals).

    ``side_a``/``side_b`` are faces meeting along their u=0 and u=1 edges;
    ``cap_edges_*`` are the pairs of edges bounding each cap (the two sides' end curves, run
    in the same direction). Planar caps become plane faces; otherwise a ruled face spans the
    two curves. A ruled face passes through both exactly and needs no trimming, where a filled
    (Plate) face only approximates its boundary (microns off on a blade tip) and is trimmed from
    a larger degree-8 surface, which makes every distance query near the cap slow and sends it
    to OpenCASCADE. Returns (solid, [faces in the order side_a, side_b, cap_start, cap_end]) as
    found in the solid's face list (indices).
    """
    caps = []
    for a, b in (cap_edges_start, cap_edges_end):
        if planar_caps:
            caps.append(Part.Face(Part.Wire([a, b])))
        else:
            caps.append(Part.makeRuledSurface(a, b))
    originals = [side_a, side_b] + caps
    sewn = Part.Compound(originals)
    sewn.sewShape()
    shells = sewn.Shells
    if len(shells) != 1 or not shells[0].isClosed():
        raise InputError("blade surfaces: sides and caps do not close into one shell")
    solid = Part.Solid(shells[0])
    if solid.Volume < 0:
        solid = Part.Solid(shells[0].reversed())
    if not solid.isValid() or solid.Volume <= 0:
        raise InputError("blade surfaces: the closed shell is not a valid solid")
    return solid, match_faces(solid, originals)


def match_faces(shape, originals):
    """Index in ``shape.Faces`` of each original face (same area and centre of mass)."""
    indices = []
    for orig in originals:
        c = orig.CenterOfMass
        best = min(range(len(shape.Faces)),
                   key=lambda i: (shape.Faces[i].CenterOfMass - c).Length
                   + abs(shape.Faces[i].Area - orig.Area))
        indices.append(best)
    if len(set(indices)) != len(indices):
        raise InputError("blade surfaces: faces of the solid could not be told apart")
    return indices
