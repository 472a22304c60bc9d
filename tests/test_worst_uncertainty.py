"""The uncertainty of a worst deviation as the error of a maximum (inspection.uncertainty
worst_terms, max_of_draws), against independent truth: the order statistics of the sensor's
noise by direct sampling, and constructed clouds where the worst stands alone (the single
reading's sigma) or shares a plateau with others (the largest of their noisy readings)."""
import dataclasses
import unittest

import numpy as np

from BladeInspect.inspection import uncertainty as U
from BladeInspect.rig.sensor import NORMAL_CLIP_SIGMAS, SensorModel
from tests import inspection_fixtures as fx
from tests.test_fit_pipeline import demo_cloud

DRAWS = 40000


class MaxOfDrawsTest(unittest.TestCase):
    def test_against_sampled_order_statistics(self):
        rng = np.random.default_rng(11)
        for noise in ("uniform", "normal"):
            sensor = SensorModel(noise=noise)
            for n in (1, 3, 12, 200):
                if noise == "uniform":
                    x = rng.uniform(-sensor.accuracy, sensor.accuracy, (DRAWS, n))
                else:
                    sd = sensor.accuracy / NORMAL_CLIP_SIGMAS
                    x = np.clip(sd * rng.standard_normal((DRAWS, n)), -sensor.accuracy,
                                sensor.accuracy)
                top = x.max(axis=1) / sensor.sigma_ref
                mean, sd_max = U.max_of_draws(n, noise)
                with self.subTest(noise=noise, n=n):
                    self.assertAlmostEqual(mean, top.mean(), delta=0.02)
                    self.assertAlmostEqual(sd_max, top.std(), delta=0.02)


class WorstTermsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = fx.demo_nominal()
        cls.on = demo_cloud(cls.nominal, lambda p: np.zeros(len(p)))
        cls.sigma = SensorModel().sigma_ref

    def result_with(self, dev):
        r = fx.make_result(self.nominal, fx.displaced(self.nominal, self.on, dev))
        return dataclasses.replace(r, pose_covariance=np.zeros((6, 6)))

    def test_a_lone_worst_is_a_single_reading(self):
        dev = np.zeros(len(self.on))
        dev[7] = 0.03                       # far above every other point's noise band
        worst, terms, n = U.worst_terms(self.result_with(dev), np.arange(len(dev)))
        self.assertEqual((worst, n), (7, 1))
        single = U.standard_terms(self.result_with(dev), 7)
        self.assertAlmostEqual(terms["noise_mm"], single["noise_mm"][0], places=12)
        self.assertAlmostEqual(terms["systematic_mm"], single["systematic_mm"][0], places=12)

    def test_a_plateau_is_the_largest_of_its_readings(self):
        # 25 points tied at the top (a flat defect): the reported worst is the largest of 25
        # noisy readings; its RMS error about the plateau, sampled here, is the stated term.
        dev = np.zeros(len(self.on))
        dev[:25] = 0.02
        _, terms, n = U.worst_terms(self.result_with(dev), np.arange(len(dev)))
        self.assertEqual(n, 25)
        rng = np.random.default_rng(4)
        a = SensorModel().accuracy
        err = rng.uniform(-a, a, (DRAWS, 25)).max(axis=1)
        self.assertAlmostEqual(terms["noise_mm"], np.sqrt(np.mean(err ** 2)),
                               delta=0.02 * terms["noise_mm"])
        self.assertGreater(terms["noise_mm"], 1.5 * self.sigma)


if __name__ == "__main__":
    unittest.main()
