"""Airfoil characteristics on noisy points (issue 15: a perfect part measured), the LE rule,
and the edge-density rule of item 7 (sigma_R = sigma / sqrt(n) f(alpha)) against Monte Carlo."""
import unittest

import numpy as np

from BladeInspect.core import airfoil
from BladeInspect.core.errors import InputError
from tests.airfoil_shapes import ArcSection

UM = 1e-3
SIGMA = 0.002


def noisy_scans(sec, seeds, spacing=0.02):
    pts = sec.points(spacing)
    prof = airfoil.Profile(pts)
    normal = prof.outward_normal(prof.point_params)
    for seed in seeds:
        rng = np.random.default_rng(seed)
        yield pts + rng.normal(0.0, SIGMA, len(pts))[:, None] * normal


class NoiseRepeatability(unittest.TestCase):
    """A perfect part at sigma = 2 um, several seeds: measured - nominal against the issue's
    targets (lengths 2 um, edge radii 5 um). Metal angles: 0.005 deg is out of reach from one
    scan at this noise (1-sigma ~6 mdeg over 50 % of the camber line, docs/validation.md); they are
    held to the measured spread (4 sigma)."""

    @classmethod
    def setUpClass(cls):
        cls.sec = ArcSection(x_le=-24.0, x_te=27.0, angle_deg=17.0, shift=(2.0, -3.0))
        cls.truth = airfoil.characteristics(cls.sec.points(0.02))
        cls.scans = [airfoil.characteristics(p, noise_mm=SIGMA)
                     for p in noisy_scans(cls.sec, (11, 12, 13, 14, 15))]

    def test_lengths_within_2_um(self):
        for ch in self.scans:
            for name in ("chord_mm", "axial_chord_mm", "max_thickness_mm"):
                self.assertAlmostEqual(getattr(ch, name), getattr(self.truth, name),
                                       delta=2 * UM, msg=name)
            self.assertLess(np.linalg.norm(ch.le_point - self.truth.le_point), 10 * UM)
            self.assertLess(np.linalg.norm(ch.te_point - self.truth.te_point), 10 * UM)

    def test_the_scan_whose_last_le_centre_wandered(self):
        # bench_airfoil.py's 11th scan (seed 3): its last inscribed LE centre is 48 um off the
        # camber line, which moved the former rule's nose-tail chord by 12.6 um.
        sec = ArcSection(x_le=-24.0, x_te=27.0)
        pts = sec.points(0.02)
        prof = airfoil.Profile(pts)
        normal = prof.outward_normal(prof.point_params)
        rng = np.random.default_rng(3)
        for _ in range(11):
            noisy = pts + rng.normal(0.0, SIGMA, len(pts))[:, None] * normal
        ch = airfoil.characteristics(noisy, noise_mm=SIGMA)
        truth = airfoil.characteristics(prof)
        self.assertAlmostEqual(ch.chord_mm, truth.chord_mm, delta=2 * UM)
        self.assertAlmostEqual(ch.stagger_deg, truth.stagger_deg, delta=0.005)

    def test_edge_radii_within_5_um_at_three_sigma(self):
        # Within 5 um at 3 sigma needs sigma_R <= 5/3 um: the item-7 rule for that target gives
        # the spacing (0.018 mm here; at 0.02 mm sigma_R is 1.8 um and one seed of 11-15 read
        # the TE radius 5.4 um off).
        h = airfoil.edge_spacing_mm(min(self.sec.r_le, self.sec.r_te), SIGMA, 5 * UM / 3)
        for pts in noisy_scans(self.sec, (11, 12, 13, 14, 15), spacing=h):
            ch = airfoil.characteristics(pts, noise_mm=SIGMA)
            self.assertAlmostEqual(ch.le_radius_mm, self.sec.r_le, delta=5 * UM)
            self.assertAlmostEqual(ch.te_radius_mm, self.sec.r_te, delta=5 * UM)
            # The stated sigma_R uses the fit's own rms, itself a noisy estimate of sigma.
            self.assertLessEqual(airfoil.edge_radius_sigma(ch.le_circle, SIGMA),
                                 1.15 * 5 * UM / 3)

    def test_angles(self):
        for ch in self.scans:
            self.assertAlmostEqual(ch.stagger_deg, self.truth.stagger_deg, delta=0.005)
            self.assertAlmostEqual(ch.inlet_angle_deg, self.truth.inlet_angle_deg, delta=0.03)
            self.assertAlmostEqual(ch.outlet_angle_deg, self.truth.outlet_angle_deg,
                                   delta=0.03)


