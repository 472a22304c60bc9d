"""The exact signed point-to-CAD distance on arrays: every face an exact (rational) B-spline
(core.bspline.SurfaceData) with its trimmed domain (core.trim) and outward side, dense samples on
the faces and a k-d tree over them. No FreeCAD: cad.nominal turns OCC faces into a FaceSet and
asks OpenCASCADE only for the points the fast path here leaves undecided.

Fast path: the k-d tree gives, for each point, the nearby faces and a start (u, v) on each;
Newton on every candidate face (vectorised per face), the smallest distance wins. A candidate is
only trusted when Newton converged to a point inside the face's trimmed domain, away from its
boundary; a point whose winner lies on a face edge (clamped at the parameter box) without one
partner face across it, or that a doubtful candidate might beat, is left undecided.
"""

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Optional

import numpy as np
from scipy.spatial import cKDTree

from . import bspline
from .trim import TrimDomain

# Number of nearest samples whose faces become Newton candidates for a point.
K_CANDIDATES = 8
# Relative cosine above which the gradient at a bound means "the minimum lies outside".
CLAMP_COSINE = 1e-7
# Newton results farther than this from the nearest sample's distance are distrusted (mm).
SAMPLE_SLACK = 1e-9
# Points per chunk (bounds the (chunk, K) candidate arrays).
POINT_CHUNK = 32768
# Threads for the fast path.
THREADS = 2
# Nearest samples searched for a Newton start on one given face.
START_CANDIDATES = 8


@dataclass
class Samples:
    xyz: np.ndarray        # (M, 3) points on the faces, inside their trimmed domains
    normal: np.ndarray     # (M, 3) outward unit normals
    face: np.ndarray       # (M,) face index
    uv: np.ndarray         # (M, 2) parameters on that face's SurfaceData
    weight: np.ndarray     # (M,) area each sample stands for (mm^2)


@dataclass
class DistanceResult:
    closest: np.ndarray    # (N, 3) closest points on the CAD
    face: np.ndarray       # (N,) index into Nominal.faces
    uv: np.ndarray         # (N, 2) parameters of the closest point on that face's SurfaceData
    normal: np.ndarray     # (N, 3) outward unit normal there (at an edge: the direction p - c, signed)
    distance: np.ndarray   # (N,) signed distance, + outside material / on the normal's side
    fallback: Optional[np.ndarray] = None   # (N,) True where OCC decided

    @property
    def fallback_fraction(self):
        if self.fallback is None or len(self.fallback) == 0:
            return 0.0
        return float(np.count_nonzero(self.fallback)) / len(self.fallback)


@dataclass
class FaceDomain:
    """A face's trimmed domain in its SurfaceData's (u, v)."""
    index: Optional[TrimDomain]      # the discretised boundary, or None for the whole box
    margin: float                    # uv distance to the boundary below which we do not decide
    planar_scale: Optional[float]    # length per parameter unit when the face is a plane


def point_in_domain(domain, uv):
    """(inside (N,) bool, boundary distance (N,) in uv, exact below domain.index.reach and
    capped there) of parameter pairs against a face's domain."""
    n = len(uv)
    if domain.index is None:
        return np.ones(n, bool), np.full(n, np.inf)
    return domain.index.query(uv)


