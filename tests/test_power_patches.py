"""core.bspline.PowerPatches against OpenCASCADE: values and first/second derivatives of random
polynomial and rational B-spline surfaces (uneven and repeated knots, degrees 1 to 5) and of
the exact NURBS forms of analytic faces, compared with Part.BSplineSurface.value/getDN, on
random parameters, span starts and the box's corners."""
import unittest

import numpy as np

import Part

from BladeInspect.core import bspline
from tests.test_bspline import occ_derivatives, random_surface, surface_data

NAMES = ["S", "Su", "Sv", "Suu", "Suv", "Svv"]


class PowerPatchesAgainstOCC(unittest.TestCase):
    def check(self, bs, surf, rng, n=50):
        (u0, u1), (v0, v1) = surf.u_range, surf.v_range
        # random points, every interior knot (a span's start, where the patch changes) and
        # the corners
        ku = np.unique(surf.knots_u[(surf.knots_u > u0) & (surf.knots_u < u1)])
        kv = np.unique(surf.knots_v[(surf.knots_v > v0) & (surf.knots_v < v1)])
        u = np.concatenate([rng.uniform(u0, u1, n), ku, rng.uniform(u0, u1, len(kv)),
                            [u0, u1, u0, u1]])
        v = np.concatenate([rng.uniform(v0, v1, n), rng.uniform(v0, v1, len(ku)), kv,
                            [v0, v1, v1, v0]])
        ours = np.array(bspline.PowerPatches(surf).evaluate(u, v))
        ref = occ_derivatives(bs, u, v)
        for k, name in enumerate(NAMES):
            mag = max(1.0, np.abs(ref[k]).max())
            err = np.abs(ours[k] - ref[k]).max() / mag
            self.assertLess(err, 1e-9, "%s differs from OCC by %.3g (relative)" % (name, err))

    def test_random_polynomial(self):
        rng = np.random.default_rng(41)
        for trial, (p, q) in enumerate([(1, 1), (2, 3), (3, 3), (5, 2)]):
            bs, surf = random_surface(rng, rational=False, degree_u=p, degree_v=q, nu=8, nv=6)
            self.check(bs, surf, rng)

    def test_random_rational(self):
        rng = np.random.default_rng(42)
        for p, q in [(2, 2), (3, 2), (3, 3)]:
            bs, surf = random_surface(rng, rational=True, degree_u=p, degree_v=q)
            self.check(bs, surf, rng)

    def test_exact_nurbs_of_analytic_faces(self):
        rng = np.random.default_rng(43)
        for face in (Part.makeCylinder(2, 5).Faces[0], Part.makeSphere(3).Faces[0],
                     Part.makeTorus(10, 2).Faces[0]):
            bs = face.toNurbs().Faces[0].Surface
            self.check(bs, surface_data(bs, closed_u=bs.isUPeriodic()), rng, n=30)

    def test_large_batch_in_chunks(self):
        rng = np.random.default_rng(45)
        bs, surf = random_surface(rng, rational=True)
        u = rng.uniform(0, 1, bspline.CHUNK + 17)
        v = rng.uniform(0, 1, len(u))
        out = bspline.PowerPatches(surf).evaluate(u, v)
        pick = np.concatenate([rng.integers(0, len(u), 20), [len(u) - 1]])
        ref = occ_derivatives(bs, u[pick], v[pick])
        for k in range(6):
            self.assertEqual(out[k].shape, (len(u), 3))
            scale = max(1, np.abs(ref[k]).max())
            np.testing.assert_allclose(out[k][pick], ref[k], atol=1e-9 * scale)

    def test_single_point_and_broadcast(self):
        rng = np.random.default_rng(44)
        bs, surf = random_surface(rng, rational=True)
        patches = bspline.PowerPatches(surf)
        one = patches.evaluate(0.3, 0.7)
        row = patches.evaluate(np.full(4, 0.3), 0.7)
        ref = occ_derivatives(bs, [0.3], [0.7])
        for k in range(6):
            scale = max(1, np.abs(ref[k]).max())
            np.testing.assert_allclose(one[k][0], ref[k][0], atol=1e-9 * scale)
            np.testing.assert_array_equal(row[k], np.repeat(one[k], 4, axis=0))


if __name__ == "__main__":
    unittest.main()
