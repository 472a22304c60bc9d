"""Airfoil characteristics (core.airfoil) against closed forms built here: a cambered
double-circular-arc section with exact circular edges (its camber line is an ellipse) and NACA
4-digit sections from their formula (tests/airfoil_shapes.py), at random poses."""
import unittest

import numpy as np

from BladeInspect.core import airfoil
from BladeInspect.core.errors import InputError
from tests.airfoil_shapes import ArcSection, NacaSection, naca_camber, naca_thickness, rigid

UM = 1e-3                 # one micrometre, in mm
MILLIDEG = 1e-3


def angle_of(v):
    return float(np.degrees(np.arctan2(v[1], v[0])))


def angle_diff(a, b):
    return abs((a - b + 180.0) % 360.0 - 180.0)


def random_pose(rng):
    return rng.uniform(-180, 180), rng.uniform(-20, 20, 2)


class ArcSectionClosedForms(unittest.TestCase):
    """Every characteristic of the double-circular-arc section, at two random poses."""

    @classmethod
    def setUpClass(cls):
        rng = np.random.default_rng(15)
        cls.cases = []
        for _ in range(2):
            angle, shift = random_pose(rng)
            sec = ArcSection(x_le=-24.0, x_te=27.0, angle_deg=angle, shift=shift)
            axis = np.array([np.cos(0.3), np.sin(0.3)])
            ch = airfoil.characteristics(sec.points(), engine_axis=axis,
                                         stations_pct=(10, 30, 50, 80))
            cls.cases.append((sec, axis, ch))

    def test_edges_and_chords(self):
        for sec, axis, ch in self.cases:
            self.assertEqual(ch.le_rule, "larger edge radius")
            self.assertLess(np.linalg.norm(ch.le_point - sec.le_point()), UM)
            self.assertLess(np.linalg.norm(ch.te_point - sec.te_point()), UM)
            self.assertEqual(ch.chord_method, "nose-tail")
            self.assertAlmostEqual(ch.chord_mm, sec.chord(), delta=UM)
            self.assertAlmostEqual(ch.caliper_chord_mm, sec.caliper(), delta=UM)
            self.assertAlmostEqual(ch.tangent_chord_mm, sec.extent(sec.pressure_tangent_dir()),
                                   delta=UM)
            self.assertAlmostEqual(ch.axial_chord_mm, sec.extent(axis), delta=UM)

    def test_stagger_is_the_asked_chords(self):
        """The stagger is the angle of the chord asked for, LE towards TE: the caliper runs
        through the two edge circles' centres, the tangent chord touches both edge circles on
        the pressure side (closed forms of the arc section)."""
        for sec, axis, ch in self.cases:
            ax = angle_of(axis)
            pts = sec.points()
            caliper_dir = rigid(np.atleast_2d(sec.C_te - sec.C_le), sec.angle_deg, (0, 0))[0]
            tangent_dir = sec.pressure_tangent_dir()
            tangent_dir = tangent_dir * np.sign(np.dot(tangent_dir, sec.chord_dir()))
            for method, line in (("caliper", caliper_dir), ("tangent", tangent_dir)):
                other = airfoil.characteristics(pts, engine_axis=axis, chord_method=method)
                self.assertLess(angle_diff(other.stagger_deg, angle_of(line) - ax), MILLIDEG,
                                method)
                # a line apart from the nose-tail chord's on this cambered section, so that
                # the nose-tail angle would fail the check above
                self.assertGreater(angle_diff(other.stagger_deg, ch.stagger_deg), 5 * MILLIDEG,
                                   method)

    def test_angles(self):
        for sec, axis, ch in self.cases:
            ax = angle_of(axis)
            self.assertLess(angle_diff(ch.stagger_deg, angle_of(sec.chord_dir()) - ax), MILLIDEG)
            self.assertLess(angle_diff(ch.inlet_angle_deg, angle_of(sec.inlet_dir()) - ax),
                            MILLIDEG)
            self.assertLess(angle_diff(ch.outlet_angle_deg, angle_of(sec.outlet_dir()) - ax),
                            MILLIDEG)

    def test_thickness(self):
        for sec, _, ch in self.cases:
            self.assertAlmostEqual(ch.max_thickness_mm, sec.max_thickness(), delta=UM)
            self.assertAlmostEqual(ch.max_thickness_pos_pct / 100 * ch.chord_mm,
                                   sec.max_thickness_pos_pct() / 100 * sec.chord(), delta=UM)
            for pct, value in zip(ch.thickness_stations_pct, ch.thickness_mm):
                self.assertAlmostEqual(value, sec.thickness_at_station(pct), delta=UM)
            for d, le, te in zip(ch.edge_offsets_mm, ch.le_thickness_mm, ch.te_thickness_mm):
                self.assertAlmostEqual(le, sec.thickness_at_arc(d), delta=UM)
                self.assertAlmostEqual(te, sec.thickness_at_arc(sec.mcl_length() - d), delta=UM)

    def test_edge_radii(self):
        for sec, _, ch in self.cases:
            self.assertAlmostEqual(ch.le_radius_mm, sec.r_le, delta=UM)
            self.assertAlmostEqual(ch.te_radius_mm, sec.r_te, delta=UM)

    def test_area_and_centroid(self):
        for sec, _, ch in self.cases:
            area, centroid = sec.area_centroid()
            # A micrometre all round the perimeter.
            self.assertAlmostEqual(ch.area_mm2, area, delta=UM * ch.profile.length)
            self.assertLess(np.linalg.norm(ch.centroid_mm - centroid), UM)

    def test_camber_line_is_the_ellipse(self):
        for sec, _, ch in self.cases:
            own = rigid(rigid(ch.inscribed_centres, 0.0, -sec.shift), -sec.angle_deg, (0, 0))
            self.assertLess(np.abs(sec.ellipse_distance(own)).max(), UM)
            m = ch.mcl
            s = np.linspace(m.le_extension, m.le_extension + m.inner_length, 3001)
            pts = rigid(rigid(m.at(s)[0], 0.0, -sec.shift), -sec.angle_deg, (0, 0))
            self.assertLess(np.abs(sec.ellipse_distance(pts)).max(), UM)

    def test_offset_part_reads_back(self):
        sec, axis, ch = self.cases[0]
        fat = ArcSection(x_le=-24.0, x_te=27.0, offset=0.02, angle_deg=sec.angle_deg,
                         shift=sec.shift)
        cf = airfoil.characteristics(fat.points(), engine_axis=axis)
        self.assertAlmostEqual(cf.max_thickness_mm - ch.max_thickness_mm, 0.04, delta=UM)
        self.assertAlmostEqual(cf.le_radius_mm - ch.le_radius_mm, 0.02, delta=UM)
        self.assertAlmostEqual(cf.te_radius_mm - ch.te_radius_mm, 0.02, delta=UM)
        self.assertLess(angle_diff(cf.stagger_deg, ch.stagger_deg), 0.005)


