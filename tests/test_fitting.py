"""Sphere, plane and circle fits against points generated on known shapes (closed forms), and
against scipy's general least-squares minimiser of the same geometric distances."""
import unittest

import numpy as np
from scipy.optimize import least_squares

from BladeInspect.core import fitting
from BladeInspect.core.errors import InputError


def random_unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def basis(normal):
    e1 = np.cross(normal, [0.3, 0.5, 0.7])
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(normal, e1)


def sphere_cap(rng, center, radius, n, half_angle_deg, axis=(0, 0, 1)):
    """n points uniformly on a spherical cap around `axis`, exactly on the sphere."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    e1, e2 = basis(axis)
    cos_max = np.cos(np.radians(half_angle_deg))
    ct = rng.uniform(cos_max, 1.0, n)
    st = np.sqrt(1 - ct ** 2)
    ph = rng.uniform(0, 2 * np.pi, n)
    dirs = ct[:, None] * axis + st[:, None] * (np.cos(ph)[:, None] * e1 + np.sin(ph)[:, None] * e2)
    return center + radius * dirs, dirs


def circle_arc(rng, center, normal, radius, n, arc_deg):
    e1, e2 = basis(normal)
    t = np.radians(rng.uniform(0, arc_deg, n))
    return center + radius * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2)


class TestSphere(unittest.TestCase):
    def test_exact_points_give_exact_sphere(self):
        rng = np.random.default_rng(1)
        for _ in range(10):
            c, R = rng.uniform(-100, 100, 3), rng.uniform(1, 50)
            pts, _ = sphere_cap(rng, c, R, 50, rng.uniform(20, 180), random_unit(rng))
            fit = fitting.fit_sphere(pts)
            np.testing.assert_allclose(fit.center, c, atol=1e-8 * R)
            self.assertAlmostEqual(fit.radius, R, delta=1e-8 * R)
            fit_known = fitting.fit_sphere(pts, radius=R)
            np.testing.assert_allclose(fit_known.center, c, atol=1e-8 * R)

    def test_noisy_cap_matches_scipy_geometric_optimum(self):
        rng = np.random.default_rng(2)
        for _ in range(5):
            c, R = rng.uniform(-50, 50, 3), 12.5
            pts, dirs = sphere_cap(rng, c, R, 300, 45.0, random_unit(rng))
            pts += dirs * rng.normal(0, 0.002, len(pts))[:, None]
            w = rng.uniform(20, 100, len(pts))
            fit = fitting.fit_sphere(pts, weights=w)
            ref = least_squares(lambda x: np.sqrt(w) * (np.linalg.norm(pts - x[:3], axis=1) - x[3]),
                                np.r_[c + 0.5, R - 0.3], xtol=1e-15, ftol=1e-15, gtol=1e-15)
            np.testing.assert_allclose(fit.center, ref.x[:3], atol=1e-7)
            self.assertAlmostEqual(fit.radius, ref.x[3], delta=1e-7)
            known = fitting.fit_sphere(pts, radius=R, weights=w)
            ref_k = least_squares(lambda x: np.sqrt(w) * (np.linalg.norm(pts - x, axis=1) - R),
                                  c + 0.5, xtol=1e-15, ftol=1e-15, gtol=1e-15)
            np.testing.assert_allclose(known.center, ref_k.x, atol=1e-8)

    def test_covariance_matches_monte_carlo_scatter(self):
        # The stated covariance must describe the real scatter of the centre over repeats.
        rng = np.random.default_rng(3)
        c, R, sigma = np.array([10.0, -5.0, 30.0]), 12.5, 0.002
        errors, stds = [], []
        for _ in range(300):
            pts, dirs = sphere_cap(rng, c, R, 200, 40.0)
            pts += dirs * rng.normal(0, sigma, len(pts))[:, None]
            fit = fitting.fit_sphere(pts, radius=R)
            errors.append(fit.center - c)
            stds.append(np.sqrt(np.diag(fit.covariance)))
        ratio = np.std(errors, axis=0) / np.mean(stds, axis=0)
        self.assertTrue(np.all((ratio > 0.85) & (ratio < 1.15)), ratio)
        self.assertTrue(np.all(np.abs(np.mean(errors, axis=0)) < 4 * np.mean(stds, axis=0) / np.sqrt(300)))

    def test_known_radius_reduces_depth_error_on_a_cap(self):
        rng = np.random.default_rng(4)
        c, R = np.zeros(3), 12.5
        free, known = [], []
        for _ in range(50):
            pts, dirs = sphere_cap(rng, c, R, 150, 30.0)
            pts += dirs * rng.normal(0, 0.002, len(pts))[:, None]
            free.append(fitting.fit_sphere(pts).center[2])
            known.append(fitting.fit_sphere(pts, radius=R).center[2])
        self.assertLess(np.std(known) * 3, np.std(free))
        self.assertLess(np.sqrt(np.mean(np.square(known))), 0.0005)

    def test_zero_weight_outlier_is_ignored(self):
        rng = np.random.default_rng(5)
        c, R = np.array([1.0, 2.0, 3.0]), 5.0
        pts, _ = sphere_cap(rng, c, R, 40, 60.0)
        pts = np.vstack([pts, [[1.0, 2.0, 20.0]]])
        w = np.r_[np.ones(40), 0.0]
        np.testing.assert_allclose(fitting.fit_sphere(pts, weights=w).center, c, atol=1e-9)

    def test_bad_input(self):
        rng = np.random.default_rng(6)
        planar = np.column_stack([rng.uniform(size=(20, 2)), np.zeros(20)])
        for call in (lambda: fitting.fit_sphere(planar),
                     lambda: fitting.fit_sphere(np.zeros((3, 3))),
                     lambda: fitting.fit_sphere(np.zeros((10, 2))),
                     lambda: fitting.fit_sphere(np.full((10, 3), np.nan)),
                     lambda: fitting.fit_sphere(rng.normal(size=(10, 3)), radius=-1.0),
                     lambda: fitting.fit_sphere(rng.normal(size=(10, 3)), weights=np.zeros(10))):
            with self.assertRaises(InputError) as ctx:
                call()
            self.assertNotIn("\n", str(ctx.exception))


class TestPlane(unittest.TestCase):
    def test_noisy_plane_recovered(self):
        rng = np.random.default_rng(7)
        for _ in range(20):
            n, p0 = random_unit(rng), rng.uniform(-100, 100, 3)
            e1, e2 = basis(n)
            uv = rng.uniform(-20, 20, (500, 2))
            noise = rng.normal(0, 0.001, 500)
            pts = p0 + uv[:, :1] * e1 + uv[:, 1:] * e2 + noise[:, None] * n
            fit = fitting.fit_plane(pts)
            self.assertGreater(abs(fit.normal @ n), np.cos(1e-4))
            self.assertLess(abs((fit.point - p0) @ n), 1e-3)
            # The canonical sign: the largest component is positive.
            self.assertGreater(fit.normal[np.argmax(np.abs(fit.normal))], 0)
            np.testing.assert_allclose(np.abs(fit.residuals), np.abs(noise - noise.mean()), atol=5e-4)

    def test_collinear_is_an_error(self):
        pts = np.outer(np.linspace(0, 1, 10), [1.0, 2.0, 3.0])
        with self.assertRaises(InputError):
            fitting.fit_plane(pts)


class TestCircle(unittest.TestCase):
    def test_exact_arcs(self):
        rng = np.random.default_rng(8)
        for _ in range(20):
            c, n, R = rng.uniform(-100, 100, 3), random_unit(rng), rng.uniform(1, 80)
            pts = circle_arc(rng, c, n, R, 12, rng.uniform(60, 360))
            fit = fitting.fit_circle_3d(pts)
            np.testing.assert_allclose(fit.center, c, atol=1e-8 * R)
            self.assertGreater(abs(fit.normal @ n), 1 - 1e-12)
            self.assertAlmostEqual(fit.radius, R, delta=1e-8 * R)
            self.assertLess(fit.residuals.max(), 1e-8)

    def test_three_points_define_the_circle(self):
        c, n, R = np.array([1.0, 2.0, 3.0]), np.array([0.0, 1.0, 0.0]), 7.0
        pts = circle_arc(np.random.default_rng(0), c, n, R, 3, 200)
        fit = fitting.fit_circle_3d(pts)
        np.testing.assert_allclose(fit.center, c, atol=1e-9)

    def test_noisy_arc_matches_scipy_geometric_optimum(self):
        rng = np.random.default_rng(9)
        for _ in range(5):
            c, n, R = rng.uniform(-50, 50, 3), random_unit(rng), 40.0
            # Noise large enough, on a short arc, for the algebraic start to be visibly biased.
            pts = circle_arc(rng, c, n, R, 10, 120) + rng.normal(0, 0.02, (10, 3))
            fit = fitting.fit_circle_3d(pts)

            def dist(x):
                nn = x[3:6] / np.linalg.norm(x[3:6])
                v = pts - x[:3]
                h = v @ nn
                rho = np.linalg.norm(v - h[:, None] * nn, axis=1)
                return np.r_[h, rho - x[6], np.linalg.norm(x[3:6]) - 1.0]
            ref = least_squares(dist, np.r_[c + 0.2, n + 0.01, R + 0.1], xtol=1e-15,
                                ftol=1e-15, gtol=1e-15)
            nref = ref.x[3:6] / np.linalg.norm(ref.x[3:6])
            np.testing.assert_allclose(fit.center, ref.x[:3], atol=1e-7)
            self.assertGreater(abs(fit.normal @ nref), 1 - 1e-12)
            self.assertAlmostEqual(fit.radius, ref.x[6], delta=1e-7)
            # And close to the truth at the noise's scale.
            self.assertLess(np.linalg.norm(fit.center - c), 0.2)

    def test_collinear_is_an_error(self):
        pts = np.outer(np.linspace(0, 1, 10), [1.0, 2.0, 3.0])
        with self.assertRaises(InputError):
            fitting.fit_circle_3d(pts)


if __name__ == "__main__":
    unittest.main()
