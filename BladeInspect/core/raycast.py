"""First hit of rays on a FaceSet's faces (core.closest), exact on the B-spline surfaces.

Stage 1 finds the first hit on a fine tessellation (OCC's, ``Face.tessellate``, turned into
arrays by cad.raycast): rays are
grouped by direction; for each group the triangles are projected on the plane normal to the
group's direction and bucketed in a 2D grid, so a ray (a point, or a short segment when the
group's directions differ slightly, in that plane) meets only the triangles of its cells.
The grid of a direction depends only on the tessellation and the direction, so it is kept
(a scan turns the part to the same few rotary angles again and again); a new direction with
few rays buckets only the triangles around them instead. Rays parallel to the
grid's direction are decided in the plane (2D barycentrics, depth interpolated); others by
Möller–Trumbore. Stage 2 moves each hit onto the exact surface of the hit triangle's face by
Newton (Chebyshev) steps on S(u, v) - o - t d = 0 (unknowns u, v, t), started from the hit's
barycentric interpolation of the triangle's vertex parameters, on the surface's polynomial
patches (core.bspline.PowerPatches). A root on the other side from the triangle's (a grazing
ray's far root) restarts at the near root its second-order expansion predicts. A ray whose
refined hit leaves the face's trimmed domain, lands too close to its boundary to tell, or does
not converge is tried on the other faces from the samples near it, then given to an exact
fallback (cad.raycast's: OCC's ``Shape.section`` with the ray as an edge). Both stages run on
chunks of rays in two threads.

Rays that graze a face within the tessellation's deflection of its silhouette may be reported
as misses (or hits) differently from the exact surface: a scanning sensor never measures there.
"""

import threading
from collections import OrderedDict

import numpy as np
from scipy.spatial import cKDTree

from . import background, bspline
from .closest import point_in_domain
from .errors import InputError
from .trim import bucket_pairs, csr

# Directions closer than this (in unit-vector components) share one projection plane.
DIRECTION_BIN = 0.02
# Ray/triangle pairs evaluated per chunk.
PAIR_CHUNK = 400000
# Above this many direction groups, rays are grouped by their dominant axis instead.
MAX_GROUPS = 48
NEWTON_ITERATIONS = 16
# An iterate whose residual |o + t d - S(u, v)| is below this (mm) takes its last step
# without evaluating where it lands: the error it leaves is of order residual^3 x curvature^2
# (~1e-12 mm on the demo blade's hits, against 1e-14 when evaluated once more).
NEWTON_TOLERANCE = 1e-6
# A neighbour face's exact hit replaces a doubtful tessellated one within this many deflections.
NEIGHBOUR_SLACK = 20.0
# Grids kept per tessellation (one per direction, least recently used dropped first).
MAX_CACHED_GRIDS = 16
# Group directions within this of a kept grid's direction (unit-vector components) reuse it.
GRID_DIRECTION_MATCH = 1e-9
# Rays are decided in the grid's plane when their traces across the box drift less than this
# fraction of the deflection from a point: the tessellated hit is only Newton's start.
PLANAR_DRIFT = 1e-3
# A direction cast with fewer rays than this many per triangle gets no kept grid (yet): only
# the triangles around its rays are bucketed (a section pass, one of many planning angles).
FEW_RAYS_PER_TRIANGLE = 0.5
# Rays per chunk of work; chunks run on two threads (numpy releases the GIL in its loops).
RAY_CHUNK = 16384
THREADS = 2


def _cross(a, b):
    """Row-wise cross product (np.cross is several times slower on (N, 3) rows)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def _dot(a, b):
    return np.einsum("ij,ij->i", a, b)


def _along(points, axis):
    """points @ axis without BLAS: its threads would compete with the ray chunks' own."""
    return points[:, 0] * axis[0] + points[:, 1] * axis[1] + points[:, 2] * axis[2]


