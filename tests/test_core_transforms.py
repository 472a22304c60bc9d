"""Rigid transforms checked against closed forms and group identities, over random draws."""
import unittest

import numpy as np

from BladeInspect.core import transforms as tf


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


class TestTransforms(unittest.TestCase):
    def setUp(self):
        self.rng = np.random.default_rng(20261123)

    def test_rotation_about_z_closed_form(self):
        for angle in (0.0, 0.3, -1.2, np.pi / 2, np.pi, 2.5):
            R = tf.rotation_from_vector(np.array([0.0, 0.0, angle]))
            c, s = np.cos(angle), np.sin(angle)
            np.testing.assert_allclose(R, [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-14)
            q = [np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)]
            np.testing.assert_allclose(tf.rotation_matrix_from_quaternion(q), R, atol=1e-14)

    def test_exp_map_matches_matrix_exponential_series(self):
        for _ in range(20):
            omega = self.rng.normal(size=3) * self.rng.uniform(1e-10, 3.0)
            K = skew(omega)
            # Taylor series of expm(K), summed far enough for |omega| <= ~5.
            expm, term = np.eye(3), np.eye(3)
            for k in range(1, 60):
                term = term @ K / k
                expm = expm + term
            np.testing.assert_allclose(tf.rotation_from_vector(omega), expm, atol=1e-13)

    def test_quaternion_round_trip_including_half_turns(self):
        rotations = [tf.random_rotation(self.rng) for _ in range(50)]
        rotations += [tf.rotation_from_vector(np.pi * a / np.linalg.norm(a))
                      for a in self.rng.normal(size=(10, 3))]
        rotations += [np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]
        for R in rotations:
            q = tf.quaternion_from_rotation(R)
            self.assertAlmostEqual(np.linalg.norm(q), 1.0, places=14)
            self.assertGreaterEqual(q[0], 0.0)
            np.testing.assert_allclose(tf.rotation_matrix_from_quaternion(q), R, atol=1e-12)

    def test_random_rotation_is_proper_and_uniform(self):
        Rs = np.array([tf.random_rotation(self.rng) for _ in range(4000)])
        for R in Rs[:50]:
            np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-13)
            self.assertAlmostEqual(np.linalg.det(R), 1.0, places=12)
        # Haar measure: E[R] = 0, and the image of a fixed axis is uniform on the sphere, so
        # its z component is uniform on [-1, 1] (mean 0, variance 1/3).
        np.testing.assert_allclose(Rs.mean(axis=0), np.zeros((3, 3)), atol=0.05)
        z = Rs[:, 2, 0]
        self.assertAlmostEqual(z.var(), 1.0 / 3.0, delta=0.02)
        # The Haar density of the rotation angle is (1 - cos a) / pi, so E[cos a] = -1/2 and
        # E[trace R] = 1 + 2 E[cos a] = 0.
        self.assertAlmostEqual(np.trace(Rs, axis1=1, axis2=2).mean(), 0.0, delta=0.05)

    def test_apply_invert_and_compose(self):
        pts = self.rng.normal(size=(30, 3)) * 50
        for _ in range(20):
            T = tf.random_transform(self.rng, 100.0)
            self.assertLessEqual(np.linalg.norm(T[:3, 3]), 100.0)
            moved = tf.apply_transform(T, pts)
            homog = (T @ np.c_[pts, np.ones(len(pts))].T).T[:, :3]
            np.testing.assert_allclose(moved, homog, atol=1e-12)
            np.testing.assert_allclose(tf.apply_transform(tf.invert_transform(T), moved), pts,
                                       atol=1e-11)
            np.testing.assert_allclose(tf.invert_transform(T), np.linalg.inv(T), atol=1e-12)
            self.assertTrue(np.allclose(tf.make_transform(T[:3, :3], T[:3, 3]), T))

    def test_corner_displacement_of_known_motions(self):
        corners = np.array([[x, y, z] for x in (0, 70.0) for y in (0, 50.0) for z in (0, 20.0)])
        shift = tf.make_transform(np.eye(3), [0.003, -0.004, 0.0])
        self.assertAlmostEqual(tf.corner_displacement(shift, np.eye(4), corners), 0.005)
        # A small turn about the z axis through the origin: the farthest corner in xy moves
        # by its radius times 2 sin(a/2).
        a = 1e-4
        turn = tf.make_transform(tf.rotation_from_vector([0, 0, a]), np.zeros(3))
        expected = np.hypot(70.0, 50.0) * 2 * np.sin(a / 2)
        self.assertAlmostEqual(tf.corner_displacement(turn, np.eye(4), corners), expected,
                               delta=1e-12)
        T = tf.random_transform(self.rng, 10.0)
        self.assertAlmostEqual(tf.corner_displacement(shift @ T, T, corners), 0.005)


if __name__ == "__main__":
    unittest.main()
