"""The edges found as edges (issue 35): on high-turning turbine profiles the caliper
diameter's ends sit on a side's shoulder, and a split of the sides there ends the camber line
short of the nose. Checked on a family of profiles whose characteristics are known in closed
form (tests/turbine_shapes.py: a circular-arc camber line, the profile the envelope of its
inscribed circles): turnings 60-160 deg, thin (t/c about 2 %) to thick (t/c over 25 %), in
several poses."""
import unittest

import numpy as np
from scipy.spatial import ConvexHull

from BladeInspect.core.airfoil import Profile, characteristics
from tests.turbine_shapes import TurbineSection

MM = 1e-3           # 1 micrometre
DEG = 0.01

# (turning deg, camber length mm, r_le, r_te, r_max, pose deg, shift)
CIRCULAR = [
    (60.0, 60.0, 1.5, 0.5, 4.0, 0.0, (0.0, 0.0)),
    (100.0, 70.0, 2.0, 0.6, 8.0, -35.0, (120.0, -40.0)),
    (120.0, 60.0, 0.3, 0.2, 0.6, 15.0, (0.0, 5.0)),          # t/c about 2.4 %
    (130.0, 65.0, 3.0, 0.4, 7.5, 60.0, (-20.0, 8.0)),
    (140.0, 70.0, 3.0, 0.5, 9.0, 25.0, (10.0, -5.0)),
    (150.0, 60.0, 4.0, 1.0, 8.0, -70.0, (3.0, 3.0)),         # t/c about 37 %
    (160.0, 70.0, 2.5, 0.5, 9.0, -40.0, (0.0, 0.0)),
    (160.0, 80.0, 1.0, 0.3, 2.0, 100.0, (-50.0, 60.0)),
]


def _angle_off(a, b):
    """a - b in degrees, wrapped into [-180, 180) (an outlet angle of -180 is +180)."""
    return (a - b + 180.0) % 360.0 - 180.0


def _section(case):
    turning, camber, r_le, r_te, r_max, pose, shift = case
    return TurbineSection(turning, camber, r_le, r_te, r_max, pose_deg=pose, shift=shift)


def _characteristics(sec):
    truth = sec.truth()
    up = truth["le_point"] - truth["te_point"]
    return characteristics(sec.points(), engine_axis=(1.0, 0.0), le_upstream=up), truth


