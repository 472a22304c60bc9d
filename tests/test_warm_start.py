"""The speed-ups of the registration must not change its answers (issue 14):

- a warm-started distance (core.closest.FootStart, the previous call's foot points) equals the
  closed form on a parabolic cylinder and the cold call, for small and large moves, inside a
  trimmed domain and near its boundary, where the warm path must hand points back;
- patch_boxes hold the surface (random points evaluated on it), and the OCC fallback's face
  pruning keeps the nearest face (OCC's own per-face distances on the demo blade);
- on the demo blade, warm and cold signed distances of a moved cloud agree, and the
  multi-resolution fine registration ends at the pose a single full-resolution ICP converges
  to, within a hundredth of the pose's own uncertainty.
"""
import unittest

import numpy as np

from BladeInspect.core import bspline, closest
from BladeInspect.core import transforms as tf
from tests.test_core_kernels import face_set, parabolic_cylinder, points_off, square_domain


def small_motion(rng, size, about):
    """A rigid motion moving points near ``about`` by about ``size`` mm."""
    R = tf.rotation_from_vector(rng.normal(0.0, size / 3.0, 3))
    return tf.make_transform(R, about - R @ about + rng.normal(0.0, size / 3.0, 3))


class WarmStartKernel(unittest.TestCase):
    def check_warm_against_cold(self, domain, x_range, y_range):
        fs = face_set(domain)
        rng = np.random.default_rng(14)
        p, x, y, h = points_off(rng, 3000, x_range, y_range, height=0.005)
        before, _ = fs.closest(p)
        cold_rows = []   # the points the warm call leaves to the cold path
        cold_path = fs.closest_chunk
        fs.closest_chunk = lambda points, *args: cold_rows.append(len(points)) or cold_path(
            points, *args)
        for size in (1e-7, 1e-4, 2e-3, 1e-2, 0.3):
            moved = tf.apply_transform(small_motion(rng, size, p.mean(axis=0)), p)
            start = closest.FootStart.of(p, before)
            cold_rows.clear()
            warm, warm_hard = fs.closest(moved, start)
            left_cold = sum(cold_rows)
            cold, cold_hard = fs.closest(moved)
            if size <= 1e-4:   # the warm path decided all but the undecided few
                self.assertLess(left_cold, len(cold_hard) + 0.05 * len(p))
            np.testing.assert_array_equal(warm_hard, cold_hard)
            ok = np.setdiff1d(np.arange(len(p)), cold_hard)
            np.testing.assert_array_equal(warm.face[ok], cold.face[ok])
            np.testing.assert_allclose(warm.distance[ok], cold.distance[ok], rtol=0, atol=1e-9)
            np.testing.assert_allclose(warm.closest[ok], cold.closest[ok], rtol=0, atol=1e-9)
            # The closed form: the foot of a point on z = x^2 solves a cubic; Newton on it.
            q = moved[ok]
            fx = q[:, 0].copy()
            for _ in range(50):
                g = (fx - q[:, 0]) + 2 * fx * (fx * fx - q[:, 2])
                fx -= g / (1 + 2 * (3 * fx * fx - q[:, 2]))
            foot = np.column_stack([fx, q[:, 1], fx * fx])
            sign = np.sign(np.einsum("ij,ij->i", q - foot, np.column_stack(
                [-2 * fx, np.zeros(len(fx)), np.ones(len(fx))])))
            np.testing.assert_allclose(warm.distance[ok], sign * np.linalg.norm(q - foot, axis=1),
                                       rtol=0, atol=1e-9)
            before, p = warm, moved

    def test_untrimmed(self):
        self.check_warm_against_cold(closest.FaceDomain(None, 0.0, None), (-0.9, 0.9),
                                     (0.05, 0.95))

    def test_trimmed_with_points_near_and_beyond_the_boundary(self):
        # x = 2u - 1 in [-0.6, 0.6]: points out to x = +-0.7 have their feet outside.
        self.check_warm_against_cold(square_domain(0.2, 0.8), (-0.7, 0.7), (0.15, 0.85))

    def test_patch_boxes_hold_the_surface(self):
        surf = parabolic_cylinder()
        lo, hi = closest.patch_boxes(surf)
        rng = np.random.default_rng(2)
        (S,) = bspline.evaluate(surf, rng.uniform(0, 1, 2000), rng.uniform(0, 1, 2000), order=0)
        self.assertEqual(float(closest.box_distance(S, lo, hi).min(axis=1).max()), 0.0)
        far = S + [0.0, 0.0, 5.0]
        self.assertTrue(np.all(closest.box_distance(far, lo, hi).min(axis=1) > 3.9))


