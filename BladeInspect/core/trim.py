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

    def _band(self, v):
        return np.clip(((v - self.band_origin) / self.band).astype(int), 0, self.n_bands - 1)

    def _index(self, x, axis):
        return np.clip(((x - self.origin[axis]) / self.cell[axis]).astype(int), 0, self.shape[axis] - 1)

    def query(self, uv):
        """(inside (N,) bool, distance to the boundary (N,), capped at `reach`)."""
        uv = np.asarray(uv, dtype=float).reshape(-1, 2)
        n = len(uv)
        a, b = self.segments[:, 0], self.segments[:, 1]
        # Even-odd count of crossings of the ray from each point towards +u.
        row = self._band(uv[:, 1])
        in_rows = ((uv[:, 1] >= self.band_origin)
                   & (uv[:, 1] < self.band_origin + self.n_bands * self.band))
        q, s = bucket_pairs(np.where(in_rows, row, 0), *self._rows)
        keep = in_rows[q]
        q, s = q[keep], s[keep]
        ay, by = a[s, 1], b[s, 1]
        py = uv[q, 1]
        straddle = (ay > py) != (by > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_cross = a[s, 0] + (py - ay) * (b[s, 0] - a[s, 0]) / (by - ay)
        hit = straddle & (uv[q, 0] < x_cross)
        inside = np.bincount(q[hit], minlength=n) % 2 == 1
        # Distance to the nearest segment among those registered in the point's cell.
        dist = np.full(n, self.reach)
        iu = ((uv[:, 0] - self.origin[0]) / self.cell[0]).astype(int)
        iv = ((uv[:, 1] - self.origin[1]) / self.cell[1]).astype(int)
        in_grid = (iu >= 0) & (iu < self.shape[0]) & (iv >= 0) & (iv < self.shape[1])
        cell = np.where(in_grid, iu * self.shape[1] + iv, 0)
        q, s = bucket_pairs(cell, *self._cells)
        keep = in_grid[q]
        q, s = q[keep], s[keep]
        if len(q):
            ab = b[s] - a[s]
            ap = uv[q] - a[s]
            len2 = np.einsum("ij,ij->i", ab, ab)
            t = np.clip(np.einsum("ij,ij->i", ap, ab) / np.where(len2 > 0, len2, 1.0), 0.0, 1.0)
            d = np.linalg.norm(ap - t[:, None] * ab, axis=1)
            # bucket_pairs lists each query's pairs together, in query order: a minimum per run
            # (ufunc.at is slow on numpy 1.24).
            first = np.flatnonzero(np.concatenate([[True], q[1:] != q[:-1]]))
            owners = q[first]
            dist[owners] = np.minimum(dist[owners], np.minimum.reduceat(d, first))
        return inside, dist
