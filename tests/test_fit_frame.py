"""The frame the robust fit chose, as a term of the airfoil angles' U (core.frame_shift,
inspection.airfoil_frame).

A prism of a corpus profile (bench/corpus) twisted 0.3 deg at the tip, its exact signed
distance from the dense profile. The robust fit is stood in for by the least-squares fit of
the points nearest the surface (the strips the twist moves most left out); scipy's nonlinear
least squares gives that fit and the fit of every point, independently of the one linear step
core.frame_shift takes from the first towards the second. The stage's bookkeeping is then
checked on a section block: the turn added linearly to the angles' U, a note, nothing on a
part whose left-out points do not move the frame.
"""
import os
import sys
import unittest

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "bench"))

from corpus import all_cases, truth  # noqa: E402

from BladeInspect.core.frame_shift import least_squares_shift  # noqa: E402
from BladeInspect.inspection import airfoil_frame  # noqa: E402
from BladeInspect.inspection import airfoil_stage as stage  # noqa: E402

TIP_DEG = 0.3
KEEP_BELOW_MM = 0.01


class Prism:
    """Signed distance (+ outside) and outward normal of the prism of a dense CCW loop."""

    def __init__(self, loop):
        self.loop = np.asarray(loop, float)
        t = np.roll(self.loop, -1, axis=0) - np.roll(self.loop, 1, axis=0)
        t /= np.linalg.norm(t, axis=1)[:, None]
        self.n = np.column_stack([t[:, 1], -t[:, 0]])
        self.tree = cKDTree(self.loop)

    def __call__(self, p):
        _, i = self.tree.query(p[:, :2])
        d = np.einsum("ij,ij->i", p[:, :2] - self.loop[i], self.n[i])
        return d, np.column_stack([self.n[i], np.zeros(len(i))])


def _moved(x, points):
    return Rotation.from_rotvec(x[:3]).apply(points) + np.append(x[3:], 0.0)


class _TwistedPrism:
    @classmethod
    def setUpClass(cls):
        case = [c for c in all_cases() if c.name == "dca_stator_staggered"][0]
        loop = case.profile.points()
        cls.prism = Prism(loop)
        rng = np.random.default_rng(7)
        n = 4000
        z = rng.uniform(0.0, case.span, n)
        base = loop[rng.integers(0, len(loop), n)]
        turned = np.array([truth.rotate(p[None], TIP_DEG * zi / case.span)[0]
                           for p, zi in zip(base, z)])
        cls.points = np.column_stack([turned, z])
        cls.w = rng.uniform(0.5, 1.5, n)

        def fit(mask):
            # rotation and in-plane shift (a prism does not see a shift along z)
            res = least_squares(
                lambda x: np.sqrt(cls.w[mask]) * cls.prism(_moved(x, cls.points[mask]))[0],
                np.zeros(5), x_scale=[1e-3, 1e-3, 1e-3, 1e-2, 1e-2], xtol=1e-15, ftol=1e-15,
                gtol=1e-15)
            return res.x

        everyone = np.ones(n, bool)
        cls.x_all = fit(everyone)
        d_all = cls.prism(_moved(cls.x_all, cls.points))[0]
        # one side of the twist left out (as a robust fit does when one flank of it stands
        # out more): the rest is no longer balanced about the least-squares turn
        cls.inlier = d_all < KEEP_BELOW_MM
        cls.x_in = fit(cls.inlier)
        cls.at_fit = _moved(cls.x_in, cls.points)


class FrameShift(_TwistedPrism, unittest.TestCase):
    def test_the_case_leaves_out_the_strips_and_turns(self):
        self.assertGreater((~self.inlier).mean(), 0.03)
        self.assertGreater(abs(np.degrees(self.x_all[2] - self.x_in[2])), 0.001)

    def test_one_step_gives_the_least_squares_turn(self):
        d, normal = self.prism(self.at_fit)
        dw, dt, _ = least_squares_shift(self.at_fit, normal, d, self.w,
                                        np.ones(len(d), bool), self.inlier)
        expected = np.degrees(self.x_all[2] - self.x_in[2])
        self.assertAlmostEqual(np.degrees(dw[2]), expected, delta=0.25 * abs(expected))

    def test_nothing_left_out_no_shift(self):
        d, normal = self.prism(self.at_fit)
        dw, dt, _ = least_squares_shift(self.at_fit, normal, d, self.w, self.inlier,
                                        self.inlier)
        self.assertLess(np.abs(dw).max(), 1e-12)
        self.assertLess(np.abs(dt).max(), 1e-12)


