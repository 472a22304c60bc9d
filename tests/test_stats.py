"""Deviation statistics on deviations built by hand, with the answers worked out independently."""
import json
import unittest

import numpy as np

from BladeInspect.core import stats
from BladeInspect.core.errors import InputError

# Paper Table 3: counts per band of the 269,158-point blade.
TABLE3_COUNTS = [2085, 5419, 14315, 228864, 17989, 459, 27]
TABLE3_PCT = [0.775, 2.013, 5.318, 85.030, 6.683, 0.171, 0.010]


class TestDeviationStatistics(unittest.TestCase):
    def test_table3_counts_and_percentages(self):
        rng = np.random.default_rng(0)
        # Values placed inside each band, including the bands' lower edges themselves (which
        # belong to the band above them: lo <= d < hi).
        ranges = [(-0.3, -0.08), (-0.08, -0.06), (-0.06, -0.04), (-0.04, 0.04), (0.04, 0.06),
                  (0.06, 0.08), (0.08, 0.3)]
        parts = []
        for (lo, hi), count in zip(ranges, TABLE3_COUNTS):
            values = rng.uniform(lo, hi, count)
            if lo != -0.3:
                values[0] = lo
            parts.append(values)
        dev = rng.permutation(np.concatenate(parts))
        s = stats.deviation_statistics(dev)
        self.assertEqual(s["n"], 269158)
        self.assertEqual([b["count"] for b in s["histogram"]], TABLE3_COUNTS)
        for band, pct in zip(s["histogram"], TABLE3_PCT):
            self.assertAlmostEqual(band["pct"], pct, delta=0.0005)
        self.assertEqual([(b["lo"], b["hi"]) for b in s["histogram"]],
                         [(None, -0.08), (-0.08, -0.06), (-0.06, -0.04), (-0.04, 0.04),
                          (0.04, 0.06), (0.06, 0.08), (0.08, None)])
        json.dumps(s)   # plain Python values only

    def test_moments_and_sigma_percentages_closed_form(self):
        s = stats.deviation_statistics([1.0, 2.0, 3.0, 4.0], band_edges=[2.0, 3.5])
        self.assertEqual(s["min"], 1.0)
        self.assertEqual(s["max"], 4.0)
        self.assertAlmostEqual(s["mean"], 2.5)
        self.assertAlmostEqual(s["rms"], np.sqrt(30.0 / 4))
        self.assertAlmostEqual(s["std"], np.sqrt(1.25))
        self.assertAlmostEqual(s["pct_within_1sigma"], 50.0)      # 2 and 3 are within 1.118
        self.assertAlmostEqual(s["pct_within_3sigma"], 100.0)
        self.assertEqual([b["count"] for b in s["histogram"]], [1, 2, 1])   # 1 | 2,3 | 4

    def test_sigma_is_about_the_mean(self):
        # Shifted data: a mean far from zero must not change the sigma percentages.
        rng = np.random.default_rng(1)
        x = rng.normal(size=100000)
        a = stats.deviation_statistics(x)
        b = stats.deviation_statistics(x + 5.0)
        self.assertAlmostEqual(a["pct_within_1sigma"], b["pct_within_1sigma"], delta=0.01)
        self.assertAlmostEqual(a["pct_within_1sigma"], 68.27, delta=0.5)
        self.assertAlmostEqual(a["pct_within_3sigma"], 99.73, delta=0.1)

    def test_tolerance_bands(self):
        np.testing.assert_allclose(stats.tolerance_bands(0.04), stats.DEFAULT_BAND_EDGES)
        edges = stats.tolerance_bands(0.01)
        s = stats.deviation_statistics([-0.05, -0.015, -0.01, 0.0, 0.0099, 0.01, 0.02, 0.5],
                                       edges)
        # bands: <-0.02 | -0.02..-0.015 | -0.015..-0.01 | -0.01..0.01 | 0.01..0.015 |
        #        0.015..0.02 | >=0.02
        self.assertEqual([b["count"] for b in s["histogram"]], [1, 0, 1, 3, 1, 0, 2])
        for bad in (0, -0.1, float("nan"), "abc"):
            with self.assertRaises(InputError):
                stats.tolerance_bands(bad)

    def test_bad_input(self):
        with self.assertRaises(InputError):
            stats.deviation_statistics([])
        with self.assertRaises(InputError):
            stats.deviation_statistics([0.0, np.nan])
        with self.assertRaises(InputError):
            stats.deviation_statistics([0.0, 1.0], band_edges=[0.1, 0.0])
        with self.assertRaises(InputError):
            stats.deviation_statistics([0.0, 1.0], band_edges=[])


if __name__ == "__main__":
    unittest.main()
