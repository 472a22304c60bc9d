"""The exact signed point-to-CAD distance on arrays: every face an exact (rational) B-spline
(core.bspline.SurfaceData) with its trimmed domain (core.trim) and outward side, dense samples on
the faces and a k-d tree over them. No FreeCAD: cad.nominal turns OCC faces into a FaceSet and
asks OpenCASCADE only for the points the fast path here leaves undecided.

Fast path: the k-d tree gives, for each point, the nearby faces and a start (u, v) on each;
Newton on every candidate face (vectorised per face), the smallest distance wins. A face none of
whose samples is among the k nearest is tried too where it can be nearer (SampleCover: the
samples' cover radius per face and clearance to the other faces per sample). A candidate is
only trusted when Newton converged to a point inside the face's trimmed domain, away from its
boundary; a point whose winner lies on a face edge (clamped at the parameter box) without one
partner face across it, or that a doubtful candidate might beat, is left undecided.

Warm starts: ICP and the deviations that follow it evaluate the same points again and again,
each time moved rigidly by less than the last (micrometres at the end). A FootStart carries a
previous call's answer for the same points. A point that call decided inside a face (not at an
edge), with every other face farther by its ``lead`` (a lower bound), needs no new
candidates while it has moved by delta < lead / 2: every distance is 1-Lipschitz in the point,
so no candidate can overtake the winner. Newton then runs on that face alone from the previous
(u, v) (one or two iterations), and the point is decided by the same tests as a cold one
(converged, inside the trimmed domain away from its boundary, not at the parameter box, no
farther than the nearest sample, whose distance is bounded by the previous one less delta).
Any other point takes the cold path, Newton starting at its previous (u, v) on the faces it
shared with the previous call. Only the candidates a cold call would list from the same k-d
tree are ever considered, so the answer is the cold one, to Newton's tolerance (~1e-10 mm).
"""

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Optional

import numpy as np
from scipy.spatial import cKDTree

from . import background, bspline
from .trim import TrimDomain

# Number of nearest samples whose faces become Newton candidates for a point. SampleCover
# tries any face they miss that can be nearer, so this only trades the k-d query's cost
# against the cover's: 8 cost a cold evaluation 10-15 % more, for the same answers.
K_CANDIDATES = 4
# Relative cosine above which the gradient at a bound means "the minimum lies outside".
CLAMP_COSINE = 1e-7
# Newton results farther than this from the nearest sample's distance are distrusted (mm).
SAMPLE_SLACK = 1e-9
# Points per chunk at most (bounds the (chunk, K) candidate arrays, a few MB). Every chunk pays
# per-face costs that do not shrink with it (the Newton loops on each face, the boundary edges'
# curve evaluations for the few points near a trim): on the third-party STEP blade at 269,158
# points the fine stage took 2.81 s (mean of 6 runs) in 10 chunks of 32,768 at most, 2.45 s in
# 6 and 2.37 s in 4 (bench/bench_register_stages.py --only step --repeat 3), with identical
# results.
POINT_CHUNK = 131072
# Threads for the fast path.
THREADS = 2
# Points per chunk at least when a call is split over the threads (below, one chunk: the
# threads' start-up and the per-face loops would cost more than the second core gives).
MIN_THREAD_CHUNK = 4096
# Nearest samples searched for a Newton start on one given face.
START_CANDIDATES = 8
# Factor on the largest sample distance found at a face's check points (cell corners, boundary
# points a quarter cell apart) for its cover radius: the points between checks are at most an
# eighth of a cell diagonal farther, and a cover radius is at least half of one.
COVER_SAFETY = 1.25
# How far a sample's clearance to the other faces is sought, in largest cover radii.
CLEARANCE_REACH = 4.0


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
    # For a warm start of the next call (see the module docstring), -inf where none may be
    # taken: how much farther than the winner any other candidate face is at least (mm), and
    # a lower bound of the distance to the nearest sample (mm).
    lead: Optional[np.ndarray] = None
    nearest: Optional[np.ndarray] = None
    # ... and a lower bound of the foot point's (u, v) distance to its face's trimmed boundary.
    boundary: Optional[np.ndarray] = None

    @property
    def fallback_fraction(self):
        if self.fallback is None or len(self.fallback) == 0:
            return 0.0
        return float(np.count_nonzero(self.fallback)) / len(self.fallback)