class Tessellation:
    """The faces' triangles with each vertex's (u, v) on its face's SurfaceData, and the
    per-direction bucket grids built from them."""

    def __init__(self, face_set, meshes, deflection):
        """meshes: per face (face index, vertices (V, 3), triangles (T, 3) vertex indices),
        a tessellation within ``deflection`` (mm) of the face."""
        verts, tris, face, uv = [], [], [], []
        base = 0
        for i, xyz, facets in meshes:
            if len(facets) == 0:
                continue
            verts.append(xyz)
            tris.append(np.asarray(facets, dtype=int) + base)
            face.append(np.full(len(facets), i))
            uv.append(_vertex_parameters(face_set, i, xyz, deflection))
            base += len(xyz)
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
        self.triangle_uv = _unwrap_seams(face_set, self.face, np.concatenate(uv)[self.triangles])
        self.outward = _outward_signs(face_set, self)
        # Newton evaluates each face's surface many times: its polynomial patches once.
        self.patches = [bspline.PowerPatches(surf) for surf in face_set.surfaces]
        self._grids = OrderedDict()
        self._lock = threading.Lock()

    def grid(self, direction, build=True):
        """The bucket grid for rays along ``direction`` (unit), built once per direction
        (None when there is none yet and ``build`` is False)."""
        key = tuple(np.round(direction / GRID_DIRECTION_MATCH).astype(np.int64))
        with self._lock:
            grid = self._grids.get(key)
            if grid is not None:
                self._grids.move_to_end(key)
                return grid
        if not build:
            return None
        grid = _TriangleGrid(self, direction)
        with self._lock:
            self._grids[key] = grid
            while len(self._grids) > MAX_CACHED_GRIDS:
                self._grids.popitem(last=False)
        return grid


def _vertex_parameters(face_set, f, xyz, deflection):
    """(u, v) of tessellation vertices on face f's surface: Newton foot points from the
    nearest sample of the face; NaN where that fails (those triangles start Newton from the
    samples instead)."""
    mine = np.flatnonzero(face_set.samples.face == f)
    if len(mine) == 0:
        return np.full((len(xyz), 2), np.nan)
    _, near = cKDTree(face_set.samples.xyz[mine]).query(xyz)
    start = face_set.samples.uv[mine[near]]
    u, v, foot, converged = bspline.project_points(face_set.surfaces[f], xyz, start[:, 0],
                                                   start[:, 1])
    # Tessellation nodes lie on the surface: a foot point far from its node is a wrong basin.
    good = converged & (np.linalg.norm(foot - xyz, axis=1) < 1e-3 * deflection)
    return np.where(good[:, None], np.column_stack([u, v]), np.nan)


def _unwrap_seams(face_set, tri_face, tri_uv):
    """Triangles across a closed surface's seam get their vertices' parameters on one side of
    it, so interpolating inside the triangle stays near the triangle."""
    out = tri_uv.copy()
    for f, surf in enumerate(face_set.surfaces):
        rows = np.flatnonzero(tri_face == f)
        for axis, closed, rng in ((0, surf.closed_u, surf.u_range),
                                  (1, surf.closed_v, surf.v_range)):
            if not closed or len(rows) == 0:
                continue
            period = rng[1] - rng[0]
            ref = out[rows, 0:1, axis]
            out[rows, :, axis] -= period * np.round((out[rows, :, axis] - ref) / period)
    return out


def _outward_signs(face_set, tess):
    """Per triangle +-1: the sign that turns e1 x e2 outward (the nominal's normal, Su x Sv
    flipped on reversed faces). A face's triangles share their winding: the majority of
    triangles compared with the surface at their centroids decides it."""
    winding = _cross(tess.e1, tess.e2)
    out = np.ones(len(tess.triangles))
    for f, surf in enumerate(face_set.surfaces):
        rows = np.flatnonzero(tess.face == f)
        uv = tess.triangle_uv[rows].mean(axis=1)
        valid = np.flatnonzero(np.all(np.isfinite(uv), axis=1))
        if len(valid) == 0:
            continue
        _, Su, Sv = bspline.evaluate(surf, uv[valid, 0], uv[valid, 1], order=1)
        agree = np.sum(np.sign(_dot(_cross(Su, Sv), winding[rows[valid]])))
        sign = (1.0 if agree >= 0 else -1.0) * (-1.0 if face_set.reversed[f] else 1.0)
        out[rows] = sign
    return out


def _plane_maps(tri2, depth):
    """Per triangle (projected corners (K, 3, 2), depths along the direction (K, 3)): the map
    from a projected point to its barycentrics and depth, (x0, y0, the inverse of [a b]
    row-major, z0, z1 - z0, z2 - z0)."""
    a = tri2[:, 1] - tri2[:, 0]
    b = tri2[:, 2] - tri2[:, 0]
    det = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    # Edge-on triangles are met by parallel rays only along a line: their neighbours decide.
    # NaN barycentrics never pass the inside test.
    seen = np.abs(det) > 1e-12 * (np.einsum("ij,ij->i", a, a) + np.einsum("ij,ij->i", b, b))
    det = np.where(seen, det, np.nan)
    return np.column_stack([
        tri2[:, 0], b[:, 1] / det, -b[:, 0] / det, -a[:, 1] / det, a[:, 0] / det,
        depth[:, 0], depth[:, 1] - depth[:, 0], depth[:, 2] - depth[:, 0]])


