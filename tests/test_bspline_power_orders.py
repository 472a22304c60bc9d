"""The power-basis evaluation Newton's projection runs on (SurfaceData.power_patches) against
OpenCASCADE, at every order it is asked for (0, 1 and 2): random polynomial and rational
surfaces of degrees 1 to 5 with uneven and repeated knots, a periodic one, at random
parameters, at every knot (each side of a span boundary) and at the box's ends, compared with
Part.BSplineSurface.value/getDN to 1e-9 relative."""
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect.core import bspline
from tests.test_bspline import occ_derivatives, random_surface, surface_data

V = FreeCAD.Vector
NAMES = ["S", "Su", "Sv", "Suu", "Suv", "Svv"]


def parameters(rng, surf, n=40):
    """Random pairs, each distinct knot against a random other parameter, and the corners."""
    (u0, u1), (v0, v1) = surf.u_range, surf.v_range
    ku = np.unique(surf.knots_u[(surf.knots_u >= u0) & (surf.knots_u <= u1)])
    kv = np.unique(surf.knots_v[(surf.knots_v >= v0) & (surf.knots_v <= v1)])
    u = np.concatenate([rng.uniform(u0, u1, n), ku, rng.uniform(u0, u1, len(kv)),
                        [u0, u1, u0, u1]])
    v = np.concatenate([rng.uniform(v0, v1, n), rng.uniform(v0, v1, len(ku)), kv,
                        [v0, v1, v1, v0]])
    return u, v


class PowerFormAgainstOCC(unittest.TestCase):
    def check(self, bs, surf, rng):
        u, v = parameters(rng, surf)
        ref = occ_derivatives(bs, u, v)
        for order, count in ((0, 1), (1, 3), (2, 6)):
            ours = surf.power_patches().evaluate(u, v, order=order)
            self.assertEqual(len(ours), count)
            for k in range(count):
                mag = max(1.0, np.abs(ref[k]).max())
                err = np.abs(ours[k] - ref[k]).max() / mag
                self.assertLess(err, 1e-9, "order %d: %s differs from OCC by %.3g (relative)"
                                % (order, NAMES[k], err))

    def test_random_polynomial(self):
        rng = np.random.default_rng(141)
        for p, q in [(1, 2), (2, 1), (3, 3), (4, 2), (5, 3)]:
            for trial in range(3):
                bs, surf = random_surface(rng, rational=False, degree_u=p, degree_v=q,
                                          nu=p + 5, nv=q + 4)
                self.check(bs, surf, rng)

    def test_random_rational(self):
        rng = np.random.default_rng(142)
        for p, q in [(1, 1), (2, 2), (3, 2), (3, 3), (5, 2)]:
            for trial in range(3):
                bs, surf = random_surface(rng, rational=True, degree_u=p, degree_v=q,
                                          nu=p + 5, nv=q + 4)
                self.check(bs, surf, rng)

    def test_periodic(self):
        """A periodic surface (OCC's own periodic form) stored non-periodic over one period."""
        rng = np.random.default_rng(143)
        for rational in (False, True):
            bs, _ = random_surface(rng, rational=rational, degree_u=3, degree_v=2, nu=8, nv=5)
            bs.setUPeriodic()
            self.assertTrue(bs.isUPeriodic())
            self.check(bs, surface_data(bs, closed_u=True), rng)

    def test_cached_and_reused(self):
        rng = np.random.default_rng(144)
        _, surf = random_surface(rng, rational=True)
        self.assertIs(surf.power_patches(), surf.power_patches())

    def test_projection_distance_matches_occ(self):
        """project_points (Newton on the power form) from perturbed starts: every point
        converges, and its distance is OCC's distance to the surface to 1e-7 mm."""
        rng = np.random.default_rng(145)
        for rational in (False, True):
            bs, surf = random_surface(rng, rational=rational)
            u, v = rng.uniform(0.05, 0.95, 200), rng.uniform(0.05, 0.95, 200)
            S, Su, Sv = bspline.evaluate(surf, u, v, order=1)
            n = np.cross(Su, Sv)
            n /= np.linalg.norm(n, axis=1)[:, None]
            pts = S + rng.uniform(-2, 2, (200, 1)) * n
            start_u = np.clip(u + rng.normal(0, 0.03, 200), 0, 1)
            start_v = np.clip(v + rng.normal(0, 0.03, 200), 0, 1)
            fu, fv, foot, conv = bspline.project_points(surf, pts, start_u, start_v)
            self.assertTrue(conv.all())
            for i in range(0, 200, 10):
                d = bs.toShape().distToShape(Part.Vertex(V(*pts[i])))[0]
                self.assertAlmostEqual(np.linalg.norm(foot[i] - pts[i]), d, delta=1e-7)


if __name__ == "__main__":
    unittest.main()
