"""First hit of rays on the nominal's faces, exact on the B-spline surfaces.

Stage 1 finds the first hit on a fine tessellation (OCC's, ``Face.tessellate``): rays are
grouped by direction; for each group the triangles are projected on the plane normal to the
group's direction and bucketed in a 2D grid, so a ray (a point, or a short segment when the
group's directions differ slightly, in that plane) meets only the triangles of its cells;
Möller–Trumbore decides those pairs, vectorised. Stage 2 moves each hit onto the exact surface
of the hit triangle's face by Newton on S(u, v) - o - t d = 0 (unknowns u, v, t), started from
the foot point of the tessellated hit. A ray whose refined hit leaves the face's trimmed domain,
lands too close to its boundary to tell, or does not converge is intersected by OCC instead
(``Shape.section`` with the ray as an edge).

Rays that graze a face within the tessellation's deflection of its silhouette may be reported
as misses (or hits) differently from the exact surface: a scanning sensor never measures there.
"""

import numpy as np

import FreeCAD
import Part

from ..core import bspline
from ..core.errors import InputError
from ..core.trim import _csr, _pairs
from .nominal import point_in_domain

# Directions closer than this (in unit-vector components) share one projection plane.
DIRECTION_BIN = 0.02
# Ray/triangle pairs evaluated per chunk.
PAIR_CHUNK = 400000
# Above this many direction groups, rays are grouped by their dominant axis instead.
MAX_GROUPS = 48
NEWTON_ITERATIONS = 30
# A neighbour face's exact hit replaces a doubtful tessellated one within this many deflections.
NEIGHBOUR_SLACK = 20.0


class Tessellation:
    def __init__(self, nominal, deflection):
        verts, tris, face = [], [], []
        base = 0
        for i, f in enumerate(nominal.faces):
            pts, facets = f.tessellate(deflection)
            if not facets:
                continue
            verts.append(np.array([[p.x, p.y, p.z] for p in pts], dtype=float))
            tris.append(np.array(facets, dtype=int) + base)
            face.append(np.full(len(facets), i))
            base += len(pts)
        if not tris:
            raise InputError("CAD faces could not be tessellated for ray casting")
        self.vertices = np.concatenate(verts)
        self.triangles = np.concatenate(tris)
        self.face = np.concatenate(face)
        self.deflection = deflection
        v = self.vertices[self.triangles]
        self.v0 = v[:, 0]
        self.e1 = v[:, 1] - v[:, 0]
        self.e2 = v[:, 2] - v[:, 0]
        self.lo = self.vertices.min(axis=0)
        self.hi = self.vertices.max(axis=0)


def _cells_overlapping(tri2, cx, cy, glo, cell):
    """Which (triangle, cell) pairs really overlap in the plane: the boxes already do, so only
    the triangle's three edge normals can separate them (separating axis theorem)."""
    lo = glo + np.column_stack([cx, cy]) * cell
    corners = lo[:, None, :] + np.array([[0, 0], [1, 0], [0, 1], [1, 1]]) * cell
    keep = np.ones(len(tri2), bool)
    for i in range(3):
        a, b, c = tri2[:, i], tri2[:, (i + 1) % 3], tri2[:, (i + 2) % 3]
        n = np.column_stack([a[:, 1] - b[:, 1], b[:, 0] - a[:, 0]])
        side = np.einsum("ij,ij->i", c - a, n)
        proj = np.einsum("ikj,ij->ik", corners - a[:, None, :], n) * np.sign(side)[:, None]
        # a degenerate (edge-on) triangle has side 0 and is kept
        keep &= ~((side != 0) & np.all(proj < 0, axis=1))
    return keep


def _cells_on_segment(a, b, cx, cy, glo, cell):
    """Which cells of the segments' boxes the segments really cross: the cell's corners must
    not all lie strictly on one side of the segment's line."""
    lo = glo + np.column_stack([cx, cy]) * cell
    corners = lo[:, None, :] + np.array([[0, 0], [1, 0], [0, 1], [1, 1]]) * cell
    n = np.column_stack([a[:, 1] - b[:, 1], b[:, 0] - a[:, 0]])
    proj = np.einsum("ikj,ij->ik", corners - a[:, None, :], n)
    return ~(np.all(proj > 0, axis=1) | np.all(proj < 0, axis=1))


