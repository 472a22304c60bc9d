"""End-to-end registration on the simulation protocol, judged against the known transform that
moved the points (never against the code's own output)."""
import unittest

import numpy as np

from BladeInspect.core import transforms as tf
from BladeInspect.inspection import pipeline
from BladeInspect.inspection.closest_fn import exact_closest_fn
from BladeInspect.inspection.simulate import pose_error, simulate_measurement
from tests.helpers import demo_nominal, least_squares_pose_bound, sensor_pose_bound

# The simulation's measurement error is uniform on +-AMPLITUDE along the normal.
AMPLITUDE = 0.006
# The stated uncertainty against the least-squares bound computed here from the truth: the SNR
# weights and the estimated residual variance move it by about 1 % (measured: 0.998-1.004).
BOUND_TOLERANCE = 0.05
# The rig's sensor bound takes the beam's error whole along the normal, so the efficient
# estimator is below it (measured: 0.77 of it on the blind scan); 10 % of margin for the robust
# weights' losses.
SENSOR_BOUND_MARGIN = 1.1


class AbsoluteBound:
    """Pose checks against the truth's own bound as well as the code's: an estimator that
    overstates its covariance (and so passes "error < 3x its own bound") fails here."""

    def assert_pose_at_the_bound(self, nominal, result, ps, truth, good):
        true = nominal.signed_distance(tf.apply_transform(truth, ps.xyz[good]))
        bound = least_squares_pose_bound(true.closest, true.normal, AMPLITUDE / np.sqrt(3.0),
                                         nominal.bbox_corners)[0]
        err = pose_error(result.measured_to_cad, truth, nominal.bbox_corners)
        self.assertLess(abs(result.pose_uncertainty_mm / bound - 1.0), BOUND_TOLERANCE,
                        "stated uncertainty %.3g mm vs least-squares bound %.3g mm"
                        % (result.pose_uncertainty_mm, bound))
        self.assertLess(err, 3.0 * bound, "pose error %.3g mm vs least-squares bound %.3g mm"
                        % (err, bound))