class NacaClosedForms(unittest.TestCase):
    """NACA 0012 with a circular tail: its camber line is the chord line, its thickness the
    formula's 2 y_t, its nose radius 1.1019 t^2 c."""

    @classmethod
    def setUpClass(cls):
        rng = np.random.default_rng(4)
        angle, shift = random_pose(rng)
        cls.sec = NacaSection("0012", c=60.0, x0=0.97, angle_deg=angle, shift=shift)
        cls.axis = np.array([1.0, 0.0])
        cls.ch = airfoil.characteristics(cls.sec.points(), stations_pct=(5, 20, 50, 90))

    def test_points_chord_angles(self):
        sec, ch = self.sec, self.ch
        self.assertLess(np.linalg.norm(ch.le_point - sec.to_world([0.0, 0.0])[0]), UM)
        self.assertLess(np.linalg.norm(ch.te_point - sec.to_world([sec.chord(), 0.0])[0]), UM)
        self.assertAlmostEqual(ch.chord_mm, sec.chord(), delta=UM)
        self.assertAlmostEqual(ch.caliper_chord_mm, sec.chord(), delta=UM)
        self.assertIsNone(ch.tangent_chord_mm)   # a convex pressure side has no bitangent
        for value in (ch.stagger_deg, ch.inlet_angle_deg, ch.outlet_angle_deg):
            self.assertLess(angle_diff(value, sec.angle_deg), MILLIDEG)

    def test_camber_line_is_the_chord_line(self):
        sec, ch = self.sec, self.ch
        own = rigid(rigid(ch.mcl.sample(2000), 0.0, -sec.shift), -sec.angle_deg, (0, 0))
        self.assertLess(np.abs(own[:, 1]).max(), UM)

    def test_thickness(self):
        sec, ch = self.sec, self.ch
        self.assertAlmostEqual(ch.max_thickness_mm, sec.max_thickness(), delta=UM)
        self.assertAlmostEqual(ch.max_thickness_pos_pct / 100 * ch.chord_mm,
                               sec.max_thickness_pos_pct() / 100 * sec.chord(), delta=UM)
        for pct, value in zip(ch.thickness_stations_pct, ch.thickness_mm):
            self.assertAlmostEqual(value, sec.thickness_at_x(pct / 100 * sec.chord()), delta=UM)
        for d, le, te in zip(ch.edge_offsets_mm, ch.le_thickness_mm, ch.te_thickness_mm):
            self.assertAlmostEqual(le, sec.thickness_at_x(d), delta=UM)
            self.assertAlmostEqual(te, sec.thickness_at_x(sec.chord() - d), delta=UM)

    def test_edge_radii(self):
        sec = self.sec
        self.assertAlmostEqual(self.ch.te_radius_mm, sec.r_te, delta=UM)
        # The nose's curvature varies (|y|^3 term): within 0.5 % for a zone of +-5 degrees.
        nose = airfoil.characteristics(self.ch.profile, edge_zone_deg=5.0)
        self.assertLess(abs(nose.le_radius_mm / sec.le_radius() - 1), 0.005)

    def test_area_and_centroid(self):
        area, centroid = self.sec.area_centroid()
        self.assertAlmostEqual(self.ch.area_mm2, area, delta=UM * self.ch.profile.length)
        self.assertLess(np.linalg.norm(self.ch.centroid_mm - centroid), UM)


