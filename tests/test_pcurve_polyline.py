"""The trimmed faces' boundary polylines (cad.nominal, issue 14's speed): the fast path decides
inside/outside a face's trimmed domain from a polyline on its pcurves and leaves every foot
point within the face's ``margin`` (uv) of it to OpenCASCADE. On the third-party-like STEP of
bench/bench_register_stages.py (a cylinder's angle in radians beside lengths in mm):

- every point of each trimming pcurve, evaluated by OCC (Geom2d value), lies within the
  margin of the polyline: the margin is honest;
- the band the margin leaves undecided is narrow in 3D too (OCC's surface derivatives give
  the length per parameter unit): once it was 12 um wide across a side's trim edge and 3 um
  across the cylindrical tip's, which sent ~70 of the paper's 269k points to OCC per
  full-cloud evaluation;
- random points within ~5 um of the tip's trim edges get OCC's signed distance, nearly all
  of them without OCC (a third went to OCC before).
"""
import unittest

import numpy as np
import Part

from BladeInspect.cad.nominal import nominal_from_shape
from tests.test_trim_edges import occ_signed_distance, points_near_edges, third_party_shape

# Widest undecided band across a trim edge, in mm (the old chord rule left 3e-3 to 1.5e-2).
MAX_BAND_MM = 1e-3


def segment_distance(segments, q):
    """Distance of points q (M, 2) to the nearest of segments (K, 2, 2), by brute force."""
    a, d = segments[:, 0], segments[:, 1] - segments[:, 0]
    len2 = np.maximum((d * d).sum(axis=1), 1e-300)
    out = np.empty(len(q))
    for s in range(0, len(q), 32):
        x = q[s:s + 32, None]
        t = np.clip(((x - a) * d).sum(axis=2) / len2, 0.0, 1.0)
        out[s:s + 32] = np.sqrt((((x - a) - t[..., None] * d) ** 2).sum(axis=2).min(axis=1))
    return out


class PcurvePolylines(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.shape = third_party_shape()
        cls.nominal = nominal_from_shape(cls.shape)

    def trimmed(self):
        for f, (nface, domain) in enumerate(zip(self.nominal._nurbs_faces, self.nominal.domains)):
            if domain.index is not None:
                yield f, nface, domain

    def test_pcurves_lie_within_the_margin_of_the_polyline(self):
        rng = np.random.default_rng(4)
        checked = 0
        for f, nface, domain in self.trimmed():
            for edge in nface.Edges:
                curve, a, b = nface.curveOnSurface(edge)
                t = rng.uniform(a, b, 150)
                q = np.array([[p.x, p.y] for p in (curve.value(x) for x in t)])
                gap = segment_distance(domain.index.segments, q)
                self.assertLessEqual(gap.max(), domain.margin, "face %d" % f)
                checked += len(q)
        self.assertGreater(checked, 3000)

    def test_the_undecided_band_is_narrow_in_3d(self):
        for f, nface, domain in self.trimmed():
            bs = nface.Surface
            u0, u1, v0, v1 = nface.ParameterRange
            speed = 0.0
            for u in np.linspace(u0, u1, 7):
                for v in np.linspace(v0, v1, 7):
                    du, dv = bs.getDN(u, v, 1, 0), bs.getDN(u, v, 0, 1)
                    speed = max(speed, du.Length, dv.Length)
            self.assertLess(domain.margin * speed, MAX_BAND_MM, "face %d" % f)

    def test_points_off_the_tip_trim_edges_are_occs_mostly_without_occ(self):
        tip = [f for f, face in enumerate(self.nominal.faces)
               if isinstance(face.Surface, Part.Cylinder)]
        self.assertTrue(tip)
        edges = [e for f in tip for e in self.nominal.faces[f].Edges if not e.Degenerated]
        rng = np.random.default_rng(8)
        p = points_near_edges(rng, edges, 120, 0.005)
        fast = self.nominal.signed_distance(p)
        truth = occ_signed_distance(self.nominal, p, fast.distance, rng)
        np.testing.assert_allclose(fast.distance, truth, rtol=0, atol=1e-6)
        # The old chord rule sent a third of such points to OCC (0.329 of 2000), now 1.2 %.
        self.assertLess(fast.fallback_fraction, 0.05)


if __name__ == "__main__":
    unittest.main()
