"""The fine registration's last level stops early and hands its residuals to the deviations
(issue 14, speed), and neither changes the answer:

- from random poses and noise on the demo blade, the multi-resolution fit ends within
  pipeline.FULL_CLOUD_UNCERTAINTY_FRACTION (1e-3) of the pose's own 1 sigma of the optimum a
  single full-resolution ICP reaches with cold exact distances, iterated to steps below 1e-9
  mm (the independent truth: no subsample, no warm start, no early stop; the stop rule before
  it, a step below 0.5 um, ends 1.8e-3 sigma away for seed 3);
- the deviations, foot points and normals it hands on (pipeline.final_distances) equal a cold
  exact evaluation at the returned pose: the deviations within 1e-9 mm, the foot points and
  normals to first order in the last step.
"""
import unittest

import numpy as np

from BladeInspect.core import icp
from BladeInspect.core import transforms as tf
from tests.test_warm_start import small_motion


class FullCloudStop(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        from tests.helpers import demo_nominal
        cls.nominal = demo_nominal()

    def check_case(self, seed):
        from BladeInspect.inspection import pipeline
        from BladeInspect.inspection.closest_fn import exact_closest_fn
        from BladeInspect.inspection.simulate import simulate_measurement
        rng = np.random.default_rng(seed)
        ps, truth, _, _ = simulate_measurement(
            self.nominal, n_points=pipeline.FINE_SUBSAMPLE + 10000, seed=seed,
            outlier_fraction=0.02, section_heights=(), noise="normal",
            sigma=rng.uniform(0.002, 0.01))
        start = small_motion(rng, rng.uniform(0.01, 0.1),
                             tf.apply_transform(truth, ps.xyz).mean(axis=0)) @ truth
        tracked = pipeline.TrackedDistance(self.nominal)
        fit = pipeline.fine_register(ps.xyz, ps.snr, self.nominal, start,
                                     rng=np.random.default_rng(seed + 1), full_distance=tracked)
        self.assertTrue(fit.converged)
        # Gauss-Newton from the fit's pose to a step below 1e-9 mm (a millionth of sigma):
        # the optimum near it, whichever way the fit got there.
        optimum = icp.icp(ps.xyz, ps.snr, exact_closest_fn(self.nominal),
                          fit.transform, icp.ICPOptions(horn_iters=0, uncertainty_fraction=0.0,
                                                        trans_tol=1e-9, rot_tol=1e-11,
                                                        max_iter=20))
        self.assertTrue(optimum.converged)
        corners = self.nominal.bbox_corners
        sigma = icp.pose_uncertainty(optimum.covariance, optimum.center, corners)
        self.assertLess(tf.corner_displacement(fit.transform, optimum.transform, corners),
                        pipeline.FULL_CLOUD_UNCERTAINTY_FRACTION * sigma)

        handed_on = pipeline.final_distances(fit, tracked)
        exact = self.nominal.signed_distance(tf.apply_transform(fit.transform, ps.xyz))
        np.testing.assert_allclose(handed_on.distance, exact.distance, rtol=0, atol=1e-9)
        # The foot points move with the last step along the surface; first order in a step
        # below LINEAR_UPDATE_MM (the normals turn by curvature x step).
        np.testing.assert_allclose(handed_on.closest, exact.closest, rtol=0,
                                   atol=pipeline.LINEAR_UPDATE_MM)
        np.testing.assert_allclose(handed_on.normal, exact.normal, rtol=0, atol=1e-4)
        np.testing.assert_array_equal(handed_on.face, exact.face)

    def test_random_poses_and_noise(self):
        for seed in (3, 41):
            with self.subTest(seed=seed):
                self.check_case(seed)


if __name__ == "__main__":
    unittest.main()