class _Result:
    def __init__(self, points, normal, deviation, inlier, snr=None):
        self.points_cad, self.normal, self.deviation = points, normal, deviation
        self.inlier, self.snr = inlier, snr


class StageTerm(_TwistedPrism, unittest.TestCase):
    def _frame(self, counted):
        d, normal = self.prism(self.at_fit)
        result = _Result(self.at_fit, normal, d, self.inlier, snr=self.w)
        return airfoil_frame.fit_frame(result, counted, (0.0, 0.0, 1.0))

    def _section(self, u):
        plane = stage.Plane(label="1", origin=np.array([0.0, 0.0, 30.0]),
                            normal=np.array([0.0, 0.0, 1.0]), height_pct=50.0)
        sr = stage.SectionResult(plane=plane, frame=None, nominal=None)
        sr.block = {"uncertainty": dict(u)}
        return sr

    def test_the_turn_is_added_to_the_angles_u(self):
        frame = self._frame(np.ones(len(self.inlier), bool))
        self.assertIsNotNone(frame)
        turn = frame["turn_deg"]
        u = {"stagger_deg": 0.001, "twist_deg": 0.0005, "inlet_angle_deg": 0.01,
             "outlet_angle_deg": 0.02, "chord_mm": 0.003}
        sr = self._section(u)
        airfoil_frame.add_fit_frame(sr, frame, 0.0, (0.0, 0.0, 1.0))
        block = sr.block
        for key in airfoil_frame.FRAME_ANGLES:
            self.assertAlmostEqual(block["uncertainty"][key], u[key] + abs(turn) / 2, places=12)
            self.assertAlmostEqual(block["uncertainty_fit_frame"][key], abs(turn), places=12)
        self.assertEqual(block["uncertainty"]["chord_mm"], u["chord_mm"])
        self.assertIn("%+.4f" % turn, sr.notes[-1])

    def test_a_twisted_blade_adds_its_twist_rate_times_the_move_along_the_span(self):
        # a made-up frame: no turn, the part moved 0.05 mm along the span; a blade twisting
        # 0.2 deg/mm then reads every section 0.01 deg turned
        frame = {"turn_deg": 0.0, "move_mm": 0.05, "dw": np.zeros(3),
                 "dt": np.array([0.0, 0.0, 0.05]), "c": np.zeros(3), "left_out": 10,
                 "share": 0.1}
        sr = self._section({"stagger_deg": 0.001})
        airfoil_frame.add_fit_frame(sr, frame, 0.2, (0.0, 0.0, 1.0))
        self.assertAlmostEqual(sr.block["uncertainty_fit_frame"]["stagger_deg"], 0.01,
                               places=12)

    def test_twist_rates_from_the_nominal_staggers(self):
        results = []
        for z, stagger in ((10.0, -30.0), (30.0, -26.0), (50.0, -22.0)):
            sr = stage.SectionResult(plane=stage.Plane(
                label="s", origin=np.array([1.0, 2.0, z]), normal=np.array([0.0, 0.0, 1.0]),
                height_pct=z), frame=None, nominal=None)
            sr.block = {"nominal": {"stagger_deg": stagger}}
            results.append(sr)
        np.testing.assert_allclose(airfoil_frame.twist_rates(results, (0, 0, 1)), 0.2)
        self.assertEqual(airfoil_frame.twist_rates(results[:1], (0, 0, 1)), [0.0])

    def test_no_term_when_the_left_out_points_are_not_counted(self):
        # isolated rejections (not in measured_surface's groups) are not counted: no frame
        self.assertIsNone(self._frame(self.inlier.copy()))


if __name__ == "__main__":
    unittest.main()
