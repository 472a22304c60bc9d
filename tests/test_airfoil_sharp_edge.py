"""A trailing edge that is a corner (Rotor 67's 90 % section leaves the blade through its tip
face there) is reported as not measurable, not read as a confident wrong angle (issue 15,
docs/user-guide.md "Sharp edges").

The section is built here: a double-circular-arc section (tests/airfoil_shapes.py) whose TE
circle is removed and its two sides run on to where their circles cross -- a corner. Its LE is
the exact circle, so its inlet metal angle stays measurable and is checked against the camber
ellipse's exact tangent there.
"""
import unittest

import numpy as np

from BladeInspect.core import airfoil
from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import airfoil_values as values
from BladeInspect.inspection import airfoil_measure as measure_mod
from tests.airfoil_shapes import ArcSection

SIGMA, SPACING = 0.002, 0.02


def _arc(centre, radius, a0, a1):
    n = max(8, int(np.ceil(abs(a1 - a0) * radius / SPACING)))
    a = np.linspace(a0, a1, n, endpoint=False)
    return centre + radius * np.column_stack([np.cos(a), np.sin(a)])


def sharp_te_section():
    """(points counter-clockwise, the section, the corner): suction arc from the corner to the
    LE circle, the LE circle, the pressure arc back to the corner."""
    sec = ArcSection()
    (os_, rs, _, s_le), le, (op, rp, p_le, _), _ = sec._pieces()
    # the two side circles cross at x > 0 on the section's side (y between their tops)
    d = np.linalg.norm(op - os_)
    a = (rs ** 2 - rp ** 2 + d ** 2) / (2 * d)
    h = np.sqrt(rs ** 2 - a ** 2)
    base = os_ + a * (op - os_) / d
    perp = np.array([-(op - os_)[1], (op - os_)[0]]) / d
    corner = max((base + h * perp, base - h * perp), key=lambda p: p[0])
    s_c = np.arctan2(*(corner - os_)[::-1])
    p_c = np.arctan2(*(corner - op)[::-1])
    pts = np.vstack([_arc(os_, rs, s_c, s_le), _arc(le[0], le[1], le[2], le[3]),
                     _arc(op, rp, p_le, p_c)])
    return pts, sec, corner


def angle_of(v):
    return float(np.degrees(np.arctan2(v[1], v[0])))


class SharpTrailingEdge(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.pts, cls.sec, cls.corner = sharp_te_section()
        cls.nominal = airfoil.characteristics(cls.pts, le_upstream=(-1.0, 0.0))
        prof = airfoil.Profile(cls.pts)
        normal = prof.outward_normal(prof.point_params)
        rng = np.random.default_rng(20261202)
        cls.measured = []
        for _ in range(3):
            noisy = cls.pts + rng.normal(0.0, SIGMA, len(cls.pts))[:, None] * normal
            cls.measured.append(measure_mod.measure(noisy, cls.nominal, stage_mod.Options(draws=0),
                                                   SIGMA, cls.nominal.le_point)[0])

    def test_the_nominal_says_its_te_is_a_corner(self):
        self.assertLess(np.linalg.norm(self.nominal.te_point - self.corner), 0.05)
        self.assertTrue(any("corner at the TE" in w for w in self.nominal.warnings))

    def test_measured_te_angle_and_radius_not_reported_with_a_reason(self):
        for ch in self.measured:
            self.assertIsNone(ch.outlet_angle_deg)
            self.assertIsNone(ch.te_radius_mm)
            self.assertTrue(any("TE" in w and "not measurable" in w for w in ch.warnings))
            block = values.flat(values.char_values(ch, _PlaneFrame()))
            self.assertNotIn("outlet_angle_deg", block)
            self.assertNotIn("te_radius_mm", block)

    def test_the_rounded_le_is_still_measured(self):
        """The inlet angle against the camber ellipse's exact tangent at the LE circle's
        centre (a few times its 1 sigma of ~10 mdeg at this noise and a 50 % window), the LE
        radius against the exact circle's."""
        inlet = angle_of(self.sec.inlet_dir())
        for ch in self.measured:
            self.assertAlmostEqual(ch.inlet_angle_deg, inlet, delta=0.05)
            self.assertAlmostEqual(ch.le_radius_mm, self.sec.r_le, delta=0.005)

    def test_a_rounded_te_is_not_withheld(self):
        pts = ArcSection().points(SPACING)
        nominal = airfoil.characteristics(pts, le_upstream=(-1.0, 0.0))
        ch = airfoil.withhold_corner_edges(airfoil.characteristics(pts, le_upstream=(-1.0, 0.0)),
                                           nominal)
        self.assertIsNotNone(ch.outlet_angle_deg)
        self.assertIsNotNone(ch.te_radius_mm)


class _PlaneFrame:
    """The identity plane frame (the block's centroid in 3D)."""
    @staticmethod
    def to_3d(p):
        p = np.atleast_2d(p)
        return np.column_stack([p, np.zeros(len(p))])


if __name__ == "__main__":
    unittest.main()
