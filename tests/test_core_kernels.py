"""The numeric kernels of core.closest and core.raycast on their own, without FreeCAD: a
parabolic cylinder z = x^2 (|x| <= 1, 0 <= y <= 1) built as an exact quadratic B-spline in
numpy, its own samples and a numpy triangle mesh of it, against closed forms (a point at height
h along the normal from a foot point is at signed distance h; a ray meets z = x^2 at the smaller
root of a quadratic)."""
import unittest

import numpy as np

from BladeInspect.core import bspline, closest, raycast
from BladeInspect.core.trim import TrimDomain


def parabolic_cylinder():
    """z = x^2 with x = 2u - 1, y = v; outward (Su x Sv) is +z at the vertex."""
    poles = np.array([[[-1.0, 0.0, 1.0], [-1.0, 1.0, 1.0]],
                      [[0.0, 0.0, -1.0], [0.0, 1.0, -1.0]],
                      [[1.0, 0.0, 1.0], [1.0, 1.0, 1.0]]])
    return bspline.SurfaceData(degree_u=2, degree_v=1, knots_u=[0, 0, 0, 1, 1, 1],
                               knots_v=[0, 0, 1, 1], poles=poles, weights=None,
                               u_range=[0.0, 1.0], v_range=[0.0, 1.0])


def unit_normal(x):
    n = np.column_stack([-2.0 * x, np.zeros(len(x)), np.ones(len(x))])
    return n / np.linalg.norm(n, axis=1)[:, None]


def face_set(domain, n=60):
    surf = parabolic_cylinder()
    u, v = np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n, indexing="ij")
    uv = np.column_stack([u.ravel(), v.ravel()])
    if domain.index is not None:
        uv = uv[closest.point_in_domain(domain, uv)[0]]
    S, Su, Sv = bspline.evaluate(surf, uv[:, 0], uv[:, 1], order=1)
    nrm = np.cross(Su, Sv)
    area = np.linalg.norm(nrm, axis=1)
    samples = closest.Samples(xyz=S, normal=nrm / area[:, None], face=np.zeros(len(S), int),
                              uv=uv, weight=area / n ** 2)
    return closest.FaceSet([surf], [domain], [False], samples)


def points_off(rng, n, x_range, y_range, height=0.05):
    """(points, foot x, foot y, signed height) along the normal from random foot points."""
    x = rng.uniform(*x_range, n)
    y = rng.uniform(*y_range, n)
    h = rng.uniform(-height, height, n)
    foot = np.column_stack([x, y, x * x])
    return foot + h[:, None] * unit_normal(x), x, y, h


def square_domain(lo, hi):
    c = np.array([[lo, lo], [hi, lo], [hi, hi], [lo, hi], [lo, lo]])
    return closest.FaceDomain(TrimDomain(np.stack([c[:-1], c[1:]], axis=1)), 1e-6, None)


class ClosestKernel(unittest.TestCase):
    def test_untrimmed_points_are_decided_exactly(self):
        fs = face_set(closest.FaceDomain(None, 0.0, None))
        rng = np.random.default_rng(3)
        # 70,000 points: three chunks on the two threads.
        p, x, y, h = points_off(rng, 70000, (-0.8, 0.8), (0.1, 0.9))
        out, undecided = fs.closest(p)
        self.assertEqual(len(undecided), 0)
        np.testing.assert_allclose(out.distance, h, atol=1e-9)
        np.testing.assert_allclose(out.closest, np.column_stack([x, y, x * x]), atol=1e-8)
        # The normal is the one of Newton's last evaluated iterate, not of the foot point it
        # steps to: good to ~1e-5 here, where the foot point is good to 1e-9.
        np.testing.assert_allclose(out.normal, unit_normal(x), atol=1e-4)
        np.testing.assert_allclose(out.uv, np.column_stack([(x + 1) / 2, y]), atol=1e-8)
        self.assertFalse(out.fallback.any())

    def test_trimmed_face_leaves_feet_outside_its_domain_undecided(self):
        fs = face_set(square_domain(0.25, 0.75))
        rng = np.random.default_rng(4)
        p, x, y, h = points_off(rng, 4000, (-1.0, 1.0), (0.0, 1.0), height=0.02)
        u = (x + 1) / 2
        out, undecided = fs.closest(p)
        decided = np.ones(len(p), bool)
        decided[undecided] = False
        # A foot outside the trimmed square is not on this face: never decided.
        outside = (np.minimum(u, y) < 0.25) | (np.maximum(u, y) > 0.75)
        self.assertFalse(np.any(decided & outside))
        # Feet well inside: all decided, exactly.
        inner = (np.minimum(u, y) > 0.3) & (np.maximum(u, y) < 0.7)
        self.assertTrue(np.all(decided[inner]))
        np.testing.assert_allclose(out.distance[decided], h[decided], atol=1e-9)

    def test_parameters_of_exact_closest_points(self):
        fs = face_set(closest.FaceDomain(None, 0.0, None))
        rng = np.random.default_rng(5)
        x, y = rng.uniform(-0.9, 0.9, 300), rng.uniform(0.05, 0.95, 300)
        foot = np.column_stack([x, y, x * x])
        rows = np.arange(0, 300, 2)
        uv = fs.parameters_of(foot, np.zeros(300, int), rows)
        np.testing.assert_allclose(uv, np.column_stack([(x[rows] + 1) / 2, y[rows]]), atol=1e-9)