class CircularNoseFamily(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.results = [(case,) + _characteristics(_section(case)) for case in CIRCULAR]

    def test_thickness_range_covered(self):
        ratios = [t["max_thickness_mm"] / t["nose_tail_chord_mm"] for _, _, t in self.results]
        self.assertLess(min(ratios), 0.03)
        self.assertGreater(max(ratios), 0.25)

    def test_edge_points(self):
        for case, ch, truth in self.results:
            with self.subTest(case=case):
                self.assertLess(np.linalg.norm(ch.le_point - truth["le_point"]), MM)
                self.assertLess(np.linalg.norm(ch.te_point - truth["te_point"]), MM)

    def test_edge_radii(self):
        for case, ch, truth in self.results:
            with self.subTest(case=case):
                self.assertAlmostEqual(ch.le_radius_mm, truth["le_radius_mm"], delta=MM)
                self.assertAlmostEqual(ch.te_radius_mm, truth["te_radius_mm"], delta=MM)

    def test_metal_angles(self):
        for case, ch, truth in self.results:
            with self.subTest(case=case):
                self.assertLess(abs(_angle_off(ch.inlet_angle_deg, truth["inlet_angle_deg"])),
                                DEG)
                self.assertLess(abs(_angle_off(ch.outlet_angle_deg,
                                               truth["outlet_angle_deg"])), DEG)

    def test_nose_tail_chord_and_stagger(self):
        for case, ch, truth in self.results:
            with self.subTest(case=case):
                self.assertEqual(ch.chord_method, "nose-tail")
                self.assertAlmostEqual(ch.nose_tail_chord_mm, truth["nose_tail_chord_mm"],
                                       delta=MM)
                self.assertLess(abs(_angle_off(ch.stagger_deg, truth["stagger_deg"])), DEG)

    def test_max_thickness(self):
        for case, ch, truth in self.results:
            with self.subTest(case=case):
                self.assertAlmostEqual(ch.max_thickness_mm, truth["max_thickness_mm"],
                                       delta=MM)
                self.assertAlmostEqual(ch.max_thickness_pos_pct,
                                       truth["max_thickness_pos_pct"], delta=0.01)

    def test_no_note_on_a_clean_profile(self):
        for case, ch, _ in self.results:
            with self.subTest(case=case):
                self.assertEqual(ch.warnings, [])

    def test_caliper_chord_stays_the_caliper_diameter(self):
        # the largest distance between the profile's points, from their convex hull (dense
        # enough that the sampling shortens it by far less than the tolerance)
        for case, ch, _ in self.results:
            with self.subTest(case=case):
                pts = _section(case).points(spacing=0.01)
                hull = pts[ConvexHull(pts).vertices]
                d = np.max(np.linalg.norm(hull[:, None] - hull[None], axis=2))
                self.assertAlmostEqual(ch.caliper_chord_mm, d, delta=MM)


class NoisyTurbineProfiles(unittest.TestCase):
    """Scans of the 140 and 160 deg profiles (2 um normal noise, 0.02 mm spacing): the split
    finds the noses on every scan, and the edge points, radii and metal angles stay within a
    few sigma of their scatter (about 5 mdeg and 2 um here) of the closed form."""

    SIGMA = 0.002

    def test_scans_near_the_closed_form(self):
        rng = np.random.default_rng(35)
        for case in (CIRCULAR[4], CIRCULAR[6]):
            sec = _section(case)
            truth = sec.truth()
            up = truth["le_point"] - truth["te_point"]
            pts = sec.points(0.02)
            prof = Profile(pts)
            normal = prof.outward_normal(prof.point_params)
            for scan in range(3):
                noisy = pts + rng.normal(0.0, self.SIGMA, len(pts))[:, None] * normal
                ch = characteristics(noisy, noise_mm=self.SIGMA, le_upstream=up)
                with self.subTest(case=case, scan=scan):
                    self.assertLess(np.linalg.norm(ch.le_point - truth["le_point"]), 0.005)
                    self.assertLess(np.linalg.norm(ch.te_point - truth["te_point"]), 0.005)
                    self.assertAlmostEqual(ch.le_radius_mm, truth["le_radius_mm"], delta=0.01)
                    self.assertAlmostEqual(ch.te_radius_mm, truth["te_radius_mm"], delta=0.01)
                    for key in ("inlet_angle_deg", "outlet_angle_deg"):
                        self.assertLess(abs(_angle_off(getattr(ch, key), truth[key])), 0.03)
                    self.assertAlmostEqual(ch.max_thickness_mm, truth["max_thickness_mm"],
                                           delta=0.01)


class EllipticNose(unittest.TestCase):
    """A half-ellipse nose (semi-axis along the camber tangent 1.5 to 3 times the half
    thickness there): the split finds it; the TE and the largest inscribed circle are exact."""

    CASES = [(110.0, 70.0, 3.0, 0.6, 8.5, 4.5, 0.0), (140.0, 70.0, 2.5, 0.5, 8.0, 5.0, 30.0),
             (155.0, 65.0, 2.0, 0.5, 7.0, 6.0, -45.0)]

    @classmethod
    def setUpClass(cls):
        cls.results = []
        for turning, camber, r_le, r_te, r_max, nose, pose in cls.CASES:
            sec = TurbineSection(turning, camber, r_le, r_te, r_max, nose_mm=nose,
                                 pose_deg=pose, shift=(5.0, -2.0))
            cls.results.append((turning,) + _characteristics(sec))

    def test_trailing_edge_and_max_thickness(self):
        for turning, ch, truth in self.results:
            with self.subTest(turning=turning):
                self.assertLess(np.linalg.norm(ch.te_point - truth["te_point"]), MM)
                self.assertAlmostEqual(ch.te_radius_mm, truth["te_radius_mm"], delta=MM)
                self.assertLess(abs(_angle_off(ch.outlet_angle_deg,
                                               truth["outlet_angle_deg"])), DEG)
                self.assertAlmostEqual(ch.max_thickness_mm, truth["max_thickness_mm"],
                                       delta=MM)

    def test_leading_edge_on_the_nose(self):
        # the LE point on the nose's tip, not on a shoulder: within a twentieth of the
        # nose's length of the ellipse's vertex, its radius below the flanks' half distance
        for (turning, ch, truth), case in zip(self.results, self.CASES):
            with self.subTest(turning=turning):
                self.assertLess(np.linalg.norm(ch.le_point - truth["le_point"]),
                                case[5] / 20.0)
                self.assertLess(ch.le_radius_mm, case[2])


if __name__ == "__main__":
    unittest.main()