class FaceSet:
    """The CAD's faces as arrays: per face its SurfaceData, FaceDomain and whether its outward
    side is -(Su x Sv); the samples on all faces and a k-d tree over their points."""

    def __init__(self, surfaces, domains, reversed_, samples):
        self.surfaces = surfaces
        self.domains = domains
        self.reversed = np.asarray(reversed_, bool)
        self.samples = samples
        self.tree = cKDTree(samples.xyz)

    def nearest_sample(self, points):
        """Index of each point's nearest sample."""
        return self.tree.query(points)[1]

    def closest(self, points):
        """The fast path on (N, 3) points -> (DistanceResult with the decided rows filled and
        ``fallback`` False there, the undecided rows (M,) for an exact solver to fill)."""
        n = len(points)
        out = DistanceResult(np.empty((n, 3)), np.empty(n, int), np.empty((n, 2)),
                             np.empty((n, 3)), np.empty(n), np.zeros(n, bool))
        starts = range(0, n, POINT_CHUNK)
        work = lambda s: self.closest_chunk(points[s:s + POINT_CHUNK], out, s)
        # numpy releases the GIL in its array loops: chunks on two threads use both cores.
        if len(starts) > 1:
            with ThreadPoolExecutor(max_workers=THREADS) as pool:
                hard = list(pool.map(work, starts))
        else:
            hard = [work(s) for s in starts]
        return out, (np.concatenate(hard) if hard else np.zeros(0, int))

    def closest_chunk(self, points, out, offset):
        """The fast path on one chunk of points: fills ``out``'s rows offset + i it decides
        and returns the rows (offset + i) it leaves to the exact fallback."""
        n = len(points)
        k = min(K_CANDIDATES, len(self.samples.xyz))
        sample_dist, idx = self.tree.query(points, k=k)
        if k == 1:
            sample_dist, idx = sample_dist[:, None], idx[:, None]
        faces = self.samples.face[idx]
        # First occurrence of each face in a point's k nearest samples (nearest sample first).
        first = np.ones_like(faces, dtype=bool)
        for j in range(1, k):
            first[:, j] = np.all(faces[:, j:j + 1] != faces[:, :j], axis=1)
        pi, cj = np.nonzero(first)
        pf = faces[pi, cj]
        start = self.samples.uv[idx[pi, cj]]
        m = len(pi)
        dist = np.full(m, np.inf)
        lower = np.full(m, np.inf)       # a lower bound of the candidate's true face distance
        trusted = np.zeros(m, bool)
        on_edge = np.zeros(m, bool)
        converged_pair = np.zeros(m, bool)
        closest = np.empty((m, 3))
        uv = np.empty((m, 2))
        normal = np.empty((m, 3))
        for f in np.unique(pf):
            sel = np.flatnonzero(pf == f)
            surf = self.surfaces[f]
            p = points[pi[sel]]
            u, v, S, Su, Sv, conv = bspline.project(surf, p, start[sel, 0], start[sel, 1])
            r = S - p
            d = np.linalg.norm(r, axis=1)
            clamped = self.clamped(surf, u, v, r, Su, Sv, d)
            nrm = np.cross(Su, Sv)
            nlen = np.linalg.norm(nrm, axis=1)
            degenerate = nlen <= 1e-12 * np.linalg.norm(Su, axis=1) * np.linalg.norm(Sv, axis=1) + 1e-300
            nrm /= np.where(nlen > 0, nlen, 1.0)[:, None]
            if self.reversed[f]:
                nrm = -nrm
            inside, bdist = point_in_domain(self.domains[f], np.column_stack([u, v]))
            decided = bdist > self.domains[f].margin
            ok = conv & inside & decided & ~degenerate
            dist[sel], closest[sel], uv[sel, 0], uv[sel, 1], normal[sel] = d, S, u, v, nrm
            trusted[sel] = ok
            on_edge[sel] = clamped
            converged_pair[sel] = conv
            low = np.where(conv, d, 0.0)
            dom = self.domains[f]
            if dom.planar_scale is not None:
                # On a plane the trimmed face is at least as far as the in-plane gap to its
                # boundary, beside the height above the plane.
                gap = np.where(inside, 0.0, np.maximum(bdist - dom.margin, 0.0)) * dom.planar_scale
                low = np.where(conv, np.hypot(d, gap), 0.0)
            lower[sel] = low
        # Per point: the best trusted candidate; doubtful candidates must not be able to beat it.
        best_d = np.full(n, np.inf)
        np.minimum.at(best_d, pi[trusted], dist[trusted])
        is_best = trusted & (dist == best_d[pi])
        best = np.full(n, -1)
        best[pi[is_best]] = np.flatnonzero(is_best)
        has_best = best >= 0
        bp = np.where(has_best[pi], best[pi], 0)
        # On an edge: the face across it reaches the same closest point (clamped there too, or,
        # for a plane trimmed by that edge, the point lies in its plane). Such a partner is no
        # threat, and the two outward normals together give the sign (their sum is the edge's
        # pseudo-normal, which is right for any point whose closest point is on the edge).
        planar = np.array([d.planar_scale is not None for d in self.domains])[pf]
        partner = (has_best[pi] & on_edge[bp] & (np.arange(m) != bp) & converged_pair
                   & ((on_edge & (np.linalg.norm(closest - closest[bp], axis=1) < 1e-7))
                      | (planar & (np.abs(np.einsum("ij,ij->i", closest[bp] - closest, normal))
                                   < 1e-9))))
        threat = ~trusted & ~partner & (lower < best_d[pi] - 1e-12)
        need = np.zeros(n, bool)
        need[pi[threat]] = True
        need |= ~has_best
        n_partner = np.bincount(pi[partner], minlength=n)
        partner_normal = np.zeros((n, 3))
        np.add.at(partner_normal, pi[partner], normal[partner])
        good = ~need
        edge = np.zeros(n, bool)
        edge[good] = on_edge[best[good]]
        need |= edge & (n_partner != 1)
        need[good] |= best_d[good] > sample_dist[good, 0] + SAMPLE_SLACK
        good = ~need
        b = best[good]
        rows = offset + np.flatnonzero(good)
        c = closest[b]
        nrm = normal[b].copy()
        e = edge[good]
        pseudo = nrm + np.where(e[:, None], partner_normal[good], 0.0)
        diff = points[good] - c
        sign = np.where(np.einsum("ij,ij->i", diff, pseudo) < 0, -1.0, 1.0)
        if e.any():
            # At an edge the distance runs along p - c, not along either face's normal.
            de = np.maximum(dist[b][e], 1e-300)
            nrm[e] = sign[e, None] * diff[e] / de[:, None]
        out.closest[rows] = c
        out.face[rows] = pf[b]
        out.uv[rows] = uv[b]
        out.normal[rows] = nrm
        out.distance[rows] = sign * dist[b]
        out.fallback[rows] = False
        return offset + np.flatnonzero(need)

    @staticmethod
    def clamped(surf, u, v, r, Su, Sv, d):
        """True where the foot point sits on the parameter box with the distance still falling
        outward: the closest point of the face is on its boundary edge."""
        (u0, u1), (v0, v1) = surf.u_range, surf.v_range
        gu = np.einsum("ij,ij->i", r, Su)
        gv = np.einsum("ij,ij->i", r, Sv)
        tu = CLAMP_COSINE * d * np.linalg.norm(Su, axis=1)
        tv = CLAMP_COSINE * d * np.linalg.norm(Sv, axis=1)
        eu = 1e-12 * (u1 - u0)
        ev = 1e-12 * (v1 - v0)
        out = np.zeros(len(u), bool)
        if not surf.closed_u:
            out |= ((u <= u0 + eu) & (gu > tu)) | ((u >= u1 - eu) & (gu < -tu))
        if not surf.closed_v:
            out |= ((v <= v0 + ev) & (gv > tv)) | ((v >= v1 - ev) & (gv < -tv))
        return out

    def parameters_of(self, closest, face, rows):
        """(len(rows), 2) parameters on our SurfaceData of exact closest points
        ``closest[rows]``, which lie on faces ``face[rows]``: Newton foot points from the
        nearest sample's parameters (the face's parameter box centre where that sample is on
        another face)."""
        uv = np.empty((len(rows), 2))
        faces = face[rows]
        for f in np.unique(faces):
            mine = faces == f
            sel = rows[mine]
            idx = self.nearest_sample(closest[sel])
            start = self.samples.uv[idx]
            same = self.samples.face[idx] == f
            if not np.all(same):
                start = np.where(same[:, None], start, [[np.mean(self.surfaces[f].u_range),
                                                          np.mean(self.surfaces[f].v_range)]])
            u, v, _, _ = bspline.project_points(self.surfaces[f], closest[sel], start[:, 0],
                                                start[:, 1])
            uv[mine] = np.column_stack([u, v])
        return uv

    def starts_on_face(self, f, x):
        """Newton starts on face f for points x near it: the (u, v) of the nearest of the
        face's samples."""
        k = min(START_CANDIDATES, len(self.samples.xyz))
        _, idx = self.tree.query(x, k=k)
        idx = idx.reshape(len(x), -1)
        on_f = self.samples.face[idx] == f
        first = np.argmax(on_f, axis=1)
        start = self.samples.uv[idx[np.arange(len(x)), first]]
        missing = np.flatnonzero(~on_f.any(axis=1))
        if len(missing):
            # Nearest sample of this face by brute force: only for the few retried rays.
            mine = np.flatnonzero(self.samples.face == f)
            for i in missing:
                j = mine[np.argmin(np.linalg.norm(self.samples.xyz[mine] - x[i], axis=1))]
                start[i] = self.samples.uv[j]
        return start
