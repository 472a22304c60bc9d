"""The CAD's airfoil profile in a section plane (cad/airfoil_sections.py) and the kernel on it,
against OCC's own area and centre of mass of the polygon face of the same cut."""
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect.cad.airfoil_sections import airfoil_section, plane_frame
from BladeInspect.core import airfoil
from BladeInspect.core.errors import InputError
from BladeInspect.inspection.sections import span_axis_of
from tests.helpers import demo_nominal


class DemoBladeSection(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = demo_nominal()
        span, (lo, hi) = span_axis_of(cls.nominal)
        bb = cls.nominal.shape.BoundBox
        centre = np.array([bb.Center.x, bb.Center.y, bb.Center.z])
        cls.origin = centre + ((lo + 0.5 * (hi - lo)) - centre @ span) * span
        cls.span = span
        cls.xy, cls.frame = airfoil_section(cls.nominal.shape, cls.origin, span)
        cls.ch = airfoil.characteristics(cls.xy)

    def test_frame_has_the_engine_axis_as_x(self):
        f = self.frame
        self.assertAlmostEqual(float(f.e1 @ f.normal), 0.0, places=12)
        self.assertAlmostEqual(float(np.cross(f.e1, f.e2) @ f.normal), 1.0, places=12)
        axis = np.array([1.0, 0.0, 0.0])
        in_plane = axis - (axis @ f.normal) * f.normal
        np.testing.assert_allclose(f.e1, in_plane / np.linalg.norm(in_plane), atol=1e-12)

    def test_area_and_centroid_agree_with_occ(self):
        loop = self.frame.to_3d(self.xy)
        face = Part.Face(Part.makePolygon([FreeCAD.Vector(*p) for p in
                                           np.vstack([loop, loop[:1]])]))
        # The polygon of the points misses a sliver h^3 kappa / 12 per segment of a convex
        # loop: pi h^2 / 6 in all for spacing h (the loop turns by 2 pi).
        h = np.linalg.norm(np.diff(np.vstack([self.xy, self.xy[:1]]), axis=0), axis=1).max()
        self.assertGreater(self.ch.area_mm2 - face.Area, 0.0)
        self.assertLess(self.ch.area_mm2 - face.Area, 1.2 * np.pi * h ** 2 / 6)
        com = self.frame.to_2d(np.array(face.CenterOfMass))[0]
        self.assertLess(np.linalg.norm(com - self.ch.centroid_mm), 1e-3)

    def test_blade_like_characteristics(self):
        ch = self.ch
        self.assertGreater(ch.le_radius_mm, ch.te_radius_mm)
        self.assertLess(ch.max_thickness_mm, 0.2 * ch.chord_mm)
        self.assertLessEqual(ch.chord_mm, ch.caliper_chord_mm + 1e-9)

    def test_engine_axis_along_the_normal_is_refused(self):
        with self.assertRaises(InputError):
            plane_frame(self.origin, self.span, engine_axis=self.span)


if __name__ == "__main__":
    unittest.main()