def _grid_size(n_triangles):
    return int(np.clip(np.sqrt(n_triangles / 2.0), 16, 1024))


class _RayGrid:
    """For a few rays along one direction (a section pass, a planning cast at a new angle):
    the triangles whose projected boxes cover a cell holding one of the rays, bucketed in
    those cells only. Costs a projection of the vertices instead of the whole grid of
    _TriangleGrid, and is not kept. Cells as the whole grid's; rays parallel to
    ``direction`` only."""

    def __init__(self, tess, direction, origins):
        self.direction = direction
        self.e1, self.e2 = _basis(direction)
        V = tess.vertices
        tri2 = np.column_stack([_along(V, self.e1), _along(V, self.e2)])[tess.triangles]
        lo2, hi2 = tri2.min(axis=1), tri2.max(axis=1)
        self.glo = lo2.min(axis=0)
        self.ghi = hi2.max(axis=0)
        g = self.g = _grid_size(len(tess.triangles))
        self.cell = np.maximum((self.ghi - self.glo) / g, 1e-12)
        xy = np.column_stack([_along(origins, self.e1), _along(origins, self.e2)])
        inside = np.all((xy >= self.glo) & (xy <= self.ghi), axis=1)
        ij = np.clip(np.floor((xy[inside] - self.glo) / self.cell).astype(int), 0, g - 1)
        held = np.zeros((g, g), bool)
        held[ij[:, 0], ij[:, 1]] = True
        # Rays in a triangle's box: a summed-area table counts the held cells of each box.
        area = np.zeros((g + 1, g + 1), dtype=np.int64)
        area[1:, 1:] = np.cumsum(np.cumsum(held, axis=0), axis=1)
        i0 = np.clip(((lo2 - self.glo) / self.cell).astype(int), 0, g - 1)
        i1 = np.clip(((hi2 - self.glo) / self.cell).astype(int), 0, g - 1) + 1
        count = (area[i1[:, 0], i1[:, 1]] - area[i0[:, 0], i1[:, 1]]
                 - area[i1[:, 0], i0[:, 1]] + area[i0[:, 0], i0[:, 1]])
        cand = np.flatnonzero(count > 0)
        i0, i1 = i0[cand], i1[cand]
        nx, ny = i1[:, 0] - i0[:, 0], i1[:, 1] - i0[:, 1]
        cnt = nx * ny
        owner = np.repeat(np.arange(len(cand)), cnt)
        local = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        cx = i0[owner, 0] + local % nx[owner]
        cy = i0[owner, 1] + local // nx[owner]
        keep = held[cx, cy]
        self.table = csr(cx[keep] * g + cy[keep], owner[keep], g * g)
        self.triangle_id = cand
        depth = _along(V, direction)[tess.triangles[cand]]
        self.plane_map = _plane_maps(tri2[cand], depth)


