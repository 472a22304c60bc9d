"""Closest points on a trimmed face's boundary edges (core.edges, issue 14): where Newton's foot
on a face's surface lands outside its trimmed domain, the fast path takes the face's closest
point from its boundary edges instead of asking OpenCASCADE. Checked against OCC's own
distances on the third-party-like STEP of bench/bench_register_stages.py (B-spline sides cut
by a revolved hub and a cylindrical tip, every face trimmed):

- the edge kernel against Part's distToShape to each edge, for random points near the edges;
- the signed distance of random points near the trim edges, outside the material, against the
  independent OCC reference (Nominal.signed_distance_occ), most of them decided without OCC;
- (an expected failure, older than the kernel) points just inside the material there.
"""
import importlib.util
import os
import shutil
import tempfile
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect.cad.nominal import curve_data_of_edge, nominal_from_shape
from BladeInspect.core.edges import FaceEdges

HERE = os.path.dirname(os.path.abspath(__file__))


def third_party_shape():
    spec = importlib.util.spec_from_file_location(
        "bench_register_stages", os.path.join(HERE, "..", "bench", "bench_register_stages.py"))
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    tmp = tempfile.mkdtemp()
    try:
        return Part.read(bench.write_revolved_cap_step(os.path.join(tmp, "blade.step")))
    finally:
        shutil.rmtree(tmp)


def points_near_edges(rng, edges, n, offset):
    """n random points within ``offset`` mm of random points on the edges."""
    out = []
    for k in rng.integers(0, len(edges), n):
        edge = edges[k]
        a, b = edge.ParameterRange
        c = np.array(edge.valueAt(rng.uniform(a + 0.02 * (b - a), b - 0.02 * (b - a))))
        out.append(c + rng.normal(0.0, offset, 3))
    return np.array(out)


class TrimEdges(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.shape = third_party_shape()
        cls.nominal = nominal_from_shape(cls.shape)
        cls.edges = [e for e in cls.shape.Edges if not e.Degenerated]
        cls.near = points_near_edges(np.random.default_rng(2), cls.edges, 250, 0.2)
        cls.occ = cls.nominal.signed_distance_occ(cls.near)

    def test_edge_kernel_is_occs_edge_distance(self):
        rng = np.random.default_rng(1)
        nurbs = self.nominal._nurbs_faces
        for face in nurbs:
            edges = [e for e in face.Edges if not e.Degenerated]
            kernel = FaceEdges([curve_data_of_edge(e) for e in edges])
            p = points_near_edges(rng, edges, 25, 0.5)
            d, c, exact = kernel.closest(p)
            self.assertGreater(np.count_nonzero(exact), 18)
            for x, dx, cx in zip(p[exact], d[exact], c[exact]):
                v = Part.Vertex(FreeCAD.Vector(*x))
                occ = min(e.distToShape(v)[0] for e in edges)
                self.assertAlmostEqual(dx, occ, delta=1e-9)
                self.assertAlmostEqual(np.linalg.norm(cx - x), dx, delta=1e-12)

    def test_signed_distance_near_trim_edges_is_occs(self):
        occ = self.occ
        outside = occ.distance > 1e-3
        p = self.near[outside]
        fast = self.nominal.signed_distance(p)
        # The faces meet within their edges' tolerances (up to 2e-4 mm in this STEP): the fast
        # path and OCC agree to that model's precision everywhere, and to Newton's where the
        # edge kernel decided (a closest point on a trim edge, at no distance from the
        # boundary) and OCC's closest point is on an edge too.
        np.testing.assert_allclose(fast.distance, occ.distance[outside], rtol=0, atol=1e-7)
        occ_on_edge = np.array([self.nominal._face_compound.distToShape(
            Part.Vertex(FreeCAD.Vector(*x)))[2][0][0] == "Edge" for x in p])
        on_edge = occ_on_edge & ~fast.fallback & (fast.boundary == 0.0)
        self.assertGreater(np.count_nonzero(on_edge), 0.5 * np.count_nonzero(occ_on_edge))
        np.testing.assert_allclose(fast.distance[on_edge], occ.distance[outside][on_edge],
                                   rtol=0, atol=1e-9)
        np.testing.assert_allclose(fast.closest[on_edge], occ.closest[outside][on_edge],
                                   rtol=0, atol=1e-7)
        # The trim edges are decided by the fast path: before the edge kernel about a third of
        # such points went to OCC (35 % of these 250, 42 % of the outside ones of 400).
        self.assertLess(fast.fallback_fraction, 0.2)

    def test_inside_points_near_the_hub_edge_are_never_understated(self):
        """Known, and older than the edge kernel: a point just inside the material near where
        a side meets the hub, whose 8 nearest samples all lie on the hub, never makes the side
        a candidate, so the fast path may answer the hub's distance (0.057 mm where OCC finds
        0.0023 mm on FreeCAD 0.20's sampling of this part; FreeCAD 1.0's samples happen to
        avoid it). What holds on every platform, and what a verdict relies on: the answer is
        a true distance to some face, so it never understates |deviation| nor flips its side."""
        p = points_near_edges(np.random.default_rng(2), self.edges, 400, 0.2)
        fast = self.nominal.signed_distance(p)
        inside = fast.distance < -1e-3
        self.assertGreater(np.count_nonzero(inside), 20)
        occ = self.nominal.signed_distance_occ(p[inside])
        self.assertTrue(np.all(np.abs(fast.distance[inside]) >= np.abs(occ.distance) - 1e-7))
        np.testing.assert_array_equal(np.sign(fast.distance[inside]), np.sign(occ.distance))


if __name__ == "__main__":
    unittest.main()