@dataclass
class FootStart:
    """A previous closest() call's answer for the same points (rows in the same order), to
    warm-start the next call after they have moved a little. A row with face -1 has none."""
    points: np.ndarray     # (N, 3) the points of that call
    face: np.ndarray       # (N,) int
    uv: np.ndarray         # (N, 2)
    lead: np.ndarray       # (N,) DistanceResult.lead
    nearest: np.ndarray    # (N,) DistanceResult.nearest
    boundary: np.ndarray   # (N,) DistanceResult.boundary

    @classmethod
    def of(cls, points, result):
        """The FootStart of a DistanceResult of ``points``."""
        n = len(points)
        lead = result.lead if result.lead is not None else np.full(n, -np.inf)
        nearest = result.nearest if result.nearest is not None else np.zeros(n)
        boundary = result.boundary if result.boundary is not None else np.zeros(n)
        return cls(np.array(points, dtype=float), result.face, result.uv, lead, nearest,
                   boundary)

    @classmethod
    def none(cls, n):
        """No start for any of n points."""
        return cls(np.zeros((n, 3)), np.full(n, -1), np.zeros((n, 2)), np.full(n, -np.inf),
                   np.zeros(n), np.zeros(n))

    def take(self, rows):
        """The FootStart of rows ``rows`` alone."""
        return FootStart(self.points[rows], self.face[rows], self.uv[rows], self.lead[rows],
                         self.nearest[rows], self.boundary[rows])

    def set_rows(self, rows, other):
        """Rows ``rows`` take the starts of ``other``, a FootStart of those points."""
        self.points[rows], self.face[rows], self.uv[rows] = other.points, other.face, other.uv
        self.lead[rows], self.nearest[rows] = other.lead, other.nearest
        self.boundary[rows] = other.boundary


@dataclass
class FaceDomain:
    """A face's trimmed domain in its SurfaceData's (u, v)."""
    index: Optional[TrimDomain]      # the discretised boundary, or None for the whole box
    margin: float                    # uv distance to the boundary below which we do not decide
    planar_scale: Optional[float]    # length per parameter unit when the face is a plane


def patch_boxes(surf):
    """(lo (P, 3), hi (P, 3)): a box around each of the surface's polynomial patches (knot
    spans) that meet its parameter box: the bounding box of the patch's poles, which holds
    the patch by the convex hull property (a rational surface's weights must be positive;
    otherwise one box of infinite extent)."""
    if surf.weights is not None and not np.all(surf.weights > 0):
        return np.full((1, 3), -np.inf), np.full((1, 3), np.inf)
    spans = []
    for knots, degree, (lo, hi) in ((surf.knots_u, surf.degree_u, surf.u_range),
                                    (surf.knots_v, surf.degree_v, surf.v_range)):
        i = np.arange(degree, len(knots) - degree - 1)
        spans.append(i[(knots[i + 1] > knots[i]) & (knots[i + 1] >= lo) & (knots[i] <= hi)])
    lo, hi = [], []
    for i in spans[0]:
        for j in spans[1]:
            poles = surf.poles[i - surf.degree_u:i + 1, j - surf.degree_v:j + 1].reshape(-1, 3)
            lo.append(poles.min(axis=0))
            hi.append(poles.max(axis=0))
    return np.array(lo), np.array(hi)


def box_distance(points, lo, hi):
    """(N, P) distance of each point to each box (0 inside)."""
    gap = np.maximum(np.maximum(lo[None] - points[:, None], points[:, None] - hi[None]), 0.0)
    return np.linalg.norm(gap, axis=2)


def grid_step(values):
    """The step of a regular grid of which ``values`` are nodes (NaN for fewer than two)."""
    steps = np.diff(np.unique(values))
    return steps.min() if len(steps) else np.nan