class _TriangleGrid:
    """Triangles projected on the plane normal to ``direction``, bucketed in a uniform grid;
    per triangle the plane map from a projected point to its barycentrics and depth."""

    def __init__(self, tess, direction):
        self.direction = direction
        self.e1, self.e2 = _basis(direction)
        V = tess.vertices
        P = np.column_stack([_along(V, self.e1), _along(V, self.e2)])
        depth = _along(V, direction)
        tri2 = P[tess.triangles]                         # (T, 3, 2)
        self.plane_map = _plane_maps(tri2, depth[tess.triangles])
        self.triangle_id = None
        lo2, hi2 = tri2.min(axis=1), tri2.max(axis=1)
        self.glo = lo2.min(axis=0)
        self.ghi = hi2.max(axis=0)
        self.g = _grid_size(len(tess.triangles))
        self.cell = np.maximum((self.ghi - self.glo) / self.g, 1e-12)
        owner, cells = self.cells_of(lo2, hi2, tri2)
        self.table = csr(cells, owner, self.g * self.g)

    def segment_cells(self, a, b):
        """(owner, flat cell) of the cells each segment a-b (in the plane) crosses, sorted by
        owner: column by column, the rows between the segment's heights at the column's
        sides (widened by a hair so a segment along a cell border gets both cells)."""
        g = self.g
        A = (a - self.glo) / self.cell
        B = (b - self.glo) / self.cell
        swap = A[:, 0] > B[:, 0]
        A, B = np.where(swap[:, None], B, A), np.where(swap[:, None], A, B)
        c0 = np.clip(np.floor(A[:, 0]).astype(int), 0, g - 1)
        c1 = np.clip(np.floor(B[:, 0]).astype(int), 0, g - 1)
        ncol = c1 - c0 + 1
        owner = np.repeat(np.arange(len(A)), ncol)
        col = c0[owner] + np.arange(len(owner)) - np.repeat(np.cumsum(ncol) - ncol, ncol)
        ax, ay, bx, by = A[owner, 0], A[owner, 1], B[owner, 0], B[owner, 1]
        x_in = np.maximum(col, ax)
        x_out = np.minimum(col + 1.0, bx)
        dx = bx - ax
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = np.where(dx > 0, (by - ay) / dx, 0.0)
        y_in = np.where(dx > 0, ay + slope * (x_in - ax), ay)
        y_out = np.where(dx > 0, ay + slope * (x_out - ax), by)
        hair = 1e-9
        r0 = np.clip(np.floor(np.minimum(y_in, y_out) - hair).astype(int), 0, g - 1)
        r1 = np.clip(np.floor(np.maximum(y_in, y_out) + hair).astype(int), 0, g - 1)
        # a column the segment's rows miss entirely (it runs beyond the grid) gives none
        nrow = np.where((np.maximum(y_in, y_out) + hair >= 0)
                        & (np.minimum(y_in, y_out) - hair < g), r1 - r0 + 1, 0)
        which = np.repeat(np.arange(len(owner)), nrow)
        row = r0[which] + np.arange(len(which)) - np.repeat(np.cumsum(nrow) - nrow, nrow)
        return owner[which], col[which] * g + row

    def cells_of(self, lo, hi, tri):
        """(owner, flat cell) of every grid cell each box overlaps, kept only where the
        triangle ``tri`` really overlaps the cell."""
        g, glo, cell = self.g, self.glo, self.cell
        i0 = np.clip(((lo - glo) / cell).astype(int), 0, g - 1)
        i1 = np.clip(((hi - glo) / cell).astype(int), 0, g - 1)
        nx, ny = i1[:, 0] - i0[:, 0] + 1, i1[:, 1] - i0[:, 1] + 1
        cnt = nx * ny
        owner = np.repeat(np.arange(len(lo)), cnt)
        local = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        cx = i0[owner, 0] + local % nx[owner]
        cy = i0[owner, 1] + local // nx[owner]
        # A convex shape spanning a box one cell wide crosses every cell of it: only boxes
        # of two cells or more each way need the test.
        test = np.flatnonzero(((nx > 1) & (ny > 1))[owner])
        keep = _cells_overlapping(tri[owner[test]], cx[test], cy[test], glo, cell)
        drop = np.zeros(len(owner), bool)
        drop[test[~keep]] = True
        return owner[~drop], cx[~drop] * g + cy[~drop]


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


# Barycentric slack that closes cracks between neighbouring triangles.
BARY_EPS = 1e-10


def _moller_trumbore(o, d, v0, e1, e2):
    """(t, bu, bv) of each ray/triangle pair (t inf where no hit at t >= 0)."""
    p = _cross(d, e2)
    det = _dot(e1, p)
    ok = np.abs(det) > 1e-300
    inv = 1.0 / np.where(ok, det, 1.0)
    s = o - v0
    bu = _dot(s, p) * inv
    q = _cross(s, e1)
    bv = _dot(d, q) * inv
    t = _dot(e2, q) * inv
    hit = ok & (bu >= -BARY_EPS) & (bv >= -BARY_EPS) & (bu + bv <= 1 + BARY_EPS) & (t >= 0)
    return np.where(hit, t, np.inf), bu, bv


def _planar_test(xy, axial, m):
    """(t, bu, bv) of rays along the grid's direction through projected points ``xy`` whose
    origins lie at ``axial`` along it, against triangles of plane maps ``m`` (pairs)."""
    x = xy[:, 0] - m[:, 0]
    y = xy[:, 1] - m[:, 1]
    bu = m[:, 2] * x + m[:, 3] * y
    bv = m[:, 4] * x + m[:, 5] * y
    t = m[:, 6] + bu * m[:, 7] + bv * m[:, 8] - axial
    hit = (bu >= -BARY_EPS) & (bv >= -BARY_EPS) & (bu + bv <= 1 + BARY_EPS) & (t >= 0)
    return np.where(hit, t, np.inf), bu, bv


