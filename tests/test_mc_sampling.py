"""core.mc_sampling (the whole-chain Monte Carlo's sampling, bench/bench_uncertainty_mc.py)
against closed forms computed here: stratified draws are uniform over the range, and the
control-variate scatter of a value driven by a uniform bias plus noise has the population's
variance on average, with a spread over repeated 8-trial sets far below that of the plain
sample standard deviation of independent draws (about 20 %, the cause of Rotor 67's false
"mode")."""
import unittest

import numpy as np

from BladeInspect.core import mc_sampling

HALF_WIDTH = 0.006
SETS = 3000


def population(c, q, noise_sd, offset):
    """(variance, mean square) of offset + c b + q b^2 + e, b uniform in +-HALF_WIDTH,
    e normal(0, noise_sd): E b^2 = a^2 / 3, Var b^2 = E b^4 - (E b^2)^2 = a^4 / 5 - a^4 / 9."""
    a = HALF_WIDTH
    var = c * c * a * a / 3.0 + q * q * (a ** 4 / 5.0 - a ** 4 / 9.0) + noise_sd ** 2
    mean = offset + q * a * a / 3.0
    return var, var + mean * mean


class StratifiedUniformTest(unittest.TestCase):
    def test_one_draw_per_stratum_and_uniform(self):
        rng = np.random.default_rng(7)
        n = 8
        pooled = []
        for _ in range(500):
            b = mc_sampling.stratified_uniform(rng, n, HALF_WIDTH)
            stratum = np.floor((b / HALF_WIDTH + 1.0) / 2.0 * n).astype(int)
            self.assertEqual(sorted(stratum), list(range(n)))
            pooled.append(b)
        pooled = np.concatenate(pooled)
        self.assertLess(abs(pooled.mean()), 0.01 * HALF_WIDTH)
        self.assertAlmostEqual(pooled.var() / (HALF_WIDTH ** 2 / 3.0), 1.0, delta=0.03)
        # the order is random: a trial's stratum does not follow its index
        first = [mc_sampling.stratified_uniform(rng, n, HALF_WIDTH)[0] for _ in range(400)]
        self.assertAlmostEqual(np.var(first) / (HALF_WIDTH ** 2 / 3.0), 1.0, delta=0.2)


class ScatterAndRmsTest(unittest.TestCase):
    def check(self, n, c, q, noise_sd, offset):
        rng = np.random.default_rng(11)
        var, ms = population(c, q, noise_sd, offset)
        sd_bias = HALF_WIDTH / np.sqrt(3.0)
        ours, plain = [], []
        for _ in range(SETS):
            b = mc_sampling.stratified_uniform(rng, n, HALF_WIDTH)
            err = offset + c * b + q * b * b + noise_sd * rng.standard_normal(n)
            ours.append(mc_sampling.scatter_and_rms(err, b, sd_bias))
            bi = rng.uniform(-HALF_WIDTH, HALF_WIDTH, n)
            erri = offset + c * bi + q * bi * bi + noise_sd * rng.standard_normal(n)
            plain.append(np.std(erri, ddof=1))
        ours = np.array(ours)
        # unbiased in the variance and the mean square
        self.assertAlmostEqual(np.mean(ours[:, 0] ** 2) / var, 1.0, delta=0.03)
        self.assertAlmostEqual(np.mean(ours[:, 1] ** 2) / ms, 1.0, delta=0.03)
        return np.std(ours[:, 0]) / np.sqrt(var), np.std(plain) / np.sqrt(var)

    def test_bias_driven_value_at_eight_trials(self):
        # a thickness on Rotor 67: -1.7 um per um of bias, 0.7 um of noise
        spread, plain = self.check(8, -1.7, 0.0, 0.0007, 0.0)
        self.assertLess(spread, 0.08)
        self.assertGreater(plain, 0.15)

    def test_curved_response_and_offset(self):
        # a response that bends (a robust fit's rejection growing with |b|) and a mean error
        spread, plain = self.check(16, 0.5, 40.0, 0.0005, 0.0008)
        self.assertLess(spread, plain)

    def test_without_bias_plain_figures(self):
        err = np.array([0.001, -0.002, 0.0005, 0.003])
        sd, rms = mc_sampling.scatter_and_rms(err, None, 1.0)
        self.assertAlmostEqual(sd, np.std(err, ddof=1))
        self.assertAlmostEqual(rms, np.sqrt(np.mean(err ** 2)))


if __name__ == "__main__":
    unittest.main()
