"""core.bspline against OpenCASCADE: values and first/second derivatives of random polynomial
and rational B-spline surfaces (and exact NURBS forms of revolved, cylindrical and spherical
faces) compared with Part.BSplineSurface.value/getDN; projections compared with OCC's own
Surface.projectPoint."""
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect.core import bspline
from BladeInspect.core.bspline import SurfaceData
from BladeInspect.core.trim import TrimDomain

V = FreeCAD.Vector


def random_surface(rng, rational, degree_u=3, degree_v=2, nu=7, nv=5, periodic_u=False):
    """A random Part.BSplineSurface (wavy grid of poles, uneven knots, random weights) and the
    same data as SurfaceData, built independently from the arrays given to OCC."""
    x, y = np.meshgrid(np.linspace(0, 30, nu), np.linspace(0, 20, nv), indexing="ij")
    # gentle enough (curvature radii above ~10 mm) that a point 5 mm off has one foot point
    poles = np.dstack([x + rng.normal(0, 0.3, x.shape), y + rng.normal(0, 0.3, x.shape),
                       rng.normal(0, 0.7, x.shape)])
    weights = rng.uniform(0.5, 2.0, (nu, nv)) if rational else np.ones((nu, nv))

    def knots(n, p):
        inner = np.sort(rng.uniform(0.1, 0.9, n - p - 1))
        # one repeated interior knot where possible, to exercise multiplicity
        if n - p - 1 >= 3 and p >= 2:
            inner[2] = inner[1]
        k, m = np.unique(np.round(inner, 12), return_counts=True)
        return [0.0] + list(k) + [1.0], [p + 1] + list(m) + [p + 1]

    ku, mu = knots(nu, degree_u)
    kv, mv = knots(nv, degree_v)
    bs = Part.BSplineSurface()
    bs.buildFromPolesMultsKnots([[V(*p) for p in row] for row in poles], mu, mv, ku, kv,
                                False, False, degree_u, degree_v, weights.tolist())
    surf = SurfaceData(degree_u, degree_v, np.repeat(ku, mu), np.repeat(kv, mv), poles,
                       weights if rational else None, (0.0, 1.0), (0.0, 1.0))
    return bs, surf


def occ_derivatives(bs, u, v):
    vec = lambda p: [p.x, p.y, p.z]
    rows = []
    for a, b in zip(u, v):
        rows.append([vec(bs.value(a, b)), vec(bs.getDN(a, b, 1, 0)), vec(bs.getDN(a, b, 0, 1)),
                     vec(bs.getDN(a, b, 2, 0)), vec(bs.getDN(a, b, 1, 1)), vec(bs.getDN(a, b, 0, 2))])
    return np.array(rows).transpose(1, 0, 2)      # (6, N, 3)


def surface_data(bs, closed_u=False):
    """SurfaceData straight from OCC's arrays (periodic made non-periodic on a copy)."""
    bs = bs.copy()
    if bs.isUPeriodic():
        bs.setUNotPeriodic()
    if bs.isVPeriodic():
        bs.setVNotPeriodic()
    poles = np.array([[[p.x, p.y, p.z] for p in row] for row in bs.getPoles()])
    u0, u1, v0, v1 = bs.bounds()
    return SurfaceData(bs.UDegree, bs.VDegree, np.repeat(bs.getUKnots(), bs.getUMultiplicities()),
                       np.repeat(bs.getVKnots(), bs.getVMultiplicities()), poles,
                       np.array(bs.getWeights()), (u0, u1), (v0, v1), closed_u=closed_u)