def _nearest_per_ray(rr, t):
    """Among pairs sorted by ray, each ray's nearest finite hit -> (ray, pair index)."""
    hits = np.flatnonzero(np.isfinite(t))
    if len(hits) == 0:
        return hits, hits
    rh, th = rr[hits], t[hits]
    starts = np.flatnonzero(np.r_[True, rh[1:] != rh[:-1]])
    tmin = np.minimum.reduceat(th, starts)
    at_min = np.flatnonzero(th == np.repeat(tmin, np.diff(np.r_[starts, len(rh)])))
    first = np.r_[True, rh[at_min[1:]] != rh[at_min[:-1]]]
    win = hits[at_min[first]]
    return rr[win], win


def _first_hits_group(tess, grid, origins, dirs, t0, t1, planar):
    """Tessellation first hit (t, triangle, bu, bv) for rays of nearly the grid's direction."""
    n = len(origins)
    best_t = np.full(n, np.inf)
    best_tri = np.full(n, -1)
    best_b = np.zeros((n, 2))
    e1, e2 = grid.e1, grid.e2
    if planar:
        xy = np.column_stack([_along(origins, e1), _along(origins, e2)])
        axial = _along(origins, grid.direction)
        inside = np.all((xy >= grid.glo) & (xy <= grid.ghi), axis=1)
        ij = np.clip(np.floor((xy - grid.glo) / grid.cell).astype(int), 0, grid.g - 1)
        ray_owner = np.flatnonzero(inside)
        ray_cell = ij[inside, 0] * grid.g + ij[inside, 1]
    else:
        # The ray's trace on the plane runs from its entry to its exit point of the box.
        a = origins + t0[:, None] * dirs
        b = origins + t1[:, None] * dirs
        ra = np.column_stack([_along(a, e1), _along(a, e2)])
        rb = np.column_stack([_along(b, e1), _along(b, e2)])
        rlo, rhi = np.minimum(ra, rb), np.maximum(ra, rb)
        meets = np.flatnonzero(np.all((rhi >= grid.glo) & (rlo <= grid.ghi), axis=1))
        ray_owner, ray_cell = grid.segment_cells(ra[meets], rb[meets])
        ray_owner = meets[ray_owner]
    step = max(1, PAIR_CHUNK // 8)
    for s in range(0, len(ray_owner), step):
        owner = ray_owner[s:s + step]
        q, tri = bucket_pairs(ray_cell[s:s + step], *grid.table)
        r = owner[q]
        for c in range(0, len(r), PAIR_CHUNK):
            rr, tt = r[c:c + PAIR_CHUNK], tri[c:c + PAIR_CHUNK]
            if len(rr) == 0:
                continue
            if planar:
                t, bu, bv = _planar_test(xy[rr], axial[rr], grid.plane_map[tt])
            else:
                t, bu, bv = _moller_trumbore(origins[rr], dirs[rr], tess.v0[tt], tess.e1[tt],
                                             tess.e2[tt])
            wr, win = _nearest_per_ray(rr, t)
            better = t[win] < best_t[wr]
            wr, win = wr[better], win[better]
            best_t[wr] = t[win]
            best_tri[wr] = tt[win] if grid.triangle_id is None else grid.triangle_id[tt[win]]
            best_b[wr] = np.column_stack([bu[win], bv[win]])
    return best_t, best_tri, best_b


def _direction_groups(dirs):
    """Group label per ray: nearly equal directions together (a scan pass is one group); when
    that makes too many groups (rays in all directions), the six signed dominant axes."""
    if np.all(dirs == dirs[0]):
        return np.zeros(len(dirs), dtype=np.int64)
    keys = np.round(dirs / DIRECTION_BIN).astype(np.int64)
    # |key| <= 1 / DIRECTION_BIN: one integer per key, so grouping is a 1D unique.
    base = 2 * int(np.ceil(1.0 / DIRECTION_BIN)) + 3
    flat = (keys[:, 0] * base + keys[:, 1]) * base + keys[:, 2]
    _, inverse = np.unique(flat, return_inverse=True)
    if inverse.max() < MAX_GROUPS:
        return inverse.ravel()
    axis = np.argmax(np.abs(dirs), axis=1)
    return 2 * axis + (dirs[np.arange(len(dirs)), axis] < 0)


def _refine(face_set, tess, f, o, d, t, start, enters):
    """Newton on S(u,v) = o + t d for rays hitting face f near o + t d, from (u, v) ``start``
    -> (t, outward normal, ok, jump). ``enters``: whether the tessellated hit had the ray
    entering the material (the exact hit must agree). ``jump`` (N, 3): for rays whose Newton
    found the root on the wrong side (a grazing ray's far root), a start (t, u, v) near the
    root before it; NaN for the others.

    Each step is Chebyshev's: the Newton step, then solved again with the surface's quadratic
    term along it, so the residual falls cubically (two evaluations from a tessellated start
    on the demo blade instead of three)."""
    surf = face_set.surfaces[f]
    sign = -1.0 if face_set.reversed[f] else 1.0
    n = len(o)
    (u0, u1), (v0, v1) = surf.u_range, surf.v_range
    u = u0 + np.mod(start[:, 0] - u0, u1 - u0) if surf.closed_u else np.clip(start[:, 0], u0, u1)
    v = v0 + np.mod(start[:, 1] - v0, v1 - v0) if surf.closed_v else np.clip(start[:, 1], v0, v1)
    nrm = np.full((n, 3), np.nan)
    converged = np.zeros(n, bool)
    jump = np.full((n, 3), np.nan)
    active = np.arange(n)
    for _ in range(NEWTON_ITERATIONS):
        if len(active) == 0:
            break
        ua, va, ta, oa, da = u[active], v[active], t[active], o[active], d[active]
        S, Su, Sv, Suu, Suv, Svv = tess.patches[f].evaluate(ua, va)
        F = oa + ta[:, None] * da - S
        # [Su Sv -d] (du dv dt) = R by Cramer's rule: the three cofactor rows.
        cu, cv, ct = _cross(Sv, -da), _cross(-da, Su), _cross(Su, Sv)
        det = _dot(Su, cu)
        area = np.linalg.norm(ct, axis=1)
        # a ray parallel to the surface is left
        ok = np.abs(det) > 1e-14 * area
        inv = 1.0 / np.where(ok, det, 1.0)
        du, dv = _dot(F, cu) * inv, _dot(F, cv) * inv
        Q = 0.5 * (Suu * (du * du)[:, None] + 2.0 * Suv * (du * dv)[:, None]
                   + Svv * (dv * dv)[:, None])
        R = F - Q
        # Far from the root the quadratic term is no correction: plain Newton there.
        R = np.where((_dot(Q, Q) < 0.25 * _dot(F, F))[:, None], R, F)
        du, dv, dt = _dot(R, cu) * inv, _dot(R, cv) * inv, _dot(R, ct) * inv
        un, vn = ua + du, va + dv
        u[active] = u0 + np.mod(un - u0, u1 - u0) if surf.closed_u else np.clip(un, u0, u1)
        v[active] = v0 + np.mod(vn - v0, v1 - v0) if surf.closed_v else np.clip(vn, v0, v1)
        t[active] = ta + dt
        # From a residual this small the step just taken lands within ~residual^2 x curvature
        # of the surface, so it needs no evaluation of its own; the normal is carried along it
        # to first order. A step the parameter box cut short is evaluated again unless what
        # was cut is as small.
        cut = np.zeros(len(active))
        if not surf.closed_u:
            cut += np.abs(un - u[active]) * np.linalg.norm(Su, axis=1)
        if not surf.closed_v:
            cut += np.abs(vn - v[active]) * np.linalg.norm(Sv, axis=1)
        # An iterate the box holds where it was will not move again: the root is off the face.
        stuck = (cut >= NEWTON_TOLERANCE) & (u[active] == ua) & (v[active] == va)
        landed = (_dot(F, F) < NEWTON_TOLERANCE ** 2) & (cut < NEWTON_TOLERANCE) & ok
        done = landed | ~ok | stuck
        g = np.flatnonzero(landed)
        dug, dvg = du[g, None], dv[g, None]
        normal = _cross(Su[g] + Suu[g] * dug + Suv[g] * dvg, Sv[g] + Suv[g] * dug + Svv[g] * dvg)
        outward = normal * (sign / np.maximum(np.linalg.norm(normal, axis=1), 1e-300))[:, None]
        # A root on the other side from the tessellated hit's (the ray leaving where the
        # triangle had it entering) is the second root of a grazing ray: the first hit may be
        # just before it.
        same_side = (_dot(da[g], outward) < 0) == enters[active[g]]
        converged[active[g[same_side]]] = True
        nrm[active[g]] = outward
        w = g[~same_side]
        if len(w):
            jump[active[w]] = _other_root(t[active[w]], u[active[w]], v[active[w]], da[w],
                                          outward[~same_side], Su[w], Sv[w], Suu[w], Suv[w],
                                          Svv[w])
        active = active[~done]
    dom = face_set.domains[f]
    inside, bdist = point_in_domain(dom, np.column_stack([u, v]))
    ok = converged & inside & (bdist > dom.margin) & (t >= 0)
    return t, nrm, ok, jump


def _other_root(t, u, v, d, nrm, Su, Sv, Suu, Suv, Svv):
    """Where the ray's other root lies, from the surface's second-order expansion at the root
    found: along the ray the height above the surface is h(s) = c s - II(w) s^2 / 2 (c = d.n,
    w = d's tangential part, II the second fundamental form), so the other root is
    s = 2c / II(w) away. -> (N, 3) starts (t, u, v); NaN unless that root comes first."""
    c = _dot(d, nrm)
    w = d - c[:, None] * nrm
    E, F, G = _dot(Su, Su), _dot(Su, Sv), _dot(Sv, Sv)
    wu, wv = _dot(Su, w), _dot(Sv, w)
    det = E * G - F * F
    a = (G * wu - F * wv) / det
    b = (E * wv - F * wu) / det
    second = _dot(Suu * (a * a)[:, None] + 2.0 * Suv * (a * b)[:, None]
                  + Svv * (b * b)[:, None], nrm)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = 2.0 * c / second
    s = np.where(np.isfinite(s) & (s < 0), s, np.nan)
    return np.column_stack([t + s, u + s * a, v + s * b])


def _enters(tess, tri, d):
    """Whether rays along d meet these triangles from outside the material."""
    return _dot(d, _cross(tess.e1[tri], tess.e2[tri])) * tess.outward[tri] < 0


def _exact_hits(face_set, tess, origins, unit, t_hit, tri, bary):
    """Stage 2 on rays with a tessellated hit: (t, face, normal) where Newton on the hit
    triangle's face decided, and the rows it could not decide."""
    n = len(origins)
    t_out = np.full(n, np.nan)
    face_out = np.full(n, -1)
    normal_out = np.full((n, 3), np.nan)
    hit = np.flatnonzero(tri >= 0)
    th = tri[hit]
    w = np.column_stack([1.0 - bary[hit, 0] - bary[hit, 1], bary[hit]])
    start = np.einsum("ij,ijk->ik", w, tess.triangle_uv[th])
    faces = tess.face[th]
    doubtful = []
    for f in np.unique(faces):
        sel = np.flatnonzero(faces == f)
        rows = hit[sel]
        uv = start[sel]
        lost = np.flatnonzero(np.isnan(uv[:, 0]) | np.isnan(uv[:, 1]))
        if len(lost):
            uv[lost] = face_set.starts_on_face(f, origins[rows[lost]]
                                      + t_hit[rows[lost], None] * unit[rows[lost]])
        enters = _enters(tess, th[sel], unit[rows])
        t, nrm, ok, jump = _refine(face_set, tess, f, origins[rows], unit[rows],
                                   t_hit[rows].copy(), uv, enters)
        # A grazing ray whose Newton found the far root: once more from the near one.
        again = np.flatnonzero(~ok & np.isfinite(jump[:, 0]))
        if len(again):
            r = rows[again]
            t2, n2, ok2, _ = _refine(face_set, tess, f, origins[r], unit[r], jump[again, 0].copy(),
                                     jump[again, 1:], enters[again])
            ok2 &= t2 < t[again]
            k = again[ok2]
            t[k], nrm[k], ok[k] = t2[ok2], n2[ok2], True
        good = rows[ok]
        t_out[good], face_out[good], normal_out[good] = t[ok], f, nrm[ok]
        doubtful.append(rows[~ok])
    doubtful = np.concatenate(doubtful) if doubtful else np.zeros(0, int)
    return t_out, face_out, normal_out, doubtful


def _chunks(n):
    return [slice(s, min(n, s + RAY_CHUNK)) for s in range(0, n, RAY_CHUNK)]


def _run(work, items):
    if len(items) > 1 and THREADS > 1:
        # Waiting, this thread lets a GUI's event loop turn (core.background).
        return background.pool_map(work, items, THREADS)
    return [work(x) for x in items]


def check_rays(origins, directions):
    """(origins (N, 3), directions (N, 3), |directions| (N,)) as float arrays, or InputError."""
    origins = np.asarray(origins, dtype=float).reshape(-1, 3)
    directions = np.asarray(directions, dtype=float).reshape(-1, 3)
    if origins.shape != directions.shape:
        raise InputError("raycast: origins %s and directions %s differ in shape"
                         % (origins.shape, directions.shape))
    length = np.linalg.norm(directions, axis=1)
    if not (np.all(np.isfinite(origins)) and np.all(np.isfinite(directions)) and np.all(length > 0)):
        raise InputError("raycast: origins and directions must be finite, directions non-zero")
    return origins, directions, length


def default_deflection(corners):
    """The tessellation's chord deflection for a part of these bounding-box corners (mm)."""
    diag = float(np.linalg.norm(corners.max(axis=0) - corners.min(axis=0)))
    return max(diag * 1e-3, 1e-4)


def cast(face_set, tess, corners, origins, directions, exact_ray):
    """First hit of each ray o + t d (t >= 0) on the faces of ``face_set`` tessellated by
    ``tess`` -> (t (N,) NaN on a miss, face (N,) -1 on a miss, outward normal (N, 3)); t in
    units of |d|. ``corners``: the part's bounding-box corners; ``exact_ray(o, unit d, t_far)``
    -> (t, face, normal) decides, one at a time, the rays this cannot."""
    origins, directions, length = check_rays(origins, directions)
    n = len(origins)
    diag = float(np.linalg.norm(corners.max(axis=0) - corners.min(axis=0)))
    deflection = tess.deflection
    unit = directions / length[:, None]
    pad = 2 * deflection + 1e-9 * diag
    t0, t1 = _slab(origins, unit, tess.lo - pad, tess.hi + pad)
    t_out = np.full(n, np.nan)
    face_out = np.full(n, -1)
    normal_out = np.full((n, 3), np.nan)
    doubtful, tri_all, t_all = [], np.full(n, -1), np.full(n, np.inf)
    live = np.flatnonzero(t0 <= t1)
    if len(live) == 0:
        return t_out, face_out, normal_out
    groups = _direction_groups(unit[live])
    jobs = []
    for g in np.unique(groups):
        sel = live[groups == g]
        d0 = unit[sel].mean(axis=0)
        d0 /= np.linalg.norm(d0)
        grid = tess.grid(d0, build=False)
        # How far a ray's trace strays from a point in the grid's plane across the box.
        drift = np.max(np.linalg.norm(unit[sel] - (d0 if grid is None else grid.direction),
                                      axis=1) * (t1[sel] - t0[sel]))
        planar = drift <= PLANAR_DRIFT * deflection
        if grid is None:
            few = len(sel) < FEW_RAYS_PER_TRIANGLE * len(tess.triangles)
            grid = _RayGrid(tess, d0, origins[sel]) if planar and few else tess.grid(d0)
        jobs += [(grid, sel[c], planar) for c in _chunks(len(sel))]

    def work(job):
        grid, rows, planar = job
        t_hit, tri, bary = _first_hits_group(tess, grid, origins[rows], unit[rows], t0[rows],
                                             t1[rows], planar)
        return rows, t_hit, tri, _exact_hits(face_set, tess, origins[rows], unit[rows], t_hit,
                                             tri, bary)

    for rows, t_hit, tri, (t, f, nrm, bad) in _run(work, jobs):
        t_out[rows], face_out[rows], normal_out[rows] = t, f, nrm
        tri_all[rows], t_all[rows] = tri, t_hit
        doubtful.append(rows[bad])
    doubtful = np.concatenate(doubtful)
    # A tessellation hit near a face's edge may belong to the face across it: try the other
    # faces near the tessellated hit; the nearest valid exact hit there is the first one when it
    # lies within the tessellation's error of the tessellated hit.
    if len(doubtful):
        best_t = np.full(len(doubtful), np.inf)
        best_f = np.full(len(doubtful), -1)
        best_n = np.full((len(doubtful), 3), np.nan)
        for f in range(len(face_set.surfaces)):
            others = np.flatnonzero(tess.face[tri_all[doubtful]] != f)
            if len(others) == 0:
                continue
            rows = doubtful[others]
            x = origins[rows] + t_all[rows, None] * unit[rows]
            t, nrm, ok, _ = _refine(face_set, tess, f, origins[rows], unit[rows],
                                    t_all[rows].copy(), face_set.starts_on_face(f, x),
                                    _enters(tess, tri_all[rows], unit[rows]))
            ok &= (np.abs(t - t_all[rows]) < NEIGHBOUR_SLACK * deflection) & (t < best_t[others])
            k = others[ok]
            best_t[k], best_f[k], best_n[k] = t[ok], f, nrm[ok]
        found = np.isfinite(best_t)
        rows = doubtful[found]
        t_out[rows], face_out[rows], normal_out[rows] = best_t[found], best_f[found], best_n[found]
        doubtful = doubtful[~found]
    for i in doubtful:
        t, f, nrm = exact_ray(origins[i], unit[i], t1[i] + pad)
        t_out[i], face_out[i], normal_out[i] = t, f, nrm
    return t_out / length, face_out, normal_out
