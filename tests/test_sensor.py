"""The sensor model against its specification: noise statistics per SNR, the ML relation
1/sigma^2 proportional to SNR, no readings outside the working range or the angular coverage,
gross errors only at low SNR, quantisation to the resolution."""
import math
import unittest

import numpy as np

from BladeInspect.core.errors import InputError
from BladeInspect.rig.sensor import SensorModel


class TestSNR(unittest.TestCase):
    def test_closed_form_values(self):
        s = SensorModel()
        # Head-on at the centre: the maximum; 60 deg halves it (cos); the range end loses half.
        np.testing.assert_allclose(s.snr([44.0, 44.0, 52.0, 36.0], np.radians([0, 60, 0, 0])),
                                   [100.0, 50.0, 50.0, 50.0], atol=1e-9)

    def test_falls_with_incidence_and_off_centre(self):
        s = SensorModel()
        inc = np.radians(np.linspace(0, 84, 50))
        self.assertTrue(np.all(np.diff(s.snr(np.full(50, 44.0), inc)) < 0))
        d = np.linspace(44.0, 51.9, 50)
        self.assertTrue(np.all(np.diff(s.snr(d, np.zeros(50))) < 0))

    def test_nothing_beyond_coverage_or_range(self):
        s = SensorModel()
        self.assertEqual(s.snr([44.0], [np.radians(85.5)])[0], 0.0)
        self.assertGreater(s.snr([44.0], [np.radians(84.5)])[0], 0.0)
        self.assertEqual(s.snr([52.01], [0.0])[0], 0.0)
        self.assertEqual(s.snr([35.99], [0.0])[0], 0.0)


class TestReadings(unittest.TestCase):
    def test_noise_rms_follows_sigma_of_snr(self):
        n = 40000
        for kind in ("uniform", "normal"):
            s = SensorModel(noise=kind)
            rng = np.random.default_rng(7)
            for inc_deg, dist in ((0.0, 44.0), (40.0, 47.0), (70.0, 41.0)):
                d = np.full(n, dist)
                reading, snr = s.read(d, np.full(n, np.radians(inc_deg)), rng)
                expected_snr = (100 * np.cos(np.radians(inc_deg))
                                * (1 - 0.5 * ((dist - 44) / 8) ** 2))
                np.testing.assert_allclose(snr, expected_snr, rtol=1e-12)
                err = reading - d
                # Independent of the model's sigma(): the spec at SNR 100 times sqrt(100/SNR).
                if kind == "uniform":
                    sigma = 0.006 / np.sqrt(3) * np.sqrt(100 / expected_snr)
                    bound = 0.006 * np.sqrt(100 / expected_snr)
                else:
                    c = 3.0
                    # Clipped normal variance by numeric integration, not the model's formula.
                    x = np.linspace(-c, c, 200001)
                    pdf = np.exp(-x * x / 2) / np.sqrt(2 * np.pi)
                    var = np.trapz(x * x * pdf, x) + c * c * math.erfc(c / math.sqrt(2))
                    sigma = 0.002 * np.sqrt(var) * np.sqrt(100 / expected_snr)
                    bound = 0.006 * np.sqrt(100 / expected_snr)
                self.assertAlmostEqual(float(s.sigma(expected_snr)), sigma, delta=1e-12)
                rms = np.sqrt(np.mean(err ** 2))
                # 40,000 samples: the RMS is known to about 0.5 %.
                self.assertAlmostEqual(rms / sigma, 1.0, delta=0.02, msg=(kind, inc_deg))
                self.assertLess(np.max(np.abs(err)), bound + 1e-4)
                self.assertLess(abs(np.mean(err)), 4 * sigma / np.sqrt(n))

    def test_inverse_variance_proportional_to_snr(self):
        s = SensorModel()
        snr = np.array([5.0, 20.0, 50.0, 100.0])
        np.testing.assert_allclose(snr / s.sigma(snr) ** -2, snr[0] / s.sigma(snr[0]) ** -2)

    def test_no_readings_out_of_range_or_coverage(self):
        s = SensorModel()
        rng = np.random.default_rng(3)
        n = 100000
        d = rng.uniform(30, 60, n)
        inc = np.radians(rng.uniform(0, 100, n))
        d[::97] = np.nan          # rays that hit nothing
        reading, snr = s.read(d, inc, rng)
        valid = np.isfinite(reading)
        self.assertTrue(np.all(reading[valid] >= 36.0) and np.all(reading[valid] <= 52.0))
        self.assertTrue(np.all(inc[valid] <= np.radians(85.0)))
        self.assertTrue(np.all(np.abs(d[valid] - 44.0) <= 8.0))
        self.assertTrue(np.all(snr[~valid] == 0) and np.all(snr[valid] >= 3.0))
        self.assertFalse(np.any(valid[::97]))
        # Most in-range, in-coverage spots do give a reading.
        inside = (np.abs(d - 44) < 7.9) & (inc < np.radians(80))
        self.assertGreater(valid[inside].mean(), 0.97)

    def test_gross_errors_only_at_low_snr(self):
        s = SensorModel()
        rng = np.random.default_rng(11)
        n = 50000
        high, _ = s.read(np.full(n, 44.0), np.zeros(n), rng)
        self.assertEqual(np.count_nonzero(np.abs(high - 44.0) > 0.05), 0)
        # Incidence 84 deg at the centre: SNR 10.45, probability 0.1 * (25 - 10.45) / 22.
        inc = np.full(n, np.radians(84.0))
        low, snr = s.read(np.full(n, 44.0), inc, rng)
        p = 0.1 * (25 - 100 * np.cos(np.radians(84))) / 22
        gross = np.abs(low - 44.0) > 0.09   # noise there stays below 0.019 mm
        frac = np.count_nonzero(gross) / n
        self.assertAlmostEqual(frac, p, delta=4 * np.sqrt(p * (1 - p) / n))
        size = np.abs(low[gross] - 44.0)
        noise = 0.006 * np.sqrt(100 / 10.4)
        self.assertTrue(np.all(size > 0.1 - noise) and np.all(size < 0.5 + noise))

    def test_quantised_to_resolution(self):
        s = SensorModel()
        reading, _ = s.read(np.random.default_rng(1).uniform(40, 48, 1000), np.zeros(1000),
                            np.random.default_rng(2))
        steps = reading / 1e-4
        np.testing.assert_allclose(steps, np.round(steps), atol=1e-6)

    def test_same_rng_same_readings(self):
        s = SensorModel()
        d = np.linspace(38, 50, 300)
        a = s.read(d, np.zeros(300), np.random.default_rng([5, 2]))
        b = s.read(d, np.zeros(300), np.random.default_rng([5, 2]))
        np.testing.assert_array_equal(a[0], b[0])

    def test_bad_parameters(self):
        with self.assertRaises(InputError):
            SensorModel(noise="gauss")
        with self.assertRaises(InputError):
            SensorModel(half_range=-1)


if __name__ == "__main__":
    unittest.main()