def _basis(d):
    a = np.array([1.0, 0, 0]) if abs(d[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = np.cross(d, a)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(d, e1)


def _slab(origins, directions, lo, hi):
    """Parameter interval [t0, t1] of each ray inside the box (t0 > t1 when it misses)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / directions
        ta = (lo - origins) * inv
        tb = (hi - origins) * inv
    ta = np.where(np.isnan(ta), -np.inf, ta)
    tb = np.where(np.isnan(tb), np.inf, tb)
    t0 = np.max(np.minimum(ta, tb), axis=1)
    t1 = np.min(np.maximum(ta, tb), axis=1)
    return np.maximum(t0, 0.0), t1


def _moller_trumbore(o, d, v0, e1, e2):
    """t of each ray/triangle pair (inf where no hit at t >= 0)."""
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-300
    inv = 1.0 / np.where(ok, det, 1.0)
    s = o - v0
    bu = np.einsum("ij,ij->i", s, p) * inv
    q = np.cross(s, e1)
    bv = np.einsum("ij,ij->i", d, q) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    eps = 1e-10     # closes cracks between neighbouring triangles
    hit = ok & (bu >= -eps) & (bv >= -eps) & (bu + bv <= 1 + eps) & (t >= 0)
    return np.where(hit, t, np.inf)


def _first_hits_group(tess, origins, dirs, t0, t1):
    """Tessellation first hit (t, triangle) for rays of nearly one direction."""
    n = len(origins)
    d0 = dirs.mean(axis=0)
    d0 /= np.linalg.norm(d0)
    e1, e2 = _basis(d0)
    P = np.column_stack([tess.vertices @ e1, tess.vertices @ e2])
    tri2 = P[tess.triangles]                       # (T, 3, 2)
    lo2, hi2 = tri2.min(axis=1), tri2.max(axis=1)
    # The ray's trace on the plane runs from its entry to its exit point of the bounding box.
    a = origins + t0[:, None] * dirs
    b = origins + t1[:, None] * dirs
    ra = np.column_stack([a @ e1, a @ e2])
    rb = np.column_stack([b @ e1, b @ e2])
    rlo, rhi = np.minimum(ra, rb), np.maximum(ra, rb)
    glo = np.minimum(lo2.min(axis=0), rlo.min(axis=0))
    ghi = np.maximum(hi2.max(axis=0), rhi.max(axis=0))
    g = int(np.clip(np.sqrt(len(tess.triangles) / 2.0), 16, 1024))
    cell = np.maximum((ghi - glo) / g, 1e-12)

    def cells_of(lo, hi, tri=None):
        i0 = np.clip(((lo - glo) / cell).astype(int), 0, g - 1)
        i1 = np.clip(((hi - glo) / cell).astype(int), 0, g - 1)
        nx, ny = i1[:, 0] - i0[:, 0] + 1, i1[:, 1] - i0[:, 1] + 1
        cnt = nx * ny
        owner = np.repeat(np.arange(len(lo)), cnt)
        local = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        cx = i0[owner, 0] + local % nx[owner]
        cy = i0[owner, 1] + local // nx[owner]
        if tri is not None:
            keep = _cells_overlapping(tri[owner], cx, cy, glo, cell)
        else:
            keep = _cells_on_segment(ra[owner], rb[owner], cx, cy, glo, cell)
        owner, cx, cy = owner[keep], cx[keep], cy[keep]
        return owner, cx * g + cy

    tri_owner, tri_cell = cells_of(lo2, hi2, tri2)
    table = _csr(tri_cell, tri_owner, g * g)
    ray_owner, ray_cell = cells_of(rlo, rhi)
    best_t = np.full(n, np.inf)
    best_tri = np.full(n, -1)
    for s in range(0, len(ray_owner), max(1, PAIR_CHUNK // 8)):
        owner = ray_owner[s:s + PAIR_CHUNK // 8]
        q, tri = _pairs(ray_cell[s:s + PAIR_CHUNK // 8], *table)
        r = owner[q]
        for c in range(0, len(r), PAIR_CHUNK):
            rr, tt = r[c:c + PAIR_CHUNK], tri[c:c + PAIR_CHUNK]
            if len(rr) == 0:
                continue
            t = _moller_trumbore(origins[rr], dirs[rr], tess.v0[tt], tess.e1[tt], tess.e2[tt])
            # Pairs come sorted by ray: reduce each ray's run of pairs.
            starts = np.flatnonzero(np.r_[True, rr[1:] != rr[:-1]])
            tmin = np.minimum.reduceat(t, starts)
            at = np.repeat(tmin, np.diff(np.r_[starts, len(rr)]))
            win = np.flatnonzero(np.isfinite(t) & (t == at))
            wr, first = np.unique(rr[win], return_index=True)
            better = t[win[first]] < best_t[wr]
            best_t[wr[better]] = t[win[first]][better]
            best_tri[wr[better]] = tt[win[first]][better]
    return best_t, best_tri


def _direction_groups(dirs):
    """Group label per ray: nearly equal directions together (a scan pass is one group); when
    that makes too many groups (rays in all directions), the six signed dominant axes."""
    keys = np.round(dirs / DIRECTION_BIN).astype(np.int64)
    _, inverse = np.unique(keys, axis=0, return_inverse=True)
    if inverse.max() < MAX_GROUPS:
        return inverse.ravel()
    axis = np.argmax(np.abs(dirs), axis=1)
    return 2 * axis + (dirs[np.arange(len(dirs)), axis] < 0)


def _refine(nominal, f, o, d, t):
    """Newton on S(u,v) = o + t d for rays hitting face f near o + t d."""
    surf = nominal.surfaces[f]
    x = o + t[:, None] * d
    k = min(8, len(nominal.samples.xyz))
    _, idx = nominal._tree.query(x, k=k)
    idx = idx.reshape(len(x), -1)
    on_f = nominal.samples.face[idx] == f
    first = np.argmax(on_f, axis=1)
    start = nominal.samples.uv[idx[np.arange(len(x)), first]]
    missing = np.flatnonzero(~on_f.any(axis=1))
    if len(missing):
        # Nearest sample of this face by brute force: only for the few retried rays.
        mine = np.flatnonzero(nominal.samples.face == f)
        for i in missing:
            j = mine[np.argmin(np.linalg.norm(nominal.samples.xyz[mine] - x[i], axis=1))]
            start[i] = nominal.samples.uv[j]
    u, v = start[:, 0].copy(), start[:, 1].copy()
    converged = np.zeros(len(x), bool)
    (u0, u1), (v0, v1) = surf.u_range, surf.v_range
    active = np.arange(len(x))
    for _ in range(NEWTON_ITERATIONS):
        if len(active) == 0:
            break
        ua, va, ta, oa, da = u[active], v[active], t[active], o[active], d[active]
        S, Su, Sv = bspline.evaluate(surf, ua, va, order=1)
        F = oa + ta[:, None] * da - S
        # Cramer's rule on [Su Sv -d] (du dv dt) = F; a ray parallel to the surface is left.
        bc = np.cross(Sv, -da)
        det = np.einsum("ij,ij->i", Su, bc)
        ok = np.abs(det) > 1e-14 * np.linalg.norm(Su, axis=1) * np.linalg.norm(Sv, axis=1)
        det = np.where(ok, det, 1.0)
        du = np.einsum("ij,ij->i", F, bc) / det
        dv = np.einsum("ij,ij->i", Su, np.cross(F, -da)) / det
        dt = np.einsum("ij,ij->i", Su, np.cross(Sv, F)) / det
        un, vn = ua + du, va + dv
        u[active] = u0 + np.mod(un - u0, u1 - u0) if surf.closed_u else np.clip(un, u0, u1)
        v[active] = v0 + np.mod(vn - v0, v1 - v0) if surf.closed_v else np.clip(vn, v0, v1)
        t[active] = ta + dt
        moved = np.linalg.norm(du[:, None] * Su + dv[:, None] * Sv, axis=1)
        # Newton converges quadratically: once a step is below 1e-8 mm the point it lands on is
        # within ~1e-16 mm, so another evaluation buys nothing (the residual check below stays).
        done = (moved < 1e-8) | ~ok
        converged[active[done & ok]] = True
        active = active[~done]
    S, Su, Sv = bspline.evaluate(surf, u, v, order=1)
    residual = np.linalg.norm(S - (o + t[:, None] * d), axis=1)
    nrm = np.cross(Su, Sv)
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1), 1e-300)[:, None]
    if nominal._reversed[f]:
        nrm = -nrm
    dom = nominal._domains[f]
    inside, bdist = point_in_domain(dom, np.column_stack([u, v]))
    ok = converged & (residual < 1e-9) & inside & (bdist > dom.margin) & (t >= 0)
    return t, nrm, ok


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


def cast(nominal, origins, directions, deflection=None):
    origins = np.asarray(origins, dtype=float).reshape(-1, 3)
    directions = np.asarray(directions, dtype=float).reshape(-1, 3)
    if origins.shape != directions.shape:
        raise InputError("raycast: origins %s and directions %s differ in shape"
                         % (origins.shape, directions.shape))
    n = len(origins)
    length = np.linalg.norm(directions, axis=1)
    if not (np.all(np.isfinite(origins)) and np.all(np.isfinite(directions)) and np.all(length > 0)):
        raise InputError("raycast: origins and directions must be finite, directions non-zero")
    corners = nominal.bbox_corners
    diag = float(np.linalg.norm(corners.max(axis=0) - corners.min(axis=0)))
    if deflection is None:
        deflection = max(diag * 1e-3, 1e-4)
    tess = nominal._tessellation
    if tess is None or tess.deflection != deflection:
        tess = nominal._tessellation = Tessellation(nominal, deflection)
    unit = directions / length[:, None]
    pad = 2 * deflection + 1e-9 * diag
    t0, t1 = _slab(origins, unit, tess.lo - pad, tess.hi + pad)
    t_hit = np.full(n, np.inf)
    tri = np.full(n, -1)
    live = np.flatnonzero(t0 <= t1)
    if len(live):
        groups = _direction_groups(unit[live])
        for g in np.unique(groups):
            sel = live[groups == g]
            t_hit[sel], tri[sel] = _first_hits_group(tess, origins[sel], unit[sel], t0[sel], t1[sel])
    t_out = np.full(n, np.nan)
    face_out = np.full(n, -1)
    normal_out = np.full((n, 3), np.nan)
    hit = np.flatnonzero(tri >= 0)
    faces = tess.face[tri[hit]]
    doubtful = []
    for f in np.unique(faces):
        rows = hit[faces == f]
        t, nrm, ok = _refine(nominal, f, origins[rows], unit[rows], t_hit[rows].copy())
        good = rows[ok]
        t_out[good], face_out[good], normal_out[good] = t[ok], f, nrm[ok]
        doubtful.extend(rows[~ok])
    # A tessellation hit near a face's edge may belong to the face across it: try the other
    # faces near the tessellated hit; the nearest valid exact hit there is the first one when it
    # lies within the tessellation's error of the tessellated hit.
    doubtful = np.array(doubtful, dtype=int)
    if len(doubtful):
        best_t = np.full(len(doubtful), np.inf)
        best_f = np.full(len(doubtful), -1)
        best_n = np.full((len(doubtful), 3), np.nan)
        for f in range(len(nominal.faces)):
            others = np.flatnonzero(tess.face[tri[doubtful]] != f)
            if len(others) == 0:
                continue
            rows = doubtful[others]
            t, nrm, ok = _refine(nominal, f, origins[rows], unit[rows], t_hit[rows].copy())
            ok &= (np.abs(t - t_hit[rows]) < NEIGHBOUR_SLACK * deflection) & (t < best_t[others])
            k = others[ok]
            best_t[k], best_f[k], best_n[k] = t[ok], f, nrm[ok]
        found = np.isfinite(best_t)
        rows = doubtful[found]
        t_out[rows], face_out[rows], normal_out[rows] = best_t[found], best_f[found], best_n[found]
        doubtful = doubtful[~found]
    for i in doubtful:
        t, f, nrm = _occ_ray(nominal, origins[i], unit[i], t1[i] + pad)
        t_out[i], face_out[i], normal_out[i] = t, f, nrm
    return t_out / length, face_out, normal_out