class EvaluateAgainstOCC(unittest.TestCase):
    def check(self, bs, surf, rng, n=60, scale=1.0):
        u0, u1 = surf.u_range
        v0, v1 = surf.v_range
        u = np.concatenate([rng.uniform(u0, u1, n), [u0, u1, u0, u1]])
        v = np.concatenate([rng.uniform(v0, v1, n), [v0, v1, v1, v0]])
        ours = np.array(bspline.evaluate(surf, u, v, order=2))
        ref = occ_derivatives(bs, u, v)
        for k, name in enumerate(["S", "Su", "Sv", "Suu", "Suv", "Svv"]):
            mag = max(1.0, np.abs(ref[k]).max())
            err = np.abs(ours[k] - ref[k]).max() / mag
            self.assertLess(err, 1e-9, "%s differs from OCC by %.3g (relative)" % (name, err))

    def test_random_polynomial(self):
        rng = np.random.default_rng(1)
        for trial in range(4):
            bs, surf = random_surface(rng, rational=False, degree_u=1 + trial, degree_v=3 - trial % 2)
            self.check(bs, surf, rng)

    def test_random_rational(self):
        rng = np.random.default_rng(2)
        for trial in range(4):
            bs, surf = random_surface(rng, rational=True, degree_u=2 + trial % 2, degree_v=2 + trial // 2)
            self.check(bs, surf, rng)

    def test_order_0_and_1_agree_with_order_2(self):
        rng = np.random.default_rng(3)
        _, surf = random_surface(rng, rational=True)
        u, v = rng.uniform(0, 1, 50), rng.uniform(0, 1, 50)
        full = bspline.evaluate(surf, u, v, order=2)
        (S,) = bspline.evaluate(surf, u, v, order=0)
        S1, Su, Sv = bspline.evaluate(surf, u, v, order=1)
        np.testing.assert_allclose(S, full[0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(S1, full[0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(Su, full[1], rtol=0, atol=1e-11)

    def test_exact_nurbs_of_analytic_faces(self):
        """Surface of revolution, cylinder, sphere, torus through Face.toNurbs (rational,
        periodic made non-periodic): same values and derivatives as OCC's B-spline, and every
        point on the original analytic surface."""
        rng = np.random.default_rng(4)
        profile = Part.BSplineCurve()
        profile.interpolate([V(3, 0, 0), V(4, 0, 2), V(3.5, 0, 4), V(5, 0, 6)])
        faces = [profile.toShape().revolve(V(0, 0, 0), V(0, 0, 1), 360),
                 Part.makeCylinder(2, 5).Faces[0], Part.makeSphere(3).Faces[0],
                 Part.makeTorus(10, 2).Faces[0]]
        for face in faces:
            bs = face.toNurbs().Faces[0].Surface
            surf = surface_data(bs, closed_u=bs.isUPeriodic())
            self.check(bs, surf, rng, n=30)
            u = rng.uniform(*surf.u_range, 30)
            v = rng.uniform(*surf.v_range, 30)
            (S,) = bspline.evaluate(surf, u, v, order=0)
            for p in S:
                d = face.Surface.projectPoint(V(*p), "LowerDistance")
                self.assertLess(d, 1e-9)

    def test_evaluate_large_batch_chunks(self):
        rng = np.random.default_rng(5)
        bs, surf = random_surface(rng, rational=True)
        u = rng.uniform(0, 1, bspline.CHUNK + 17)
        v = rng.uniform(0, 1, len(u))
        S, Su, Sv = bspline.evaluate(surf, u, v)
        pick = rng.integers(0, len(u), 20)
        ref = occ_derivatives(bs, u[pick], v[pick])
        np.testing.assert_allclose(S[pick], ref[0], atol=1e-9)
        np.testing.assert_allclose(Sv[pick], ref[2], atol=1e-8)


class ProjectAgainstOCC(unittest.TestCase):
    def test_projection_matches_projectPoint(self):
        """Random points 0.01-5 mm off random rational surfaces, starts half a parameter
        percent off (Newton is local: the start must lie in the foot point's basin): the foot
        point equals OCC's LowerDistance projection within 1e-6 mm."""
        rng = np.random.default_rng(6)
        for trial in range(3):
            bs, surf = random_surface(rng, rational=trial > 0)
            n = 60
            u = rng.uniform(0.05, 0.95, n)
            v = rng.uniform(0.05, 0.95, n)
            S, Su, Sv = bspline.evaluate(surf, u, v)
            nrm = np.cross(Su, Sv)
            nrm /= np.linalg.norm(nrm, axis=1)[:, None]
            off = rng.choice([-1, 1], n) * 10 ** rng.uniform(-2, np.log10(5), n)
            p = S + off[:, None] * nrm
            pu, pv, c, conv = bspline.project_points(surf, p, u + rng.normal(0, 0.005, n),
                                                     v + rng.normal(0, 0.005, n))
            self.assertTrue(conv.all())
            for i in range(n):
                ref = bs.value(*bs.projectPoint(V(*p[i]), "LowerDistanceParameters"))
                d_ref = bs.projectPoint(V(*p[i]), "LowerDistance")
                self.assertAlmostEqual(np.linalg.norm(p[i] - c[i]), d_ref, delta=1e-6)
                self.assertLess(np.linalg.norm(c[i] - np.array(ref)), 1e-6)

    def test_clamped_at_bounds(self):
        """Points beyond the patch project onto its boundary: the clamped Newton result is the
        closest point of the boundary curve (checked against OCC's distance to the face)."""
        rng = np.random.default_rng(7)
        bs, surf = random_surface(rng, rational=True)
        face = bs.toShape()
        n = 40
        u = rng.choice([-0.2, 1.2], n) + rng.normal(0, 0.02, n)
        v = rng.uniform(0.1, 0.9, n)
        # points off the u-ends along the surface's own extension
        S, Su, _ = bspline.evaluate(surf, np.clip(u, 0, 1), v)
        p = S + (u - np.clip(u, 0, 1))[:, None] * Su + rng.normal(0, 0.5, (n, 3))
        pu, pv, c, conv = bspline.project_points(surf, p, np.clip(u, 0, 1) + rng.normal(0, 0.03, n),
                                                 v + rng.normal(0, 0.03, n))
        self.assertTrue(conv.all())
        for i in range(n):
            d, pairs, _ = face.distToShape(Part.Vertex(V(*p[i])))
            self.assertAlmostEqual(np.linalg.norm(p[i] - c[i]), d, delta=1e-6)

    def test_seam_wraps_on_closed_surface(self):
        """A cylinder's NURBS face is closed in u: a start on one side of the seam reaches the
        foot point on the other side instead of stopping at the bound."""
        face = Part.makeCylinder(2, 5).Faces[0]
        bs = face.toNurbs().Faces[0].Surface
        surf = surface_data(bs, closed_u=True)
        ang = np.radians(-3.0)
        p = np.array([[3 * np.cos(ang), 3 * np.sin(ang), 2.5]])
        pu, pv, c, conv = bspline.project_points(surf, p, [0.05], [2.0])
        np.testing.assert_allclose(c[0], [2 * np.cos(ang), 2 * np.sin(ang), 2.5], atol=1e-9)
        self.assertTrue(conv[0])


class TrimDomainAgainstClosedForm(unittest.TestCase):
    def test_square_with_round_hole(self):
        rng = np.random.default_rng(8)
        t = np.linspace(0, 2 * np.pi, 721)
        circle = np.column_stack([5 + 2 * np.cos(t), 5 + 2 * np.sin(t)])
        square = np.array([[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]], float)
        segs = np.concatenate([np.stack([c[:-1], c[1:]], axis=1) for c in (circle, square[::-1])])
        dom = TrimDomain(segs)
        uv = rng.uniform(-2, 12, (5000, 2))
        inside, dist = dom.query(uv)
        r = np.linalg.norm(uv - 5, axis=1)
        in_square = np.all((uv > 0) & (uv < 10), axis=1)
        expected = in_square & (r > 2)
        d_circle = np.abs(r - 2)
        outside_gap = np.linalg.norm(np.maximum(0, np.maximum(-uv, uv - 10)), axis=1)
        d_square = np.where(in_square, np.min(np.column_stack([uv, 10 - uv]), axis=1), outside_gap)
        true_d = np.minimum(d_circle, d_square)
        sure = true_d > 1e-3
        np.testing.assert_array_equal(inside[sure], expected[sure])
        near = true_d < dom.reach * 0.99
        # polygonal circle: chord error of 720 segments of radius 2 is 2*(1-cos(pi/720)) ~ 2e-5
        np.testing.assert_allclose(dist[near], true_d[near], atol=3e-5)
        self.assertTrue(np.all(dist[~near] <= true_d[~near] + 3e-5))


if __name__ == "__main__":
    unittest.main()
