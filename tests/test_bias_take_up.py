"""core.bias_take_up: the rigid take-up r of a unit reading bias and what it leaves, s = beta - J r,
against an independent least squares solved here (scipy.optimize.least_squares on the motion
about the origin, its residuals written from the moved points, not from a Jacobian), on random
points, normals, beams and weights in random frames; the edge-foot exclusion (a grazing point
takes up nothing: the answer is that without it, and another when the rule is off); and its two
callers, core.icp._bias_response and inspection.uncertainty.bias_take_up /
systematic_coefficients, against the same independent solution."""
import dataclasses
import unittest

import numpy as np
from scipy.optimize import least_squares

from BladeInspect.core import bias_take_up as T
from BladeInspect.core import icp
from BladeInspect.core.transforms import rotation_from_vector

MAX_INCIDENCE = np.radians(85.0)


def random_set(rng, n=300):
    pts = rng.uniform(-20.0, 20.0, (n, 3)) * [3.0, 1.0, 0.3]
    normals = rng.normal(size=(n, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    beams = normals + 0.4 * rng.normal(size=(n, 3))   # within the sensor's incidence
    beams /= np.linalg.norm(beams, axis=1)[:, None]
    oblique = np.einsum("ij,ij->i", beams, normals) < 0.3
    beams[oblique] = normals[oblique]
    w = rng.uniform(0.2, 2.0, n)
    return pts, normals, beams, w


def independent(pts, normals, beams, w, center):
    """(r about ``center``, s) from scipy's least squares of the motion p -> p + u + v x p
    (about the origin) that best puts each point's unit-bias displacement (its beam) back,
    measured along the normal: sqrt(w) n . (beam - u - v x p)."""
    def residual(x):
        back = beams - x[:3] - np.cross(x[3:], pts)
        return np.sqrt(w) * np.einsum("ij,ij->i", back, normals)
    x = least_squares(residual, np.zeros(6), xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    u, v = x[:3], x[3:]
    # the same motion about c: u + v x p = (u + v x c) + v x (p - c)
    r = np.r_[u + np.cross(v, center), v]
    s = np.einsum("ij,ij->i", beams - u - np.cross(v, pts), normals)
    return r, s


class TestTakeUp(unittest.TestCase):

    def test_against_an_independent_least_squares_in_random_frames(self):
        rng = np.random.default_rng(11)
        for trial in range(4):
            pts, normals, beams, w = random_set(rng)
            R = rotation_from_vector(rng.normal(size=3))
            shift = rng.uniform(-100, 100, 3)
            pts, normals, beams = pts @ R.T + shift, normals @ R.T, beams @ R.T
            center = rng.uniform(-50, 50, 3)
            r = T.take_up(pts, normals, beams, w, center, MAX_INCIDENCE)
            r_ref, s_ref = independent(pts, normals, beams, w, center)
            # (the frame's shift, ~100 mm, costs scipy's origin-based solution a few digits)
            np.testing.assert_allclose(r, r_ref, rtol=0, atol=1e-6)
            s = T.left_over(pts, normals, beams, r, center)
            np.testing.assert_allclose(s, s_ref, rtol=0, atol=1e-7)
            # s does not depend on the centre the motion is stated about; r does
            other = center + rng.uniform(-30, 30, 3)
            r2 = T.take_up(pts, normals, beams, w, other, MAX_INCIDENCE)
            np.testing.assert_allclose(T.left_over(pts, normals, beams, r2, other), s_ref,
                                       rtol=0, atol=1e-7)
            self.assertGreater(np.linalg.norm(r2[:3] - r[:3]), 1e-6)

    def test_convention_translation_then_rotation(self):
        # beams all along one direction: a pure translation by that direction takes up the
        # whole bias, exactly, whatever the normals
        rng = np.random.default_rng(2)
        pts, normals, _, w = random_set(rng)
        d = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
        beams = np.tile(d, (len(pts), 1))
        r = T.take_up(pts, normals, beams, w, pts[0])
        np.testing.assert_allclose(r, np.r_[d, 0, 0, 0], atol=1e-10)
        np.testing.assert_allclose(T.left_over(pts, normals, beams, r, pts[0]), 0.0,
                                   atol=1e-10)

    def test_an_edge_foot_takes_up_nothing(self):
        rng = np.random.default_rng(5)
        pts, normals, beams, w = random_set(rng)
        # the edge foot: its beam square to its normal (a foot on a face's edge, normal
        # p - c), far out and at the grazing floor's weight
        side = np.cross(normals[0], [0.0, 0.0, 1.0])
        beams[0] = side / np.linalg.norm(side) * np.cos(0.1) + normals[0] * np.sin(0.01)
        beams[0] /= np.linalg.norm(beams[0])
        pts[0] = [80.0, 5.0, 3.0]
        w[0] = 1000.0
        self.assertFalse(T.takes_part(pts, normals, beams, w, MAX_INCIDENCE)[0])
        center = w[1:] @ pts[1:] / w[1:].sum()
        r = T.take_up(pts, normals, beams, w, center, MAX_INCIDENCE)
        r_without = T.take_up(pts[1:], normals[1:], beams[1:], w[1:], center, MAX_INCIDENCE)
        np.testing.assert_allclose(r, r_without, rtol=0, atol=1e-12)
        np.testing.assert_allclose(r, independent(pts[1:], normals[1:], beams[1:], w[1:],
                                                  center)[0], rtol=0, atol=1e-8)
        # the rule off: the edge foot takes part and the answer is another
        r_all = T.take_up(pts, normals, beams, w, center)
        np.testing.assert_allclose(r_all, independent(pts, normals, beams, w, center)[0],
                                   rtol=0, atol=1e-8)
        self.assertGreater(np.max(np.abs(r_all - r)), 1e-3)

    def test_points_without_weight_or_normal_take_no_part(self):
        rng = np.random.default_rng(8)
        pts, normals, beams, w = random_set(rng)
        w[:5] = 0.0
        w[5] = np.nan
        normals[6] = np.nan
        keep = np.arange(7, len(pts))
        c = np.zeros(3)
        r = T.take_up(pts, normals, beams, w, c, MAX_INCIDENCE)
        np.testing.assert_allclose(r, independent(pts[keep], normals[keep], beams[keep],
                                                  w[keep], c)[0], rtol=0, atol=1e-8)
        np.testing.assert_array_equal(T.take_up(pts, normals, beams, 0 * w, c), np.zeros(6))


class TestCallers(unittest.TestCase):
    """Both callers give the independent solution's s with their own weights."""

    def setUp(self):
        rng = np.random.default_rng(21)
        self.pts, self.normals, self.beams, self.w = random_set(rng, 400)
        side = np.cross(self.normals[0], [0.0, 0.0, 1.0])
        self.beams[0] = side / np.linalg.norm(side)      # an edge foot
        self.w[0] = 1000.0
        self.w[1] = 0.0                                   # a point without weight

    def test_icp_defect_test(self):
        s = icp._bias_response(self.pts, self.normals, self.beams, self.w, MAX_INCIDENCE)
        fit = np.arange(2, len(self.pts))
        c = self.w[fit] @ self.pts[fit] / self.w[fit].sum()
        _, s_ref = independent(self.pts[fit], self.normals[fit], self.beams[fit], self.w[fit], c)
        # 1e-7: the iterative reference's own convergence on another BLAS (FreeCAD 1.0's
        # numpy 2.2 gave 1.9e-9); a wrong take-up is off by 1e-2 and more
        np.testing.assert_allclose(s[fit], s_ref, rtol=0, atol=1e-7)
        self.assertEqual(s[1], 0.0)                        # no weight: nothing stated
        r, _ = independent(self.pts[fit], self.normals[fit], self.beams[fit], self.w[fit], c)
        beta0 = self.beams[0] @ self.normals[0]
        j0 = np.r_[self.normals[0], np.cross(self.pts[0] - c, self.normals[0])]
        self.assertAlmostEqual(s[0], beta0 - j0 @ r, delta=1e-7)   # the edge foot's own s

    def test_uncertainty(self):
        from BladeInspect.inspection import uncertainty as U
        from BladeInspect.rig.sensor import SensorModel

        @dataclasses.dataclass
        class Result:   # what bias_take_up reads of a RegistrationResult
            points_cad: np.ndarray
            normal: np.ndarray
            center: np.ndarray
            icp_weights: np.ndarray
            snr: np.ndarray
            inlier: np.ndarray
        inlier = np.ones(len(self.pts), dtype=bool)
        inlier[2] = False                                 # rejected: no part in the take-up
        center = np.array([3.0, -2.0, 1.0])
        result = Result(self.pts, self.normals, center, self.w, None, inlier)
        sensor = SensorModel()
        original = U.beam_directions
        U.beam_directions = lambda res: self.beams
        try:
            beams, r = U.bias_take_up(result, sensor)
            s = U.systematic_coefficients(result, sensor)
        finally:
            U.beam_directions = original
        fit = np.arange(3, len(self.pts))
        r_ref, _ = independent(self.pts[fit], self.normals[fit], self.beams[fit], self.w[fit],
                               center)
        np.testing.assert_allclose(r, r_ref, rtol=0, atol=1e-8)
        J = np.hstack([self.normals, np.cross(self.pts - center, self.normals)])
        np.testing.assert_allclose(s, np.einsum("ij,ij->i", self.beams, self.normals) - J @ r_ref,
                                   rtol=0, atol=1e-8)
        self.assertLess(np.cos(sensor.max_incidence_rad), 0.1)   # the edge foot is one


if __name__ == "__main__":
    unittest.main()