class CamberedNaca(unittest.TestCase):
    def test_camber_line_meets_naca_camber_line_at_max_thickness(self):
        """Where dy_t/dx = 0 the circle of radius y_t about NACA's camber point touches both
        sides (thickness is laid off normal to the camber line), so there the inscribed-circle
        camber line passes through NACA's camber line exactly; elsewhere they differ at
        second order (bench/bench_airfoil.py prints by how much)."""
        sec = cambered_naca("4412", c=50.0)
        ch = airfoil.characteristics(sec)
        from scipy.optimize import brentq
        from tests.airfoil_shapes import naca_thickness_slope
        xm = brentq(lambda x: naca_thickness_slope(x, 0.12), 0.05, 0.6, xtol=1e-15)
        yc, _ = naca_camber(xm, 0.04, 0.4)
        point = 50.0 * np.array([xm, float(yc)])
        mcl = ch.mcl.sample(20001)
        self.assertLess(np.min(np.linalg.norm(mcl - point, axis=1)), UM)
        self.assertAlmostEqual(ch.max_thickness_mm, 2 * 50.0 * naca_thickness(xm, 0.12),
                               delta=UM)


def cambered_naca(digits, c, x0=0.95, n_side=2500, spacing=0.02):
    """A cambered NACA section closed behind x0 by a circle through its two ends (a corner
    there, far from where the test looks)."""
    sec = NacaSection("00" + digits[2:], c=c)
    sec.m, sec.p = int(digits[0]) / 100.0, int(digits[1]) / 10.0
    xi = np.linspace(0.0, np.sqrt(x0), n_side)
    upper, lower = sec.surface(xi, True), sec.surface(xi, False)
    centre = (upper[-1] + lower[-1]) / 2
    r = np.linalg.norm(upper[-1] - centre)
    a0 = np.arctan2(*(lower[-1] - centre)[::-1])
    a1 = np.arctan2(*(upper[-1] - centre)[::-1])
    a1 += 2 * np.pi * (a1 < a0)
    n = int(np.ceil((a1 - a0) * r / spacing))
    a = np.linspace(a0, a1, n, endpoint=False)[1:]
    tail = centre + r * np.column_stack([np.cos(a), np.sin(a)])
    return np.vstack([lower, tail, upper[::-1][:-1]])