def mesh(surf, nu=41, nv=11):
    u, v = np.meshgrid(np.linspace(0, 1, nu), np.linspace(0, 1, nv), indexing="ij")
    (xyz,) = bspline.evaluate(surf, u.ravel(), v.ravel(), order=0)
    k = np.arange(nu * nv).reshape(nu, nv)
    a, b, c, d = k[:-1, :-1].ravel(), k[1:, :-1].ravel(), k[1:, 1:].ravel(), k[:-1, 1:].ravel()
    return xyz, np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])


def parabola_hit(o, d):
    """Smallest t >= 0 with o + t d on z = x^2 (NaN when none)."""
    A = d[:, 0] ** 2
    B = 2 * o[:, 0] * d[:, 0] - d[:, 2]
    C = o[:, 0] ** 2 - o[:, 2]
    disc = np.sqrt(B * B - 4 * A * C)
    roots = np.stack([(-B - disc) / (2 * A), (-B + disc) / (2 * A)], axis=1)
    roots = np.where(roots >= 0, roots, np.inf)
    return roots.min(axis=1)


class RaycastKernel(unittest.TestCase):
    def test_rays_from_both_sides_and_misses(self):
        fs = face_set(closest.FaceDomain(None, 0.0, None))
        xyz, tris = mesh(fs.surfaces[0])
        tess = raycast.Tessellation(fs, [(0, xyz, tris)], deflection=1e-3)
        rng = np.random.default_rng(6)
        n = 2000
        x0, y0 = rng.uniform(-0.6, 0.6, n), rng.uniform(0.2, 0.8, n)
        down = rng.random(n) < 0.5
        o = np.column_stack([x0, y0, np.where(down, 3.0, -2.0)])
        # Not unit directions: t is in units of |d|.
        d = np.column_stack([rng.uniform(-0.1, 0.1, n), rng.uniform(-0.05, 0.05, n),
                             np.where(down, -1.0, 1.0)]) * rng.uniform(0.5, 2.0, n)[:, None]
        miss_o = np.column_stack([rng.uniform(1.2, 2.0, 50), rng.uniform(0, 1, 50),
                                  np.full(50, 5.0)])
        miss_d = np.tile([0.0, 0.0, -1.0], (50, 1))
        calls = []

        def exact_ray(o1, d1, t_far):
            calls.append(o1)
            return np.nan, -1, np.full(3, np.nan)
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (0, 1) for z in (0, 1)], float)
        t, face, nrm = raycast.cast(fs, tess, corners, np.vstack([o, miss_o]),
                                    np.vstack([d, miss_d]), exact_ray)
        self.assertEqual(calls, [])
        np.testing.assert_allclose(t[:n], parabola_hit(o, d), atol=1e-9)
        self.assertTrue(np.all(face[:n] == 0))
        hit = o + t[:n, None] * d
        np.testing.assert_allclose(nrm[:n], unit_normal(hit[:, 0]), atol=1e-8)
        self.assertTrue(np.all(np.isnan(t[n:])) and np.all(face[n:] == -1))

    def test_bad_rays_are_refused(self):
        from BladeInspect.core.errors import InputError
        with self.assertRaises(InputError):
            raycast.check_rays(np.zeros((2, 3)), np.zeros((2, 3)))
        with self.assertRaises(InputError):
            raycast.check_rays(np.zeros((2, 3)), np.ones((3, 3)))


def star_segments(rng, n=1500, lobes=7):
    """A non-convex closed star in (u, v), stretched 1:40 like a blade side's parameters,
    its segments in shuffled order and random direction."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 1.0 + 0.4 * np.sin(lobes * t)
    p = np.column_stack([r * np.cos(t), 40.0 * r * np.sin(t)])
    seg = np.stack([p, np.roll(p, -1, axis=0)], axis=1)
    flip = rng.random(n) < 0.5
    seg[flip] = seg[flip][:, ::-1]
    return seg[rng.permutation(n)]


def brute_force(seg, q):
    """Even-odd count over every segment and the distance to every segment."""
    a, b = seg[:, 0][None], seg[:, 1][None]
    p = q[:, None]
    straddle = (a[..., 1] > p[..., 1]) != (b[..., 1] > p[..., 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        x = a[..., 0] + (p[..., 1] - a[..., 1]) * (b[..., 0] - a[..., 0]) / (b[..., 1] - a[..., 1])
    inside = np.count_nonzero(straddle & (p[..., 0] < x), axis=1) % 2 == 1
    ab, ap = b - a, p - a
    t = np.clip(np.sum(ap * ab, axis=2) / np.sum(ab * ab, axis=2), 0.0, 1.0)
    d = np.linalg.norm(ap - t[..., None] * ab, axis=2).min(axis=1)
    return inside, d


class TrimDomainQueries(unittest.TestCase):
    def test_against_every_segment(self):
        rng = np.random.default_rng(9)
        seg = star_segments(rng)
        dom = TrimDomain(seg)
        vertices = seg[:, 0]
        q = np.vstack([rng.uniform([-1.6, -64], [1.6, 64], (1500, 2)),
                       vertices[:300], vertices[:300] + [0.0, 1e-12],
                       vertices[:300] + rng.normal(0, 1e-3, (300, 2))])
        inside, dist = dom.query(q)
        want_inside, want_dist = brute_force(seg, q)
        np.testing.assert_array_equal(inside, want_inside)
        near = want_dist < dom.reach
        np.testing.assert_allclose(dist[near], want_dist[near], rtol=0, atol=1e-12)
        self.assertTrue(np.all(dist[~near] == dom.reach))
        self.assertTrue(np.all(dist <= dom.reach))


if __name__ == "__main__":
    unittest.main()
