"""core.edges.FaceEdges.closest projects a point only on the edges that can come within
RIVAL_MM of its nearest one (a vertex bound, issue 14's speed). On every trimmed face of the
third-party-like STEP of bench/bench_register_stages.py, for random points from 10 um to 3 mm
off random edges:

- the same answer as Newton on every edge from its nearest polyline vertex (brute force), to
  Newton's tolerance;
- OCC's distance to the face's edges (distToShape) where it is marked exact.
"""
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect.cad.nominal import nominal_from_shape
from BladeInspect.core import edges as edges_mod
from tests.test_trim_edges import points_near_edges, third_party_shape


def every_edge(face_edges, points):
    """(distance, closest point, exact) of FaceEdges.closest without the vertex bound: Newton
    on every edge, the nearest wins, undecided at an end or with a rival elsewhere."""
    dist, closest, exact = [], [], []
    for curve, tree, ts in zip(face_edges.curves, face_edges.trees, face_edges.vertex_t):
        _, i = tree.query(points)
        _, c, conv, at_end = edges_mod.project_on_curve(curve, points, ts[i])
        closest.append(c)
        dist.append(np.linalg.norm(c - points, axis=1))
        exact.append(conv & ~at_end)
    dist, closest, exact = np.array(dist), np.array(closest), np.array(exact)
    win = np.argmin(dist, axis=0)
    cols = np.arange(len(points))
    best, c = dist[win, cols], closest[win, cols]
    rival = ((dist < best + edges_mod.RIVAL_MM)
             & (np.linalg.norm(closest - c, axis=2) > 1e-7)).any(axis=0)
    return best, c, exact[win, cols] & ~rival


class PrunedEdges(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = nominal_from_shape(third_party_shape())

    def test_pruned_edges_are_every_edge_and_occs(self):
        rng = np.random.default_rng(11)
        exact_total = 0
        for f, face_edges in enumerate(self.nominal.face_set.edges):
            if face_edges is None:
                continue
            occ_edges = [e for e in self.nominal._nurbs_faces[f].Edges if not e.Degenerated]
            p = np.concatenate([points_near_edges(rng, occ_edges, 40, scale)
                                for scale in (0.01, 0.3, 3.0)])
            d, c, exact = face_edges.closest(p)
            bd, bc, bexact = every_edge(face_edges, p)
            # Newton's batches differ (it iterates until all of a batch has converged).
            np.testing.assert_allclose(d, bd, rtol=0, atol=1e-11)
            np.testing.assert_allclose(c, bc, rtol=0, atol=1e-11)
            np.testing.assert_array_equal(exact, bexact)
            for x, dx in zip(p[exact][::4], d[exact][::4]):
                v = Part.Vertex(FreeCAD.Vector(*x))
                self.assertAlmostEqual(dx, min(e.distToShape(v)[0] for e in occ_edges),
                                       delta=1e-9)
            exact_total += np.count_nonzero(exact)
        self.assertGreater(exact_total, 500)


if __name__ == "__main__":
    unittest.main()
