"""A trimmed face's domain in its surface's (u, v): point-in-domain and distance to the boundary,
vectorised over many parameter pairs.

The boundary is a soup of segments (the face's discretised trimming curves, in any order and
direction); inside is decided by the even-odd rule on a ray towards +u. Segments are bucketed
in a uniform grid so each query meets only the few segments near it: cells dilated by one cell
for the distance, which is therefore exact up to one cell size and reported as that cell size
beyond (a valid lower bound, all callers need); for the crossing count, finer v bands of their
own (every segment that straddles a point's v is in that point's band, so the count is exact
whatever the bands; finer bands just pair each point with fewer segments).
"""

import numpy as np

# Target number of segments per grid row / column.
SEGMENTS_PER_BIN = 8
# Most rows of the crossing count's own bands.
MAX_ROWS = 8192


def csr(bin_ids, item_ids, n_bins):
    """Items bucketed by bin: (start, count per bin, items ordered by bin), for bucket_pairs."""
    order = np.argsort(bin_ids, kind="stable")
    counts = np.bincount(bin_ids, minlength=n_bins)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    return starts, counts, item_ids[order]


def bucket_pairs(query_bins, starts, counts, members):
    """(query index, member) for every member of each query's bin of a csr table."""
    cnt = counts[query_bins]
    q = np.repeat(np.arange(len(query_bins)), cnt)
    first = np.repeat(starts[query_bins], cnt)
    offset = np.arange(len(q)) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    return q, members[first + offset]


def _ranges(starts, counts):
    """(owner, value): for each i, counts[i] entries owner i with values starts[i] + 0, 1, ..."""
    owner = np.repeat(np.arange(len(counts)), counts)
    return owner, starts[owner] + np.arange(len(owner)) - np.repeat(np.cumsum(counts) - counts,
                                                                    counts)


class TrimDomain:
    def __init__(self, segments):
        """segments: (K, 2, 2) boundary pieces in (u, v)."""
        self.segments = np.asarray(segments, dtype=float)
        a, b = self.segments[:, 0], self.segments[:, 1]
        lo = np.minimum(a, b)
        hi = np.maximum(a, b)
        span = np.maximum(hi.max(axis=0) - lo.min(axis=0), 1e-12)
        g = int(np.clip(np.sqrt(len(self.segments) / SEGMENTS_PER_BIN) * 2, 4, 512))
        self.cell = span / g
        self.origin = lo.min(axis=0) - self.cell          # one dilation cell on each side
        self.shape = (g + 2, g + 2)
        # v bands each segment crosses, for the even-odd count (one spare band each side).
        n_bands = int(np.clip(len(self.segments) // SEGMENTS_PER_BIN, g, MAX_ROWS))
        self.band = span[1] / n_bands
        self.band_origin = lo[:, 1].min() - self.band
        self.n_bands = n_bands + 2
        r0 = self._band(lo[:, 1])
        r1 = self._band(hi[:, 1])
        rows_seg, rows = _ranges(r0, r1 - r0 + 1)
        self._rows = csr(rows, rows_seg, self.n_bands)
        # Cells of each segment's box dilated by one cell, for the distance.
        c0u, c1u = self._index(lo[:, 0], 0) - 1, self._index(hi[:, 0], 0) + 1
        c0v, c1v = self._index(lo[:, 1], 1) - 1, self._index(hi[:, 1], 1) + 1
        c0u, c0v = np.maximum(c0u, 0), np.maximum(c0v, 0)
        c1u, c1v = np.minimum(c1u, self.shape[0] - 1), np.minimum(c1v, self.shape[1] - 1)
        nv = c1v - c0v + 1
        ids, local = _ranges(np.zeros_like(c0u), (c1u - c0u + 1) * nv)
        cells = (c0u[ids] + local // nv[ids]) * self.shape[1] + c0v[ids] + local % nv[ids]
        self._cells = csr(cells, ids, self.shape[0] * self.shape[1])
        self.reach = float(self.cell.min())
        # Per segment, contiguous: start (u, v), direction (u, v), squared length (1 when 0).
        d = b - a
        self._columns = (np.ascontiguousarray(a[:, 0]), np.ascontiguousarray(a[:, 1]),
                         np.ascontiguousarray(d[:, 0]), np.ascontiguousarray(d[:, 1]),
                         np.where((d * d).sum(axis=1) > 0, d[:, 0] ** 2 + d[:, 1] ** 2, 1.0))

    def _band(self, v):
        return np.clip(((v - self.band_origin) / self.band).astype(int), 0, self.n_bands - 1)

    def _index(self, x, axis):
        return np.clip(((x - self.origin[axis]) / self.cell[axis]).astype(int), 0, self.shape[axis] - 1)

    def query(self, uv):
        """(inside (N,) bool, distance to the boundary (N,), capped at `reach`)."""
        uv = np.asarray(uv, dtype=float).reshape(-1, 2)
        n = len(uv)
        pu, pv = uv[:, 0], uv[:, 1]
        au, av, du, dv, len2 = self._columns
        # Even-odd count of crossings of the ray from each point towards +u.
        rows = np.flatnonzero((pv >= self.band_origin)
                              & (pv < self.band_origin + self.n_bands * self.band))
        q, s = bucket_pairs(self._band(pv[rows]), *self._rows)
        q = rows[q]
        py = pv[q]
        ay = av[s]
        straddle = (ay > py) != (ay + dv[s] > py)
        q, s, py, ay = q[straddle], s[straddle], py[straddle], ay[straddle]
        hit = pu[q] < au[s] + (py - ay) * du[s] / dv[s]
        inside = np.bincount(q[hit], minlength=n) % 2 == 1
        # Distance to the nearest segment among those registered in the point's cell.
        dist = np.full(n, self.reach)
        iu = ((pu - self.origin[0]) / self.cell[0]).astype(int)
        iv = ((pv - self.origin[1]) / self.cell[1]).astype(int)
        cells = np.flatnonzero((iu >= 0) & (iu < self.shape[0]) & (iv >= 0) & (iv < self.shape[1]))
        q, s = bucket_pairs(iu[cells] * self.shape[1] + iv[cells], *self._cells)
        if len(q):
            q = cells[q]
            ab_u, ab_v = du[s], dv[s]
            ap_u, ap_v = pu[q] - au[s], pv[q] - av[s]
            t = np.clip((ap_u * ab_u + ap_v * ab_v) / len2[s], 0.0, 1.0)
            d = np.sqrt((ap_u - t * ab_u) ** 2 + (ap_v - t * ab_v) ** 2)
            # bucket_pairs lists each query's pairs together, in query order: a minimum per run
            # (ufunc.at is slow on numpy 1.24).
            first = np.flatnonzero(np.concatenate([[True], q[1:] != q[:-1]]))
            owners = q[first]
            dist[owners] = np.minimum(dist[owners], np.minimum.reduceat(d, first))
        return inside, dist