class WarmStartDemoBlade(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        from tests.helpers import demo_nominal
        cls.nominal = demo_nominal()

    def test_warm_and_cold_signed_distances_agree(self):
        from BladeInspect.inspection.simulate import simulate_measurement
        ps, truth, _, _ = simulate_measurement(self.nominal, n_points=20000, seed=3,
                                               outlier_fraction=0.02, section_heights=())
        p = tf.apply_transform(truth, ps.xyz)
        rng = np.random.default_rng(4)
        before = self.nominal.signed_distance(p)
        for size in (1e-6, 1e-3, 0.05):
            moved = tf.apply_transform(small_motion(rng, size, p.mean(axis=0)), p)
            warm = self.nominal.signed_distance(moved, closest.FootStart.of(p, before))
            cold = self.nominal.signed_distance(moved)
            np.testing.assert_allclose(warm.distance, cold.distance, rtol=0, atol=1e-9)
            np.testing.assert_allclose(warm.closest, cold.closest, rtol=0, atol=1e-9)
            np.testing.assert_array_equal(warm.fallback, cold.fallback)
            before, p = warm, moved

    def test_fallback_keeps_the_nearest_face(self):
        import FreeCAD
        import Part
        fs = self.nominal.face_set
        rng = np.random.default_rng(5)
        # Points near the faces' boundaries, where the fallback works.
        idx = rng.choice(len(fs.samples.xyz), 4000, replace=False)
        near = fs.samples.xyz[idx]
        bbox = self.nominal.bbox_corners
        edge = np.minimum(np.abs(near[:, 2] - bbox[:, 2].min()),
                          np.abs(near[:, 2] - bbox[:, 2].max())) < 1.0
        p = near[edge][:30] + rng.normal(0.0, 0.3, (min(30, edge.sum()), 3))
        reach = fs.faces_within_reach(p)
        for point, keep in zip(p, reach):
            vertex = Part.Vertex(FreeCAD.Vector(*point))
            d = np.array([face.distToShape(vertex)[0] for face in self.nominal.faces])
            self.assertEqual(d[keep].min(), d.min())

    def test_multi_resolution_fit_is_the_full_resolution_fit(self):
        from BladeInspect.core import icp
        from BladeInspect.inspection import pipeline
        from BladeInspect.inspection.closest_fn import exact_closest_fn
        from BladeInspect.inspection.simulate import pose_error, simulate_measurement
        n = pipeline.FINE_SUBSAMPLE + 10000
        ps, truth, _, good = simulate_measurement(self.nominal, n_points=n, seed=8,
                                                  outlier_fraction=0.02, section_heights=())
        rng = np.random.default_rng(9)
        start = small_motion(rng, 0.05, tf.apply_transform(truth, ps.xyz).mean(axis=0)) @ truth
        levels = pipeline.fine_register(ps.xyz, ps.snr, self.nominal, start,
                                        rng=np.random.default_rng(10))
        # One level, every point, cold exact distances, iterated to the tight tolerances.
        single = icp.icp(ps.xyz, ps.snr, exact_closest_fn(self.nominal), start,
                         icp.ICPOptions(uncertainty_fraction=0.0, max_iter=100))
        self.assertTrue(single.converged)
        bound = icp.pose_uncertainty(single.covariance, single.center,
                                     self.nominal.bbox_corners)
        difference = pose_error(levels.transform, single.transform, self.nominal.bbox_corners)
        self.assertLess(difference, 0.01 * bound)


if __name__ == "__main__":
    unittest.main()
