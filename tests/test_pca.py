"""PCA coarse poses checked against the known random transform that moved the cloud."""
import unittest

import numpy as np

from BladeInspect.core import pca
from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import InputError


def anisotropic_cloud(rng, n=3000, extents=(35.0, 20.0, 6.0)):
    """A lumpy, non-symmetric cloud with clearly distinct extents along x, y, z."""
    pts = rng.uniform(-1, 1, size=(n, 3)) * extents
    pts[:, 2] += 0.02 * pts[:, 0] ** 2 + 0.05 * pts[:, 0] * pts[:, 1] / 10.0
    return pts


class TestPrincipalAxes(unittest.TestCase):
    def test_axes_of_a_box_aligned_cloud(self):
        rng = np.random.default_rng(1)
        # Uniform on [-a, a]: variance a^2 / 3.
        pts = rng.uniform(-1, 1, size=(200000, 3)) * [30.0, 10.0, 3.0] + [5.0, -2.0, 7.0]
        pa = pca.principal_axes(pts)
        np.testing.assert_allclose(pa.centroid, [5.0, -2.0, 7.0], atol=0.1)
        np.testing.assert_allclose(pa.eigenvalues, [300.0, 100.0 / 3, 3.0], rtol=0.02)
        np.testing.assert_allclose(np.abs(pa.axes), np.eye(3), atol=0.01)
        self.assertAlmostEqual(np.linalg.det(pa.axes), 1.0, places=12)

    def test_weights_equal_repetition(self):
        rng = np.random.default_rng(2)
        pts = anisotropic_cloud(rng, 200)
        counts = rng.integers(1, 4, size=len(pts))
        weighted = pca.principal_axes(pts, counts.astype(float))
        repeated = pca.principal_axes(np.repeat(pts, counts, axis=0))
        np.testing.assert_allclose(weighted.centroid, repeated.centroid, atol=1e-12)
        np.testing.assert_allclose(weighted.eigenvalues, repeated.eigenvalues, rtol=1e-12)
        # Same axes up to sign.
        np.testing.assert_allclose(np.abs(np.sum(weighted.axes * repeated.axes, axis=0)),
                                   1.0, atol=1e-10)
        # Covariance of eq. 3 rebuilt from the decomposition.
        d = np.repeat(pts, counts, axis=0) - repeated.centroid
        cov = d.T @ d / len(d)
        np.testing.assert_allclose(weighted.axes @ np.diag(weighted.eigenvalues)
                                   @ weighted.axes.T, cov, atol=1e-9)

    def test_bad_input(self):
        with self.assertRaises(InputError):
            pca.principal_axes(np.zeros((2, 3)))
        with self.assertRaises(InputError):
            pca.principal_axes(np.zeros((10, 2)))
        with self.assertRaises(InputError):
            pca.principal_axes(np.ones((10, 3)), -np.ones(10))


class TestCandidatePoses(unittest.TestCase):
    def test_one_candidate_is_the_true_pose(self):
        rng = np.random.default_rng(3)
        for trial in range(25):
            nominal_pts = anisotropic_cloud(rng)
            truth = tf.random_transform(rng, 100.0)            # measured -> nominal
            measured_pts = tf.apply_transform(tf.invert_transform(truth), nominal_pts)
            poses = pca.candidate_poses(pca.principal_axes(measured_pts),
                                        pca.principal_axes(nominal_pts))
            self.assertEqual(len(poses), 4)
            for T in poses:
                self.assertAlmostEqual(np.linalg.det(T[:3, :3]), 1.0, places=12)
                np.testing.assert_allclose(T[3], [0, 0, 0, 1])
            errors = [np.abs(T - truth).max() for T in poses]
            self.assertLess(min(errors), 1e-9, "trial %d" % trial)
            # The other three are half turns away, not near misses.
            self.assertGreater(sorted(errors)[1], 0.5)
            # The poses are distinct: the four proper sign patterns.
            rots = [T[:3, :3] for T in poses]
            for i in range(4):
                for j in range(i + 1, 4):
                    self.assertGreater(np.abs(rots[i] - rots[j]).max(), 0.5)

    def test_warning_for_symmetric_shapes_only(self):
        rng = np.random.default_rng(4)
        good = pca.principal_axes(anisotropic_cloud(rng))
        self.assertIsNone(pca.axes_warning(good, good))
        # A disc: two equal eigenvalues.
        r = np.sqrt(rng.uniform(size=5000)) * 20
        a = rng.uniform(0, 2 * np.pi, size=5000)
        disc = np.c_[r * np.cos(a), r * np.sin(a), rng.normal(size=5000) * 0.5]
        disc_axes = pca.principal_axes(disc)
        text = pca.axes_warning(disc_axes, good)
        self.assertIsNotNone(text)
        self.assertIn("measured", text)
        self.assertNotIn("nominal", text)
        self.assertIn("nominal", pca.axes_warning(good, disc_axes))
        # The threshold is the ratio of consecutive eigenvalues.
        pa = pca.PrincipalAxes(np.zeros(3), np.array([10.0, 9.5, 1.0]), np.eye(3))
        self.assertIsNotNone(pca.axes_warning(pa, good, min_ratio=1.1))
        self.assertIsNone(pca.axes_warning(pa, good, min_ratio=1.04))


if __name__ == "__main__":
    unittest.main()
