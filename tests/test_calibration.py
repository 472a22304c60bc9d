"""Rotary-axis calibration with a reference sphere: the analytic sphere part, the axis from
centres turned about a known axis (closed form), and the whole calibration on the simulated
rig with injected axis offset and tilt, judged against the injected truth."""
import json
import os
import tempfile
import unittest

import numpy as np

from BladeInspect.core.errors import InputError
from BladeInspect.rig import calibration as cal


def rodrigues(points, angle_deg, point, direction):
    """Independent turn about a line (Rodrigues' vector form, not a matrix)."""
    k = np.asarray(direction, float) / np.linalg.norm(direction)
    v = np.atleast_2d(points) - point
    a = np.radians(angle_deg)
    return (point + v * np.cos(a) + np.cross(k, v) * np.sin(a)
            + np.outer(v @ k, k) * (1 - np.cos(a)))


def tilted_axis(tilt_z_deg, tilt_x_deg):
    """+Y leaned by the two tilts: towards +X (about Z) and towards +Z (about X)."""
    d = np.array([np.tan(np.radians(tilt_z_deg)), 1.0, np.tan(np.radians(tilt_x_deg))])
    return d / np.linalg.norm(d)


class TestSpherePart(unittest.TestCase):
    def test_raycast_closed_form(self):
        rng = np.random.default_rng(0)
        c, R = np.array([3.0, -2.0, 5.0]), 12.5
        part = cal.SpherePart(R, c)
        # Vertical rays at random x, y: the hit height is c_z + sqrt(R^2 - rho^2).
        xy = c[:2] + rng.uniform(-15, 15, (500, 2))
        origins = np.column_stack([xy, np.full(500, 60.0)])
        down = np.tile([0.0, 0.0, -1.0], (500, 1))
        t, face, normal = part.raycast(origins, down)
        rho2 = np.sum((xy - c[:2]) ** 2, axis=1)
        inside = rho2 < R * R
        np.testing.assert_allclose(60.0 - t[inside], c[2] + np.sqrt(R * R - rho2[inside]),
                                   atol=1e-10)
        self.assertTrue(np.all(np.isnan(t[~inside])))
        hits = origins[inside] + t[inside, None] * down[inside]
        np.testing.assert_allclose(normal[inside], (hits - c) / R, atol=1e-12)

    def test_ray_from_inside_hits_the_far_wall(self):
        part = cal.SpherePart(2.0)
        t, _, _ = part.raycast(np.zeros((1, 3)), np.array([[1.0, 0, 0]]))
        self.assertAlmostEqual(t[0], 2.0)
        t, _, _ = part.raycast(np.array([[5.0, 0, 0]]), np.array([[1.0, 0, 0]]))
        self.assertTrue(np.isnan(t[0]))


class TestAxisFromCentres(unittest.TestCase):
    def test_exact_centres_give_the_axis(self):
        rng = np.random.default_rng(1)
        for _ in range(20):
            direction = tilted_axis(*rng.uniform(-2, 2, 2))
            point = np.array([rng.uniform(-1, 1), 0.0, rng.uniform(-1, 1)])
            start = np.array([rng.uniform(20, 60), rng.uniform(0, 50), rng.uniform(-10, 10)])
            angles = np.sort(rng.choice(np.arange(0, 360, 15), size=7, replace=False))
            centres = np.vstack([rodrigues(start, a, point, direction) for a in angles])
            axis = cal.axis_from_centres(centres, angles)
            np.testing.assert_allclose(axis["point"], point, atol=1e-9)
            np.testing.assert_allclose(axis["direction"], direction, atol=1e-11)
            self.assertLess(np.max(axis["angle_model_residual_mm"]), 1e-9)

    def test_direction_follows_the_angle_sense(self):
        # Turning by -a about -u is turning by a about u: the sign is fixed by the angles.
        point, u = np.zeros(3), tilted_axis(0.5, -0.3)
        start = np.array([40.0, 30.0, 0.0])
        angles = np.arange(0, 360, 45.0)
        centres = np.vstack([rodrigues(start, -a, point, u) for a in angles])
        axis = cal.axis_from_centres(centres, angles)
        np.testing.assert_allclose(axis["direction"], -u, atol=1e-11)

    def test_wrong_angles_show_in_the_angle_model(self):
        point, u = np.zeros(3), np.array([0.0, 1.0, 0.0])
        angles = np.arange(0, 360, 45.0)
        centres = np.vstack([rodrigues([40.0, 30.0, 0.0], a, point, u) for a in angles])
        told = angles.copy()
        told[3] += 0.01    # one angle reported 0.01 deg off: 7 um at 40 mm
        axis = cal.axis_from_centres(centres, told)
        self.assertGreater(np.max(axis["angle_model_residual_mm"]), 0.004)

    def test_too_few_angles(self):
        with self.assertRaises(InputError):
            cal.axis_from_centres(np.eye(3)[:2], [0.0, 90.0])


if __name__ == "__main__":
    unittest.main()
