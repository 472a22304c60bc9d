"""The error of a reported maximum (core.uncertainty_model.max_error) against an independent
truth: scans simulated in the test, each one's reported max |deviation| compared with the
true largest |deviation|. The model sees one scan's readings only; its stated RMS error
(bias included) must agree with the simulated RMS error within the issue's +-30 %."""
import unittest

import numpy as np

from BladeInspect.core import uncertainty_model as um

SIGMA = 0.0034                     # the sensor's sigma at SNR_ref, mm
SCANS = 400


def uniform(rng, sigma):
    return rng.uniform(-1.0, 1.0, sigma.shape) * np.sqrt(3.0) * sigma


def stated_rms(terms):
    return float(np.sqrt(sum(v ** 2 for v in terms.values())))


class MaxErrorTest(unittest.TestCase):
    def check(self, truth, sigma, coefficient=None, accuracy=0.006, seed=0):
        """Simulated RMS error of max |d| over SCANS scans against the model's figure averaged
        over a few of those scans (the model reads one scan)."""
        rng = np.random.default_rng(seed)
        errors, stated = [], []
        for k in range(SCANS):
            d = truth + uniform(rng, sigma)
            shared = ()
            if coefficient is not None:
                d = d + rng.uniform(-accuracy, accuracy) * coefficient
                shared = (um.SharedTerm("systematic_mm", coefficient,
                                        lambda r, n: r.uniform(-accuracy, accuracy, (n, 1))),)
            errors.append(np.abs(d).max() - np.abs(truth).max())
            if k < 8:
                terms, _, _ = um.max_error(d, sigma, shared=shared, seed=k)
                if coefficient is not None and "systematic_mm" not in terms:
                    w = int(np.argmax(np.abs(d)))
                    terms["systematic_mm"] = abs(coefficient[w]) * accuracy / np.sqrt(3.0)
                stated.append(stated_rms(terms))
        rms = float(np.sqrt(np.mean(np.square(errors))))
        return float(np.mean(stated)) / rms

    def test_a_flat_part_inside_its_noise(self):
        # 1000 readings of a perfect part, their sigma varying with incidence and range: the
        # reported worst is the largest noise reading, biased by nearly the noise's bound.
        x = np.linspace(0.0, 100.0, 1000)
        sigma = SIGMA * (0.8 + 0.4 * np.abs(np.sin(x)))
        ratio = self.check(np.zeros_like(x), sigma)
        self.assertTrue(0.8 <= ratio <= 1.2, ratio)

    def test_a_smooth_bump(self):
        # A 30 um bump 6 mm in radius read every 0.1 mm: some 40 readings compete at its top.
        x = np.arange(-50.0, 50.0, 0.1)
        truth = 0.03 * np.clip(1.0 - (x / 6.0) ** 2, 0.0, None)
        ratio = self.check(truth, np.full_like(x, SIGMA))
        self.assertTrue(0.8 <= ratio <= 1.3, ratio)

    def test_a_lone_worst_is_one_reading(self):
        x = np.arange(-50.0, 50.0, 0.1)
        truth = np.where(np.abs(x) < 0.05, 0.03, 0.0)
        ratio = self.check(truth, np.full_like(x, SIGMA))
        self.assertTrue(0.85 <= ratio <= 1.15, ratio)
        terms, bias, n = um.max_error(truth, np.full_like(x, SIGMA))
        self.assertEqual((n, bias, terms["noise_mm"]), (1, 0.0, SIGMA))

    def test_a_bias_the_fit_took_up_unevenly(self):
        # A perfect part whose reading bias b (uniform in +-6 um, one per scan) the fit has
        # left at s_i between -0.5 and 1.5 of each reading: the worst is where b s_i and the
        # noise together push furthest, which the bias at one point does not state.
        x = np.linspace(0.0, 100.0, 1000)
        coefficient = 0.5 + np.sin(x / 7.0)
        ratio = self.check(np.zeros_like(x), np.full_like(x, SIGMA), coefficient)
        self.assertTrue(0.75 <= ratio <= 1.3, ratio)

    def test_the_closed_form_of_equal_readings(self):
        # 25 readings tied well above zero, one sigma: the order statistic's closed form.
        d = np.zeros(500)
        d[:25] = 0.03
        n = 25
        closed = (np.sqrt(3.0) * (n - 1) / (n + 1), np.sqrt(3.0 * 4 * n / ((n + 1) ** 2 * (n + 2))))
        terms, bias, k = um.max_error(d, np.full(500, SIGMA), equal_sigma_max=lambda m: closed)
        self.assertEqual(k, 25)
        self.assertAlmostEqual(bias, SIGMA * closed[0], places=12)
        sampled, sbias, _ = um.max_error(d, np.full(500, SIGMA), draws=4000)
        self.assertAlmostEqual(sbias, bias, delta=0.02 * bias)
        self.assertAlmostEqual(sampled["noise_mm"], terms["noise_mm"],
                               delta=0.02 * terms["noise_mm"])


if __name__ == "__main__":
    unittest.main()
