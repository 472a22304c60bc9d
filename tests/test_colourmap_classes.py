"""The deviation map's out-of-tolerance classes: which points are beyond the tolerance, their
colours apart from every colour of the ramp, their counts."""
import unittest

import numpy as np

from BladeInspect.core import colourmap
from BladeInspect.core.errors import InputError
from tests.test_colourmap import srgb_to_lab


class TestOutOfToleranceClasses(unittest.TestCase):
    def test_classes_over_families_of_tolerances(self):
        rng = np.random.default_rng(11)
        for tolerance in (0.004, 0.04, 0.25, 1.5):
            dev = rng.normal(0.0, tolerance, 2000)
            dev[:3] = (tolerance, -tolerance, np.nan)
            classes = colourmap.deviation_classes(dev, tolerance)
            for d, c in zip(dev, classes):
                expected = 1 if d > tolerance else (-1 if d < -tolerance else 0)
                self.assertEqual(c, expected, (d, tolerance))
            below, above = colourmap.class_counts(dev, tolerance)
            self.assertEqual(below, sum(1 for d in dev if d < -tolerance))
            self.assertEqual(above, sum(1 for d in dev if d > tolerance))

    def test_out_of_tolerance_colours(self):
        tolerance = 0.04
        dev = np.array([-0.2, -0.0401, -0.04, 0.0, 0.04, 0.0401, 3.0, np.nan])
        colours = colourmap.classed_colours(dev, tolerance)
        for i in (0, 1):
            np.testing.assert_allclose(colours[i], colourmap.BELOW_COLOUR)
        for i in (5, 6):
            np.testing.assert_allclose(colours[i], colourmap.ABOVE_COLOUR)
        # within the tolerance: the ramp's own colours, the ends included; NaN grey
        np.testing.assert_allclose(colours[2:5],
                                   colourmap.deviation_colours(dev[2:5], tolerance))
        np.testing.assert_allclose(colours[7], colourmap.NAN_COLOUR)

    def test_a_wider_ramp_keeps_the_classes(self):
        dev = np.linspace(-0.1, 0.1, 201)
        colours = colourmap.classed_colours(dev, 0.04, limit=0.08)
        inside = np.abs(dev) <= 0.04
        np.testing.assert_allclose(colours[inside],
                                   colourmap.deviation_colours(dev[inside], 0.08))
        self.assertTrue(np.all(colours[dev > 0.04] == colourmap.ABOVE_COLOUR))
        self.assertTrue(np.all(colours[dev < -0.04] == colourmap.BELOW_COLOUR))

    def test_class_colours_stand_apart_from_the_ramp(self):
        """CIELAB distance (CIE76) from each class colour to the nearest ramp colour, by the
        tests' own sRGB -> Lab conversion: far more than a just-noticeable difference (about
        2.3), and the two classes far from each other."""
        ramp = srgb_to_lab(colourmap.colourmap_table())
        for colour in (colourmap.ABOVE_COLOUR, colourmap.BELOW_COLOUR):
            lab = srgb_to_lab(np.array([colour]))[0]
            self.assertGreater(np.min(np.linalg.norm(ramp - lab, axis=1)), 25.0, colour)
        pair = srgb_to_lab(np.array([colourmap.ABOVE_COLOUR, colourmap.BELOW_COLOUR]))
        self.assertGreater(np.linalg.norm(pair[0] - pair[1]), 50.0)

    def test_bad_tolerance(self):
        for bad in (0.0, -0.1, float("nan")):
            with self.assertRaises(InputError):
                colourmap.deviation_classes([0.0], bad)


if __name__ == "__main__":
    unittest.main()
