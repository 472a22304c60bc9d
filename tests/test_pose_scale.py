"""The pose term's residual scale (core.icp.random_residual_share,
inspection.uncertainty.random_pose_covariance): a least-squares pose covariance scaled by the
residuals' s^2 counts a smooth misfit -- the part of a reading bias the fit cannot take up, a
thickened part -- as if it were noise, although it moves the pose by a fixed amount, which the
budget's systematic term carries. Truth: closed forms for white noise and a slow sine, and the
pose bound of the simulated sensor's noise from first principles (tests.helpers
.sensor_pose_bound) for a registration of a planned scan."""
import types
import unittest

import numpy as np

from BladeInspect.core import icp as icp_mod
from BladeInspect.inspection import uncertainty as uncertainty_mod

N = 20000


def white(rng):
    """(weights 1 / sigma^2, residuals) of readings with their own sigma, white noise."""
    sigma = rng.uniform(0.002, 0.006, N)
    return 1.0 / sigma ** 2, sigma * rng.standard_normal(N)


class RandomResidualShare(unittest.TestCase):
    def test_white_noise_is_all_random(self):
        for seed in range(4):
            w, r = white(np.random.default_rng(seed))
            with self.subTest(seed=seed):
                self.assertGreater(icp_mod.random_residual_share(w, r), 0.97)

    def test_a_slow_misfit_is_taken_out_as_the_closed_form_says(self):
        """z = e + A sin(2 pi i / L), e unit white: s^2 -> 1 + A^2 / 2, s_d^2 -> 1 (the sine's
        differences are O(A / L)), so the share -> 1 / (1 + A^2 / 2)."""
        i = np.arange(N)
        for seed, amplitude in enumerate((0.5, 1.0, 2.0)):
            w, r = white(np.random.default_rng(10 + seed))
            misfit = amplitude * np.sin(2.0 * np.pi * i / 2000.0) / np.sqrt(w)
            expected = 1.0 / (1.0 + amplitude ** 2 / 2.0)
            with self.subTest(amplitude=amplitude):
                share = icp_mod.random_residual_share(w, r + misfit)
                self.assertAlmostEqual(share, expected, delta=0.04 * expected)

    def test_points_in_no_order_keep_the_whole_scale(self):
        rng = np.random.default_rng(20)
        w, r = white(rng)
        r = r + 2.0 * np.sin(2.0 * np.pi * np.arange(N) / 2000.0) / np.sqrt(w)
        order = rng.permutation(N)
        self.assertGreater(icp_mod.random_residual_share(w[order], r[order]), 0.97)

    def test_undefined_is_one(self):
        self.assertEqual(icp_mod.random_residual_share(np.ones(100), np.zeros(100)), 1.0)
        self.assertEqual(icp_mod.random_residual_share(np.ones(7), np.arange(7.0)), 1.0)
        self.assertEqual(icp_mod.random_residual_share(np.zeros(100), np.ones(100)), 1.0)

    def test_a_covariance_from_elsewhere_is_kept(self):
        """Without the fit's own weights the result's covariance is not the residuals'."""
        cov = np.diag([1e-6] * 3 + [1e-10] * 3)
        result = types.SimpleNamespace(pose_covariance=cov, icp_weights=None,
                                       deviation=np.sin(np.arange(500) / 50.0))
        np.testing.assert_array_equal(uncertainty_mod.random_pose_covariance(result), cov)


class ThickenedPartOnThePlannedScan(unittest.TestCase):
    """The demo blade's planned two-section scan, read by the simulated sensor at a known pose,
    from a part made 12 um thick all over (a misfit a rigid fit cannot take up): the pose
    covariance scaled by s^2 states ~1.8x the bound of the sensor's noise; cut to the random
    part it states that bound within 25 % (it was 1.13x on the seed used)."""

    @classmethod
    def setUpClass(cls):
        from BladeInspect.inspection import pipeline
        from BladeInspect.inspection.sections import span_axis_of
        from BladeInspect.inspection.weighting import weight_model_for
        from BladeInspect.measurement.planning import plan_sections
        from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose_of
        from tests.helpers import demo_nominal, planned_pointset, sensor_pose_bound
        nominal = demo_nominal()
        axis, _ = span_axis_of(nominal)
        truth = random_fixture_pose_of(nominal, np.random.default_rng(3), axis)
        cls.figures = {}
        for name, field in (("exact", None), ("thick", lambda p: np.full(len(p), 0.012))):
            rig = SimulatedRig(nominal, truth, seed=3, error_field=field)
            plan = plan_sections(nominal, truth, (30.0, 70.0), rig.sensor, rig.limits,
                                 span_axis=axis)
            points = planned_pointset(rig, plan)
            model, _ = weight_model_for(points)
            fit = pipeline.fine_register(points.xyz, points.snr, nominal, truth,
                                         weight_model=model)
            cov, stated, _ = pipeline.pose_summary(fit, nominal)
            share = icp_mod.random_residual_share(fit.weights, fit.distances)
            cls.figures[name] = (stated, icp_mod.pose_uncertainty(share * cov, fit.center,
                                                                  nominal.bbox_corners))
            if field is None:
                cls.bound, _ = sensor_pose_bound(nominal, truth, points.xyz, points.snr,
                                                 rig.sensor)

    def test_the_misfit_inflates_the_covariance(self):
        self.assertGreater(self.figures["thick"][0], 1.5 * self.bound)

    def test_its_random_part_states_the_noises_bound(self):
        for name, (_, random) in self.figures.items():
            with self.subTest(part=name):
                self.assertGreater(random, 0.85 * self.bound)
                self.assertLess(random, 1.25 * self.bound)


if __name__ == "__main__":
    unittest.main()