class LeadingEdgeRule(unittest.TestCase):
    def test_upstream_direction_names_the_le(self):
        sec = ArcSection(x_le=-24.0, x_te=27.0)
        for up, le in (((-1.0, 0.0), sec.le_point()), ((1.0, 0.0), sec.te_point())):
            ch = airfoil.characteristics(sec.points(), le_upstream=up)
            self.assertEqual(ch.le_rule, "given upstream direction")
            self.assertLess(np.linalg.norm(ch.le_point - le), UM)

    def test_equal_radii_fall_back_to_the_engine_axis(self):
        # A symmetric arc section: its two edge circles are the same; the engine axis decides.
        sec = ArcSection(x_le=-25.0, x_te=25.0)
        self.assertAlmostEqual(sec.r_le, sec.r_te, delta=1e-12)
        for axis, le in (((1.0, 0.0), sec.le_point()), ((-1.0, 0.0), sec.te_point())):
            ch = airfoil.characteristics(sec.points(), engine_axis=axis)
            self.assertEqual(ch.le_rule, "upstream along the engine axis")
            self.assertLess(np.linalg.norm(ch.le_point - le), UM)

    def test_distinct_radii_keep_the_larger_radius_rule(self):
        ch = airfoil.characteristics(ArcSection(x_le=-24.0, x_te=27.0).points(),
                                     engine_axis=(-1.0, 0.0))
        self.assertEqual(ch.le_rule, "larger edge radius")

    def test_bad_upstream_and_window_refused(self):
        pts = ArcSection().points()
        with self.assertRaises(InputError):
            airfoil.characteristics(pts, le_upstream=(0.0, 0.0))
        with self.assertRaises(InputError):
            airfoil.characteristics(pts, metal_angle_window_pct=0.0)


class EdgeDensityRule(unittest.TestCase):
    """sigma_R = sigma / sqrt(n) f(alpha) against the scatter of geometric circle fits to n
    noisy points over an arc of half-angle alpha (Monte Carlo, several arcs and counts)."""

    def test_radius_factor_matches_monte_carlo(self):
        rng = np.random.default_rng(5)
        for zone_deg, n in ((30.0, 40), (45.0, 60), (60.0, 30), (90.0, 25)):
            a = np.radians(zone_deg)
            t = np.linspace(-a, a, n)
            radii = []
            for _ in range(300):
                rho = 0.5 + rng.normal(0.0, SIGMA, n)
                radii.append(airfoil.fit_circle_2d(np.column_stack([rho * np.cos(t),
                                                                     rho * np.sin(t)]))[1])
            predicted = SIGMA / np.sqrt(n) * airfoil.circle_radius_factor(a)
            # 300 fits: the sample standard deviation is good to about 4 % (1 sigma).
            self.assertAlmostEqual(np.std(radii) / predicted, 1.0, delta=0.15,
                                   msg="zone %g deg, n %d" % (zone_deg, n))

    def test_rule_spacing_gives_the_target(self):
        rng = np.random.default_rng(6)
        noise, target, r = 0.0035, 0.002, 0.3
        h = airfoil.edge_spacing_mm(r, noise, target)
        a = np.radians(airfoil.DEFAULT_EDGE_ZONE_DEG)
        t = np.arange(-a, a, h / r)
        radii = [airfoil.fit_circle_2d(np.column_stack([(r + e) * np.cos(t), (r + e) * np.sin(t)]))[1]
                 for e in (rng.normal(0.0, noise, (300, len(t))))]
        self.assertLess(np.std(radii), 1.15 * target)


if __name__ == "__main__":
    unittest.main()