class SectionFit(unittest.TestCase):
    def test_known_shift_and_twist_recovered(self):
        rng = np.random.default_rng(7)
        nominal = airfoil.Profile(ArcSection(x_le=-24.0, x_te=27.0).points(0.02))
        pivot = airfoil.area_centroid(nominal)[1]
        for _ in range(3):
            twist = rng.uniform(-0.5, 0.5)
            shift = rng.uniform(-0.05, 0.05, 2)
            pts = ArcSection(x_le=-24.0, x_te=27.0).points(0.013)
            measured = rigid(pts - pivot, twist, (0, 0)) + pivot + shift
            fit = airfoil.fit_section(measured, nominal)
            self.assertAlmostEqual(fit.twist_deg, twist, delta=1e-6)
            self.assertLess(np.linalg.norm(fit.shift_mm - shift), 1e-6)
            self.assertLess(fit.rms_after_mm, 1e-6)

    def test_contour_of_a_moved_section(self):
        """A translated section: its form error is nil; before the fit every normal sees the
        shift, so the zone holding all points is twice the shift wide."""
        sec = ArcSection(x_le=-24.0, x_te=27.0)
        chars = airfoil.characteristics(sec.points())
        shift = np.array([0.006, -0.008])
        out = airfoil.contour(sec.points(0.013) + shift, chars)
        # The nominal spline misses the G1 junctions of arcs by nanometres.
        self.assertLess(out["all"]["form_mm"], 1e-5)
        self.assertAlmostEqual(out["all"]["form_location_mm"], 2 * np.linalg.norm(shift),
                               delta=1e-6)
        self.assertEqual(sum(out[z]["n"] for z in airfoil.ZONES), out["all"]["n"])

    def test_unordered_points_ordered_by_the_nominal(self):
        sec = ArcSection(x_le=-24.0, x_te=27.0)
        nominal = airfoil.characteristics(sec.points())
        pts = sec.points(0.013)
        shuffled = pts[np.random.default_rng(1).permutation(len(pts))]
        ch = airfoil.characteristics(airfoil.order_by_nominal(shuffled, nominal.profile))
        self.assertAlmostEqual(ch.max_thickness_mm, sec.max_thickness(), delta=UM)


class Noise(unittest.TestCase):
    def test_noisy_points_read_within_a_few_micrometres(self):
        rng = np.random.default_rng(3)
        sec = ArcSection(x_le=-24.0, x_te=27.0)
        pts = sec.points(0.02)
        truth = airfoil.characteristics(pts)
        normal = airfoil.Profile(pts).outward_normal(airfoil.Profile(pts).point_params)
        noisy = pts + rng.normal(0.0, 0.002, len(pts))[:, None] * normal
        ch = airfoil.characteristics(noisy, noise_mm=0.002)
        for name in ("chord_mm", "max_thickness_mm", "axial_chord_mm"):
            self.assertAlmostEqual(getattr(ch, name), getattr(truth, name), delta=3 * UM,
                                   msg=name)
        self.assertAlmostEqual(ch.le_radius_mm, sec.r_le, delta=5 * UM)
        self.assertAlmostEqual(ch.te_radius_mm, sec.r_te, delta=5 * UM)


class LeanBow(unittest.TestCase):
    def test_line_through_the_end_sections(self):
        heights = [0.0, 10.0, 20.0, 40.0]
        lean = np.array([0.001, -0.002])
        shifts = np.array([[0.01, 0.0]]) + np.outer(heights, lean)
        shifts[2] += [0.004, 0.003]
        out = airfoil.lean_bow(heights, shifts)
        np.testing.assert_allclose(out["lean_mm_per_mm"], lean, atol=1e-12)
        self.assertEqual(out["largest_bow_section"], 2)
        self.assertAlmostEqual(out["bow_magnitude_mm"][2], 0.005, delta=1e-12)


class Corners(unittest.TestCase):
    def test_a_sharp_trailing_edge_is_flagged(self):
        """NACA 0012 closed by its own formula's sides meeting at a point: a corner."""
        sec = NacaSection("0012", c=50.0)
        xi = np.linspace(0.0, 1.0, 2500)
        upper, lower = sec.surface(xi, True), sec.surface(xi, False)
        upper[-1] = lower[-1] = [50.0, 0.0]
        pts = np.vstack([lower, upper[::-1][1:-1]])
        ch = airfoil.characteristics(pts)
        self.assertEqual(len(ch.warnings), 2)
        self.assertIn("corner at the TE", ch.warnings[0])
        # a corner's radius is zero, not the circle fitted about the camber line's end
        self.assertIsNone(ch.te_radius_mm)
        self.assertIn("TE is a corner", ch.warnings[1])
        self.assertIsNotNone(ch.le_radius_mm)

    def test_round_edges_raise_no_warning(self):
        for pts in (ArcSection().points(), NacaSection("0012", x0=0.97).points()):
            self.assertEqual(airfoil.characteristics(pts).warnings, [])


class BadInput(unittest.TestCase):
    def test_one_line_errors(self):
        with self.assertRaises(InputError):
            airfoil.Profile(np.zeros((3, 2)))
        with self.assertRaises(InputError):
            airfoil.Profile(np.full((20, 2), np.nan))
        pts = ArcSection().points()
        with self.assertRaises(InputError):
            airfoil.characteristics(pts, chord_method="longest")
        with self.assertRaises(InputError):
            airfoil.characteristics(pts, engine_axis=(0, 0))
        with self.assertRaises(InputError):
            airfoil.lean_bow([1.0], [[0, 0]])


if __name__ == "__main__":
    unittest.main()