class TestRegistrationFromAnyPose(AbsoluteBound, unittest.TestCase):
    def test_random_poses_reach_the_statistical_limit(self):
        nominal = demo_nominal()
        for seed in (11, 12, 13):
            with self.subTest(seed=seed):
                ps, truth, info, good = simulate_measurement(
                    nominal, n_points=4000, outlier_fraction=0.02, seed=seed,
                    section_heights=(), max_translation=150.0)
                result = pipeline.register(nominal, ps, seed=seed)
                err = pose_error(result.measured_to_cad, truth, nominal.bbox_corners)
                self.assertLess(err, 3.0 * result.pose_uncertainty_mm,
                                "pose error %.3g mm vs bound %.3g mm"
                                % (err, result.pose_uncertainty_mm))
                self.assert_pose_at_the_bound(nominal, result, ps, truth, good)
                # The residual of the good points is the injected noise, within 0.1 um.
                dev = result.deviation[good]
                self.assertAlmostEqual(np.sqrt(np.mean(dev ** 2)),
                                       info["noise_rms_injected_mm"], delta=1e-4)
                # Gross outliers are all flagged, good points almost never. An outlier pushed
                # through a thin edge can land near the other side: judge each by its true
                # distance to the CAD (the simulator's pose), not by its injected offset.
                true_dist = nominal.signed_distance(
                    tf.apply_transform(truth, ps.xyz[~good])).distance
                far = np.abs(true_dist) > 0.02
                self.assertEqual(np.count_nonzero(result.inlier[~good][far]), 0)
                self.assertGreater(np.mean(result.inlier[good]), 0.99)

    def test_large_cloud_pose_is_the_converged_optimum(self):
        """Above the fine subsample the whole cloud only gets Gauss-Newton steps until one is
        small: the pose must be the full cloud's optimum all the same (ICP run on to its tight
        tolerances from there moves it by far less than a micrometre's hundredth)."""
        from BladeInspect.core import icp
        nominal = demo_nominal()
        n = pipeline.FINE_SUBSAMPLE + 10000
        ps, truth, info, good = simulate_measurement(nominal, n_points=n, outlier_fraction=0.02,
                                                     seed=21, section_heights=())
        result = pipeline.register(nominal, ps, seed=21)
        tight = icp.icp(ps.xyz, ps.snr, exact_closest_fn(nominal),
                        result.measured_to_cad, icp.ICPOptions(horn_iters=0))
        self.assertTrue(tight.converged)
        moved = pose_error(result.measured_to_cad, tight.transform, nominal.bbox_corners)
        self.assertLess(moved, 1e-5)
        err = pose_error(result.measured_to_cad, truth, nominal.bbox_corners)
        self.assertLess(err, 3.0 * result.pose_uncertainty_mm)
        self.assert_pose_at_the_bound(nominal, result, ps, truth, good)

    def test_translation_far_away_and_upside_down(self):
        nominal = demo_nominal()
        rng = np.random.default_rng(5)
        R = tf.rotation_from_vector(np.array([np.pi, 0.0, 0.0]))  # turned over
        pose = tf.make_transform(R @ tf.random_rotation(rng), np.array([250.0, -180.0, 90.0]))
        ps, truth, info, good = simulate_measurement(nominal, n_points=3000, seed=5, pose=pose,
                                                     section_heights=())
        result = pipeline.register(nominal, ps)
        err = pose_error(result.measured_to_cad, truth, nominal.bbox_corners)
        self.assertLess(err, 3.0 * result.pose_uncertainty_mm)
        self.assert_pose_at_the_bound(nominal, result, ps, truth, good)

    def test_a_bump_does_not_pull_the_fit(self):
        """A smooth 0.05 mm bump on about 5 % of the surface: the pose moves < 2 um and the
        deviations at the bump read +0.05 mm within 5 um."""
        nominal = demo_nominal()
        ps, truth, info, good = simulate_measurement(nominal, n_points=8000, seed=21,
                                                     section_heights=())
        cad_pts = tf.apply_transform(truth, ps.xyz)
        # Bump centred on a suction-side point; radius chosen so ~5 % of the points lie on it.
        centre = cad_pts[np.argmin(np.abs(cad_pts[:, 2] - 35.0) + 50 * (cad_pts[:, 0] < 0))]
        d = np.linalg.norm(cad_pts - centre, axis=1)
        radius = np.quantile(d, 0.05)
        height = 0.05 * np.where(d < radius, np.cos(np.pi * d / (2 * radius)) ** 2, 0.0)
        normals = nominal.signed_distance(cad_pts).normal
        bumped_cad = cad_pts + height[:, None] * normals
        ps.xyz = tf.apply_transform(tf.invert_transform(truth), bumped_cad)
        clean = pipeline.register(nominal, simulate_measurement(
            nominal, n_points=8000, seed=21, section_heights=())[0])
        bumped = pipeline.register(nominal, ps)
        moved = pose_error(bumped.measured_to_cad, clean.measured_to_cad, nominal.bbox_corners)
        self.assertLess(moved, 0.002)
        # Every point reads its bump height within the +-6 um measurement error plus 2 um of
        # pose; at the top of the bump the median reads the height within 5 um.
        self.assertLess(np.max(np.abs(bumped.deviation - height)), 0.006 + 0.002)
        top = d < 0.2 * radius
        self.assertGreater(np.count_nonzero(top), 10)
        self.assertLess(abs(np.median(bumped.deviation[top] - height[top])), 0.005)
        self.assertGreater(np.median(bumped.deviation[top]), 0.045)


class TestBlindScanRegistration(unittest.TestCase):
    def test_three_section_scan_finds_the_global_pose(self):
        """Three blind sections of a nearly helical blade leave a neighbouring minimum 4 mm
        away whose residual is 80 um: the coarse stage must search its way out of it. Judged
        against the simulated rig's own fixture pose."""
        import json
        import shutil
        import tempfile
        from BladeInspect.measurement.scan import open_rig, scan_to_dir
        nominal = demo_nominal()
        tmp = tempfile.mkdtemp(prefix="bladeinspect-blind-")
        try:
            rig = open_rig("sim", nominal, 1)
            scan_to_dir(tmp + "/scan", rig, n_sections=3, seed=1)
            with open(tmp + "/scan/scan.json") as fh:
                truth = np.array(json.load(fh)["table_to_cad"])
            points = pipeline.load_points(tmp + "/scan/points.csv")
            result = pipeline.register(nominal, points)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        err = pose_error(result.measured_to_cad, truth, nominal.bbox_corners)
        self.assertLess(err, 3.0 * result.pose_uncertainty_mm)
        bound, n = sensor_pose_bound(nominal, truth, points.xyz, points.snr, rig.sensor)
        self.assertGreater(n, 0.9 * len(points.xyz))
        self.assertLess(result.pose_uncertainty_mm, SENSOR_BOUND_MARGIN * bound,
                        "stated uncertainty %.3g mm vs the sensor's bound %.3g mm"
                        % (result.pose_uncertainty_mm, bound))
        self.assertLess(err, 3.0 * bound)


class TestRegistrationInputs(unittest.TestCase):
    def test_too_few_points(self):
        from BladeInspect.core.errors import InputError
        from BladeInspect.core.pointio import PointSet
        ps = PointSet(xyz=np.zeros((5, 3)), snr=None, columns={}, n_rows_skipped=0, source="x.csv")
        with self.assertRaises(InputError):
            pipeline.register(demo_nominal(), ps)


if __name__ == "__main__":
    unittest.main()
