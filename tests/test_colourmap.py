"""The deviation colour map: sign, saturation, perceptual symmetry, legend."""
import unittest

import numpy as np

from BladeInspect.core import colourmap
from BladeInspect.core.errors import InputError
from tests.helpers import best_cpu_seconds


def srgb_to_lab(rgb):
    """Reference conversion the other way (sRGB -> XYZ -> CIELAB, D65), written from the
    standard's formulas independently of the module's Lab -> sRGB path."""
    rgb = np.atleast_2d(rgb)
    lin = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    m = np.array([[0.4124564, 0.3575761, 0.1804375],
                  [0.2126729, 0.7151522, 0.0721750],
                  [0.0193339, 0.1191920, 0.9503041]])
    xyz = lin @ m.T / np.array([0.95047, 1.0, 1.08883])
    d = 6.0 / 29.0
    f = np.where(xyz > d ** 3, np.cbrt(xyz), xyz / (3 * d * d) + 4.0 / 29.0)
    return np.column_stack([116 * f[:, 1] - 16, 500 * (f[:, 0] - f[:, 1]),
                            200 * (f[:, 1] - f[:, 2])])


class TestColourmap(unittest.TestCase):
    def test_zero_is_green_and_sign_sets_hue(self):
        rng = np.random.default_rng(3)
        limit = 0.04
        c0 = colourmap.deviation_colours([0.0], limit)[0]
        self.assertGreater(c0[1], c0[0])
        self.assertGreater(c0[1], c0[2])
        neg = colourmap.deviation_colours(-rng.uniform(0.5, 1.0, 200) * limit, limit)
        pos = colourmap.deviation_colours(rng.uniform(0.5, 1.0, 200) * limit, limit)
        self.assertTrue(np.all(neg[:, 2] > neg[:, 0]), "material missing must look blue")
        self.assertTrue(np.all(pos[:, 0] > pos[:, 2]), "material in excess must look red")

    def test_saturates_at_limit(self):
        limit = 0.04
        c = colourmap.deviation_colours([-limit, -1.0, -0.05, limit, 0.2, 5.0], limit)
        np.testing.assert_array_equal(c[0], c[1])
        np.testing.assert_array_equal(c[0], c[2])
        np.testing.assert_array_equal(c[3], c[4])
        np.testing.assert_array_equal(c[3], c[5])
        self.assertFalse(np.allclose(c[0], c[3]))
        # the limit scales the map: the same fraction of the limit gives the same colour
        np.testing.assert_array_equal(colourmap.deviation_colours([0.01], 0.04),
                                      colourmap.deviation_colours([0.025], 0.1))

    def test_lightness_symmetric_and_monotonic(self):
        """Equal |deviation| must look equally strong on both sides: L* (measured back from the
        sRGB output with an independent conversion) is symmetric about zero and falls
        monotonically away from it; consecutive steps are small (no visible bands)."""
        values = np.linspace(-1.0, 1.0, 201)
        lab = srgb_to_lab(colourmap.deviation_colours(values, 1.0))
        L = lab[:, 0]
        np.testing.assert_allclose(L, L[::-1], atol=1.5)
        self.assertTrue(np.all(np.diff(L[100:]) <= 0.2))
        self.assertTrue(np.all(np.diff(L[:101]) >= -0.2))
        self.assertGreater(L[100] - max(L[0], L[-1]), 35.0)
        step = np.linalg.norm(np.diff(lab, axis=0), axis=1)
        self.assertLess(step.max(), 3.0 * np.median(step) + 0.5)

    def test_nan_grey_and_shape(self):
        c = colourmap.deviation_colours([np.nan, 0.0, np.inf], 0.04)
        self.assertEqual(c.shape, (3, 3))
        np.testing.assert_allclose(c[0], colourmap.NAN_COLOUR)
        np.testing.assert_allclose(c[2], colourmap.NAN_COLOUR)
        self.assertTrue(np.all((c >= 0) & (c <= 1)))
        u8 = colourmap.deviation_colours_uint8([0.0, 0.04], 0.04)
        self.assertEqual(u8.dtype, np.uint8)

    def test_legend(self):
        values, colours = colourmap.legend_ticks(0.04, 9)
        np.testing.assert_allclose(values, np.linspace(-0.04, 0.04, 9))
        self.assertEqual(values[4], 0.0)
        np.testing.assert_array_equal(colours, colourmap.deviation_colours(values, 0.04))
        self.assertEqual(colourmap.colourmap_table().shape, (colourmap.LUT_SIZE, 3))

    def test_bad_limit(self):
        for bad in (0.0, -0.01, float("nan")):
            with self.assertRaises(InputError):
                colourmap.deviation_colours([0.0], bad)
        with self.assertRaises(InputError):
            colourmap.legend_ticks(0.04, 1)

    def test_fast_for_a_full_blade(self):
        dev = np.random.default_rng(0).normal(0, 0.03, 269158)
        seconds, _ = best_cpu_seconds(lambda: colourmap.deviation_colours(dev, 0.04),
                                      enough=0.5)
        self.assertLess(seconds, 0.5)


if __name__ == "__main__":
    unittest.main()
