"""core.trim.TrimDomain.query against brute force over every segment: random polygons with a
hole (thousands of segments, so the grid has many cells), random points inside, outside, off
the domain's box and on the vertices; inside by the even-odd rule on all segments, distance as
min(exact distance to the nearest segment, reach)."""
import unittest

import numpy as np

from BladeInspect.core.trim import TrimDomain


def ring(rng, centre, radius, n, wobble):
    t = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = radius * (1 + wobble * np.sin(5 * t + rng.uniform(0, 6)))
    pts = np.column_stack([centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)])
    return np.stack([pts, np.roll(pts, -1, axis=0)], axis=1)


def brute(segments, uv):
    a, b = segments[None, :, 0], segments[None, :, 1]
    p = uv[:, None]
    ab, ap = b - a, p - a
    t = np.clip((ap * ab).sum(-1) / (ab * ab).sum(-1), 0, 1)
    dist = np.linalg.norm(ap - t[..., None] * ab, axis=-1).min(axis=1)
    ay, by, py = a[..., 1], b[..., 1], p[..., 1]
    straddle = (ay > py) != (by > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_cross = a[..., 0] + (py - ay) * (b[..., 0] - a[..., 0]) / (by - ay)
    inside = (straddle & (p[..., 0] < x_cross)).sum(axis=1) % 2 == 1
    return inside, dist


class TrimQueryAgainstBruteForce(unittest.TestCase):
    def test_random_domains(self):
        rng = np.random.default_rng(71)
        for trial in range(4):
            outer = ring(rng, (0.5, 0.5), 0.4, int(rng.integers(300, 1500)), 0.2)
            hole = ring(rng, (0.5, 0.5), 0.1, int(rng.integers(50, 500)), 0.3)
            segs = np.concatenate([outer, hole])
            rng.shuffle(segs)
            dom = TrimDomain(segs)
            uv = np.concatenate([rng.uniform(-0.2, 1.2, (1500, 2)), segs[::7, 0],
                                 segs[::11, 0] + rng.normal(0, 1e-4, (len(segs[::11]), 2)),
                                 [[-5.0, 0.5], [0.5, 7.0]]])
            inside, dist = dom.query(uv)
            ref_inside, ref_dist = brute(segs, uv)
            off_vertex = np.ones(len(uv), bool)
            off_vertex[1500:1500 + len(segs[::7])] = False   # on a vertex inside is either
            np.testing.assert_array_equal(inside[off_vertex], ref_inside[off_vertex])
            np.testing.assert_allclose(dist, np.minimum(ref_dist, dom.reach), rtol=0, atol=1e-15)
            self.assertTrue((ref_dist < dom.reach).sum() > 100)


if __name__ == "__main__":
    unittest.main()
