"""The airfoil kernel's faster numerics (issue 15, "all characteristics of five sections in
under 1 s") against independent truth: the Newton circle fit against scipy's least-squares
solver on random noisy arcs, the edge zone's bounds against the closed form on a circle, both
when the zone lies round the edge point and when it takes the whole-loop scan."""

import unittest

import numpy as np
from scipy.optimize import least_squares

from BladeInspect.core import airfoil
from BladeInspect.core.airfoil.edges import _zone_range


class CircleFit(unittest.TestCase):
    def test_agrees_with_an_independent_least_squares_solver(self):
        rng = np.random.default_rng(7)
        for _ in range(40):
            radius = rng.uniform(0.05, 3.0)
            centre = rng.uniform(-50.0, 50.0, 2)
            half = np.radians(rng.uniform(20.0, 180.0))
            t = rng.uniform(-half, half, int(rng.integers(12, 400))) + rng.uniform(0, 2 * np.pi)
            rho = radius + rng.normal(0.0, rng.choice([1e-4, 3.5e-3, 0.02]) * radius, len(t))
            xy = centre + rho[:, None] * np.column_stack([np.cos(t), np.sin(t)])
            c, r, rms = airfoil.fit_circle_2d(xy)

            def residual(x):
                return np.linalg.norm(xy - x[:2], axis=1) - x[2]
            ref = least_squares(residual, np.append(centre, radius), xtol=1e-15, ftol=1e-15,
                                gtol=1e-15, method="lm")
            # scipy stops with a gradient of ~1e-8: the same circle to its own precision, and
            # no better a fit than this one (the sum of squares at least as small).
            self.assertLess(abs(r - ref.x[2]), 1e-7 * max(1.0, radius))
            self.assertLess(np.linalg.norm(c - ref.x[:2]), 1e-7 * max(1.0, radius))
            ours = np.sum(residual(np.append(c, r)) ** 2)
            self.assertLessEqual(ours, np.sum(residual(ref.x) ** 2) * (1 + 1e-12))
            self.assertAlmostEqual(rms, float(np.sqrt(ours / len(xy))), delta=1e-12)


class EdgeZone(unittest.TestCase):
    def _circle(self, radius, n):
        t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
        return airfoil.Profile(radius * np.column_stack([np.cos(t), np.sin(t)]))

    def test_bounds_are_where_the_zone_rays_cross_the_circle(self):
        # Seen from the centre, the zone's bounds are at +-zone_deg round the outward
        # direction: arc length r * zone angle either side of the edge point.
        rng = np.random.default_rng(3)
        for radius, zone_deg in ((0.3, 45.0), (5.0, 30.0), (40.0, 170.0)):
            prof = self._circle(radius, 720)
            for _ in range(5):
                phi = rng.uniform(0.0, 2 * np.pi)
                outward = np.array([np.cos(phi), np.sin(phi)])
                u_edge = prof.closest(radius * outward)[0][0]
                lo, hi = _zone_range(prof, np.zeros(2), outward, u_edge, zone_deg)
                half = np.radians(zone_deg) * prof.length / (2 * np.pi)
                # the parameter is the spline's chord length, the arc length to ~1e-7 r here
                for got, want in ((lo, u_edge - half), (hi, u_edge + half)):
                    p = prof.eval([got])[0]
                    angle = np.degrees(np.arccos(np.clip(p @ outward / np.linalg.norm(p), -1, 1)))
                    self.assertAlmostEqual(angle, zone_deg, delta=1e-6)
                    self.assertAlmostEqual(got, want, delta=1e-5 * radius)

    def test_a_zone_of_the_whole_loop_is_refused(self):
        prof = self._circle(1.0, 360)
        # seen from far behind, every point of the circle is within 60 deg of +x
        with self.assertRaises(Exception):
            _zone_range(prof, np.array([-1e4, 0.0]), np.array([1.0, 0.0]), 0.0, 60.0)


if __name__ == "__main__":
    unittest.main()
