"""The airfoil stage's speed-ups (issue 15, "all characteristics of five sections in under
1 s") against independent truth:

- Profile.closest remembers a point set's feet (whatever its order): the feet of points round
  a circle profile against the closed form (centre + r (p - c) / |p - c|), for the set, the same
  set permuted (served from the memory), a set one point off (not served from it), and after a
  caller wrote into the arrays it was given;
- max_error(bias_only=True), which runs only the sampled round the bias comes from: the bias of
  the largest of readings on a plateau, half of them pushed by a shared uniform term, against
  the expectation computed another way (order statistics of uniforms, sampled apart).
"""

import unittest

import numpy as np

from BladeInspect.core import airfoil
from BladeInspect.core import uncertainty_model


def _circle_profile(radius, n):
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return airfoil.Profile(radius * np.column_stack([np.cos(t), np.sin(t)]))


def _true_feet(points, radius):
    return radius * points / np.linalg.norm(points, axis=1)[:, None]


class RememberedFeet(unittest.TestCase):
    def setUp(self):
        self.radius = 7.0
        self.prof = _circle_profile(self.radius, 2000)
        rng = np.random.default_rng(11)
        phi = rng.uniform(0.0, 2 * np.pi, 300)
        rho = self.radius + rng.uniform(-0.05, 0.05, len(phi))
        self.pts = rho[:, None] * np.column_stack([np.cos(phi), np.sin(phi)])
        # the interpolating spline of 2000 points is the circle to ~1e-9 of its radius
        self.tol = 1e-7

    def _check(self, pts, foot, u):
        self.assertLess(np.abs(foot - _true_feet(pts, self.radius)).max(), self.tol)
        self.assertLess(np.abs(self.prof.eval(u) - foot).max(), 1e-12)

    def test_feet_of_a_set_and_of_the_set_permuted(self):
        u1, f1 = self.prof.closest(self.pts)
        self._check(self.pts, f1, u1)
        perm = np.random.default_rng(5).permutation(len(self.pts))
        u2, f2 = self.prof.closest(self.pts[perm])
        self.assertGreater(len(self.prof._memo), 0)
        self._check(self.pts[perm], f2, u2)
        # the same feet, in the order asked, to the bit
        np.testing.assert_array_equal(u2, u1[perm])
        np.testing.assert_array_equal(f2, f1[perm])

    def test_another_set_is_not_served_the_remembered_feet(self):
        self.prof.closest(self.pts)
        other = self.pts.copy()
        other[17] *= 0.99             # one point moved inward by 1 %
        u, f = self.prof.closest(other)
        self._check(other, f, u)

    def test_a_caller_writing_into_its_feet_does_not_change_the_memory(self):
        u, f = self.prof.closest(self.pts)
        u[:] = 0.0
        f[:] = 0.0
        u2, f2 = self.prof.closest(self.pts)
        self._check(self.pts, f2, u2)
        u2[:] = -1.0
        u3, f3 = self.prof.closest(self.pts[::-1])
        self._check(self.pts[::-1], f3, u3)


class BiasOnly(unittest.TestCase):
    def test_bias_of_a_plateau_with_a_shared_push(self):
        n, sigma, a, level = 50, 0.002, 0.006, 1.0
        dev = np.full(n, level)
        # half the readings are pushed by one shared z ~ U(-a, a), half not at all
        coef = (np.arange(n) % 2).astype(float)
        shared = [uncertainty_model.SharedTerm("push", coef,
                                               lambda rng, k: rng.uniform(-a, a, (k, 1)))]
        terms, bias, competitors = uncertainty_model.max_error(
            dev, np.full(n, sigma), shared=shared, bias_only=True)
        self.assertEqual(terms, {})
        self.assertEqual(competitors, n)
        # The readings lie far from zero: the largest less the plateau is max(X, z + Y), X and
        # Y the largest noise of each half (25 uniforms of sigma each), whatever the level.
        rng = np.random.default_rng(123)
        m, half = 400000, n // 2
        w = np.sqrt(3.0) * sigma

        def largest(k):
            return w * (2.0 * rng.uniform(size=k) ** (1.0 / half) - 1.0)
        expected = np.mean(np.maximum(largest(m), rng.uniform(-a, a, m) + largest(m)))
        # 1000 draws: the sampled mean's standard error is ~6e-5 mm here
        self.assertAlmostEqual(bias, expected, delta=3e-4)
        # and far from the noise-only bias (the round without the push)
        noise_only = w * (n - 1.0) / (n + 1.0)
        self.assertGreater(abs(expected - noise_only), 1e-3)
        # the full call's bias is the same number
        _, full_bias, _ = uncertainty_model.max_error(dev, np.full(n, sigma), shared=shared)
        self.assertEqual(bias, full_bias)


if __name__ == "__main__":
    unittest.main()