def cover_radius(surf, domain, uv, tree, hull_size):
    """The cover radius of a face's samples: the largest distance from a point of the face to
    its nearest sample (mm), capped at ``hull_size`` (a diameter of the face). The samples
    are the centres of the cells of a regular (u, v) grid on the parameter box that lie in
    the trimmed domain (``uv``, ``tree`` a k-d tree over their points); the face's farthest
    points from them are the cells' corners (the vertices of the samples' Voronoi diagram)
    and, where the grid is cut, the trimmed boundary: both are checked (COVER_SAFETY)."""
    (u0, u1), (v0, v1) = surf.u_range, surf.v_range
    du, dv = grid_step(uv[:, 0]), grid_step(uv[:, 1])
    if not (du > 0 and dv > 0):
        return hull_size
    iu, iv = (uv[:, 0] - u0) / du - 0.5, (uv[:, 1] - v0) / dv - 0.5
    if (np.abs(iu - np.rint(iu)).max() > 1e-6 or np.abs(iv - np.rint(iv)).max() > 1e-6
            or iu.min() < -0.5 or iv.min() < -0.5):
        return hull_size         # not the grid of nominal's sampling
    iu, iv = np.rint(iu).astype(np.int64), np.rint(iv).astype(np.int64)
    width = iv.max() + 2
    corner = np.unique(((iu[:, None] + [0, 0, 1, 1]) * width + iv[:, None] + [0, 1, 0, 1]).ravel())
    check = [np.column_stack([u0 + corner // width * du, v0 + corner % width * dv])]
    if domain.index is not None:
        a, b = domain.index.segments[:, 0], domain.index.segments[:, 1]
        along = np.cumsum(np.linalg.norm(b - a, axis=1)) / (0.25 * min(du, dv))
        check.append(a[np.diff(np.floor(along), prepend=-1.0) > 0])
    check = np.clip(np.concatenate(check), [u0, v0], [u1, v1])
    (S,) = surf.power_patches().evaluate(check[:, 0], check[:, 1], order=0)
    return min(COVER_SAFETY * float(tree.query(S)[0].max()), hull_size)


class SampleCover:
    """Which faces a point's candidates (the faces of its k nearest samples) may miss.

    Every point of a face B lies within B's cover radius R_B (cover_radius) of one of B's
    samples, so a point s is at least |s - t| - R_B from B, t the B-sample nearest to s. For
    each sample s of a face A the clearance is the least of that bound over the other faces
    (``clearance``, known up to CLEARANCE_REACH). A point p whose best candidate is face A at
    distance d, closest point c, Newton started from A's sample s, is at least
    clearance(s) - |c - s| - d from every other face: where that exceeds d, no face missed
    can be nearer. Elsewhere (near another face) every face with a sample within d + R_B of
    p is tried, from that sample; the others are farther than d."""

    def __init__(self, surfaces, domains, samples):
        n_faces = len(surfaces)
        self.trees, self.uv = [None] * n_faces, [None] * n_faces
        self.sample_xyz = samples.xyz
        self.surfaces, self.boxes = surfaces, [None] * n_faces
        self.lo, self.hi = np.zeros((n_faces, 3)), np.zeros((n_faces, 3))
        self.radius = np.zeros(n_faces)
        order = np.argsort(samples.face, kind="stable")
        cuts = np.searchsorted(samples.face[order], np.arange(n_faces + 1))
        members = [order[cuts[f]:cuts[f + 1]] for f in range(n_faces)]

        def face_cover(f):
            surf = surfaces[f]
            xyz = samples.xyz[members[f]]
            self.trees[f], self.uv[f] = cKDTree(xyz), samples.uv[members[f]]
            self.lo[f], self.hi[f] = xyz.min(axis=0), xyz.max(axis=0)
            poles = surf.poles.reshape(-1, 3)
            # The convex hull property (positive weights): the face lies in its poles' box.
            hull = (np.linalg.norm(poles.max(axis=0) - poles.min(axis=0))
                    if surf.weights is None or np.all(surf.weights > 0) else np.inf)
            self.radius[f] = cover_radius(surf, domains[f], self.uv[f], self.trees[f], hull)
        self.sampled = np.flatnonzero(cuts[1:] > cuts[:-1])
        # Hook (speed): the faces' trees and radii, then each face's clearances (rows of its
        # own samples only), on the threads: numpy and the k-d trees release the GIL.
        with ThreadPoolExecutor(max_workers=THREADS) as pool:
            list(pool.map(face_cover, self.sampled))
        # A face without samples is never a candidate: only its patch boxes bound it.
        self.unsampled = [(f, patch_boxes(surfaces[f])) for f in
                          np.flatnonzero(cuts[1:] == cuts[:-1])]
        self.radius_max = float(self.radius.max()) if n_faces else 0.0
        reach = CLEARANCE_REACH * self.radius_max
        self.clearance = np.full(len(samples.xyz), reach - self.radius_max)

        def face_clearance(a):
            for b in self.sampled:
                boxes_apart = np.maximum(np.maximum(self.lo[a] - self.hi[b],
                                                    self.lo[b] - self.hi[a]), 0.0)
                if a == b or np.linalg.norm(boxes_apart) > reach:
                    continue
                mine = members[a]
                # Only the samples within reach of b's box can be within reach of b's samples.
                mine = mine[box_distance(samples.xyz[mine], self.lo[b:b + 1],
                                         self.hi[b:b + 1])[:, 0] <= reach]
                d, _ = self.trees[b].query(samples.xyz[mine], distance_upper_bound=reach)
                self.clearance[mine] = np.minimum(self.clearance[mine],
                                                  np.minimum(d, reach) - self.radius[b])
        with ThreadPoolExecutor(max_workers=THREADS) as pool:
            list(pool.map(face_clearance, self.sampled))

    def patch_boxes(self, f):
        """patch_boxes of face f, kept from the first call."""
        if self.boxes[f] is None:
            self.boxes[f] = patch_boxes(self.surfaces[f])
        return self.boxes[f]

    def beyond(self, points, pi, pf, pair_sample, dist, closest, trusted):
        """(point, face, Newton start (u, v)) of the candidates the k nearest samples missed,
        and per point a lower bound of its distance to every face tried neither among those
        nor among the pairs (pi, pf) (candidates from samples ``pair_sample``, at
        ``dist`` with closest points ``closest``, ``trusted`` where decided)."""
        n = len(points)
        best = np.full(n, np.inf)
        np.minimum.at(best, pi[trusted], dist[trusted])
        win = np.flatnonzero(trusted & (dist == best[pi]))
        s = np.full(n, -1)
        s[pi[win]] = pair_sample[win]
        gap = np.full(n, np.inf)
        gap[pi[win]] = np.linalg.norm(closest[win] - self.sample_xyz[pair_sample[win]], axis=1)
        untried = np.where(s >= 0, self.clearance[s] - gap - best, -np.inf)
        for f, (lo, hi) in self.unsampled:
            untried = np.minimum(untried, box_distance(points, lo, hi).min(axis=1))
        ask = np.flatnonzero((s >= 0) & ~(untried > best))
        more = [np.zeros(0, int)], [np.zeros(0, int)], [np.zeros((0, 2))]
        if len(ask):
            row = np.full(n, -1)
            row[ask] = np.arange(len(ask))
            mine = row[pi] >= 0
            tried = np.zeros((len(ask), len(self.trees)), bool)
            tried[row[pi[mine]], pf[mine]] = True
            p, reach = points[ask], best[ask]
            bound = np.full(len(ask), np.inf)
            for f, (lo, hi) in self.unsampled:
                bound = np.minimum(bound, box_distance(p, lo, hi).min(axis=1))
            for f in self.sampled:
                r = np.flatnonzero(~tried[:, f])
                box_gap = box_distance(p[r], self.lo[f:f + 1], self.hi[f:f + 1])[:, 0]
                near = box_gap <= reach[r] + self.radius[f]
                bound[r[~near]] = np.minimum(bound[r[~near]], box_gap[~near] - self.radius[f])
                r = r[near]
                if not len(r):
                    continue
                d, j = self.trees[f].query(p[r])
                low = d - self.radius[f]
                close = low <= reach[r]
                if close.any():
                    # The face lies in its patches' boxes: where they are farther, so is it.
                    lo, hi = self.patch_boxes(f)
                    low[close] = np.maximum(low[close],
                                            box_distance(p[r[close]], lo, hi).min(axis=1))
                    close = low <= reach[r]
                bound[r[~close]] = np.minimum(bound[r[~close]], low[~close])
                more[0].append(ask[r[close]])
                more[1].append(np.full(np.count_nonzero(close), f))
                more[2].append(self.uv[f][j[close]])
            untried[ask] = bound
        return tuple(np.concatenate(x) for x in more) + (untried,)


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

    def __init__(self, surfaces, domains, reversed_, samples, edges=None):
        self.surfaces = surfaces
        # core.edges.FaceEdges per trimmed face (None: none known), for feet outside the domain.
        self.edges = edges
        self.domains = domains
        self.reversed = np.asarray(reversed_, bool)
        self.samples = samples
        self.tree = cKDTree(samples.xyz)
        self._patch_boxes = None
        self.cover = SampleCover(surfaces, domains, samples)

    def nearest_sample(self, points):
        """Index of each point's nearest sample."""
        return self.tree.query(points)[1]

    def faces_within_reach(self, points):
        """(N, F) bool: the faces that may hold a point's closest point. The samples lie on
        the faces, so the nearest one's distance bounds the closest point's from above; a
        face whose patch boxes (patch_boxes) are all farther cannot hold it."""
        if self._patch_boxes is None:
            self._patch_boxes = [patch_boxes(surf) for surf in self.surfaces]
        reach = self.tree.query(points)[0]
        return np.column_stack([box_distance(points, lo, hi).min(axis=1) <= reach
                                for lo, hi in self._patch_boxes])

    def closest(self, points, start=None):
        """The fast path on (N, 3) points -> (DistanceResult with the decided rows filled and
        ``fallback`` False there, the undecided rows (M,) for an exact solver to fill).
        ``start``: a FootStart of these points (see the module docstring), or None."""
        n = len(points)
        out = DistanceResult(np.empty((n, 3)), np.empty(n, int), np.empty((n, 2)),
                             np.empty((n, 3)), np.empty(n), np.zeros(n, bool),
                             np.full(n, -np.inf), np.zeros(n), np.zeros(n))

        def cold(rows):
            return self.closest_chunk(points[rows], out, rows, start)
        rows = np.arange(n)
        if start is not None:
            # The warm pass first, then what it leaves (near trims and edges: a few hundred
            # points of a tracked fit's 269,158) in one cold pass, so that the cold path's
            # per-face costs are paid once, not once per chunk. Every point's answer is its
            # own: the batching changes none.
            rows = np.concatenate(self._on_threads(
                lambda r: self.warm_chunk(points, r, out, start), rows) or [rows[:0]])
        hard = self._on_threads(cold, rows)
        return out, (np.concatenate(hard) if hard else np.zeros(0, int))

    @staticmethod
    def _on_threads(work, rows):
        """[work(chunk) for each chunk of ``rows``], the chunks on THREADS threads."""
        n = len(rows)
        if n == 0:
            return []
        # Hook (speed): equal chunks, as many as a multiple of the threads, so that neither
        # thread waits for the other's last chunk (an odd number of chunks leaves one thread a
        # chunk alone; the fine fit's 30,000 points would run on one thread).
        n_chunks = -(-n // POINT_CHUNK)
        if n >= THREADS * MIN_THREAD_CHUNK:
            n_chunks = THREADS * -(-n_chunks // THREADS)
        size = max(-(-n // max(n_chunks, 1)), 1)
        chunks = [rows[s:s + size] for s in range(0, n, size)]
        # numpy releases the GIL in its array loops: chunks on two threads use both cores.
        if len(chunks) > 1:
            # Waiting, this thread lets a GUI's event loop turn (core.background).
            return background.pool_map(work, chunks, THREADS)
        return [work(c) for c in chunks]

    def warm_chunk(self, points, rows, out, start):
        """The warm path (module docstring) on ``points[rows]``: fills ``out``'s rows it
        decides and returns the others, for the cold path."""
        moved = np.linalg.norm(points[rows] - start.points[rows], axis=1)
        face = start.face[rows]
        warm = (face >= 0) & (start.lead[rows] > 2.0 * moved)
        done = np.zeros(len(rows), bool)
        for f in np.unique(face[warm]):
            sel = np.flatnonzero(warm & (face == f))
            r = rows[sel]
            surf = self.surfaces[f]
            p = points[r]
            u, v, S, Su, Sv, conv = bspline.project(surf, p, start.uv[r, 0], start.uv[r, 1])
            diff = S - p
            d = np.linalg.norm(diff, axis=1)
            nrm, degenerate = self.unit_normal(f, Su, Sv)
            uv = np.column_stack([u, v])
            inside, bdist = self.still_inside(f, uv, start.uv[r], start.boundary[r])
            nearest = start.nearest[r] - moved[sel]
            ok = (conv & inside & (bdist > self.domains[f].margin) & ~degenerate
                  & ~self.clamped(surf, u, v, diff, Su, Sv, d) & (d <= nearest + SAMPLE_SLACK))
            r, i = r[ok], sel[ok]
            out.closest[r] = S[ok]
            out.face[r] = f
            out.uv[r] = uv[ok]
            out.normal[r] = nrm[ok]
            out.distance[r] = np.where(np.einsum("ij,ij->i", diff[ok], nrm[ok]) > 0, -1.0,
                                       1.0) * d[ok]
            out.fallback[r] = False
            out.lead[r] = start.lead[r] - 2.0 * moved[i]
            out.nearest[r] = nearest[ok]
            out.boundary[r] = bdist[ok]
            done[i] = True
        return rows[~done]

    def still_inside(self, f, uv, uv_before, boundary_before):
        """point_in_domain of face f at ``uv``, where the foot points were inside at
        ``uv_before``, at least ``boundary_before`` from the boundary: a move shorter than
        the margin left needs no query (it crosses no boundary, and the distance to it falls
        by at most the move's length)."""
        domain = self.domains[f]
        step = np.linalg.norm(uv - uv_before, axis=1)
        bdist = boundary_before - step
        known = bdist > domain.margin
        inside = known.copy()
        if not known.all():
            ask = np.flatnonzero(~known)
            inside[ask], bdist[ask] = point_in_domain(domain, uv[ask])
        return inside, bdist

    def unit_normal(self, f, Su, Sv):
        """(outward unit normals (N,3), degenerate (N,) bool: Su x Sv vanishes) on face f."""
        nrm = np.cross(Su, Sv)
        nlen = np.linalg.norm(nrm, axis=1)
        degenerate = nlen <= 1e-12 * np.linalg.norm(Su, axis=1) * np.linalg.norm(Sv, axis=1) + 1e-300
        nrm /= np.where(nlen > 0, nlen, 1.0)[:, None]
        return (-nrm if self.reversed[f] else nrm), degenerate

    def closest_chunk(self, points, out, rows, foot_start=None):
        """The cold fast path on the points of ``out``'s rows ``rows``: fills the rows it
        decides and returns those it leaves to the exact fallback. ``foot_start``: a
        FootStart of all of ``out``'s points, for Newton's starts, or None."""
        n = len(points)
        if n == 0:
            return rows
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
        if foot_start is not None:
            warm = foot_start.face[rows[pi]] == pf
            start[warm] = foot_start.uv[rows[pi[warm]]]
        tried = self.try_faces(points, pi, pf, start)
        # Hook (cover radius): faces none of whose samples is among the k nearest may still
        # be nearer than the best candidate; SampleCover tries those that can be.
        more_pi, more_pf, more_start, untried = self.cover.beyond(
            points, pi, pf, idx[pi, cj], tried[0], tried[5], tried[2])
        if len(more_pi):
            more = self.try_faces(points, more_pi, more_pf, more_start)
            pi, pf = np.concatenate([pi, more_pi]), np.concatenate([pf, more_pf])
            tried = tuple(np.concatenate([x, y]) for x, y in zip(tried, more))
        dist, lower, trusted, on_edge, converged_pair, closest, uv, normal, boundary = tried
        m = len(pi)
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
        # ... nor a face no sample of which was near enough to be tried (one without samples).
        need |= untried < best_d - 1e-12
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
        # The lead of a point decided inside a face: the least gap from its winner to another
        # candidate's lower bound (none at an edge, where the partner face is as near).
        lead = np.full(n, np.inf)
        other = np.arange(m) != bp
        np.minimum.at(lead, pi[other], lower[other] - best_d[pi[other]])
        lead = np.minimum(lead, untried - best_d)
        decided = rows[good]
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
        out.closest[decided] = c
        out.face[decided] = pf[b]
        out.uv[decided] = uv[b]
        out.normal[decided] = nrm
        out.distance[decided] = sign * dist[b]
        out.fallback[decided] = False
        out.lead[decided] = np.where(e, -np.inf, lead[good])
        out.nearest[decided] = sample_dist[good, 0]
        out.boundary[decided] = boundary[b]
        return rows[np.flatnonzero(need)]

    def try_faces(self, points, pi, pf, start):
        """Newton on face pf[j] for point points[pi[j]] from (u, v) start[j], per face -> the
        candidates' (distance, lower bound of the face's distance, trusted, on an edge,
        converged, closest point, (u, v), outward normal, uv distance to the boundary)."""
        m = len(pi)
        dist = np.full(m, np.inf)
        lower = np.full(m, np.inf)       # a lower bound of the candidate's true face distance
        trusted = np.zeros(m, bool)
        on_edge = np.zeros(m, bool)
        converged_pair = np.zeros(m, bool)
        closest = np.empty((m, 3))
        uv = np.empty((m, 2))
        normal = np.empty((m, 3))
        boundary = np.empty(m)
        for f in np.unique(pf):
            sel = np.flatnonzero(pf == f)
            surf = self.surfaces[f]
            p = points[pi[sel]]
            u, v, S, Su, Sv, conv = bspline.project(surf, p, start[sel, 0], start[sel, 1])
            r = S - p
            d = np.linalg.norm(r, axis=1)
            clamped = self.clamped(surf, u, v, r, Su, Sv, d)
            nrm, degenerate = self.unit_normal(f, Su, Sv)
            inside, bdist = point_in_domain(self.domains[f], np.column_stack([u, v]))
            decided = bdist > self.domains[f].margin
            boundary[sel] = bdist
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
            # Hook (trim edges): a foot clearly outside the trimmed domain means the face's
            # closest point is on its boundary edges, which give it exactly.
            rim = conv & ~inside & (bdist > dom.margin) & ~degenerate
            if self.edges is not None and self.edges[f] is not None and rim.any():
                j = sel[rim]
                de, ce, uve, ne, exact = self.on_boundary(f, p[rim])
                j, de = j[exact], de[exact]
                dist[j], closest[j], uv[j], normal[j] = de, ce[exact], uve[exact], ne[exact]
                trusted[j] = on_edge[j] = True
                lower[j] = de
                boundary[j] = 0.0
        return dist, lower, trusted, on_edge, converged_pair, closest, uv, normal, boundary

    def on_boundary(self, f, p):
        """(distance, closest point, its (u, v), outward unit normal there, exact) of points
        p to face f's boundary edges (core.edges); exact is False where that is undecided."""
        d, c, exact = self.edges[f].closest(p)
        start = self.starts_on_face(f, c)
        u, v, _, Su, Sv, conv = bspline.project(self.surfaces[f], c, start[:, 0], start[:, 1])
        nrm, degenerate = self.unit_normal(f, Su, Sv)
        return d, c, np.column_stack([u, v]), nrm, exact & conv & ~degenerate

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
