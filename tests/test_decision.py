"""Decision rules against their definitions: ISO 14253-1 and simple acceptance, on values
constructed at known places around the limits."""
import unittest

import numpy as np

from BladeInspect.core import decision as D


class TestDecisionRules(unittest.TestCase):
    def test_iso_rule_around_an_upper_limit(self):
        T, U = 0.04, 0.003
        got = [D.decide(v, U, upper=T).verdict for v in (T - 2 * U, T - U / 2, T + U / 2, T + 2 * U)]
        self.assertEqual(got, [D.PASS, D.NOT_PROVEN, D.NOT_PROVEN, D.FAIL])

    def test_simple_acceptance_around_an_upper_limit(self):
        T, U = 0.04, 0.003
        got = [D.decide(v, U, upper=T, rule="simple").verdict
               for v in (T - 2 * U, T - U / 2, T + U / 2, T + 2 * U)]
        self.assertEqual(got, [D.PASS, D.PASS, D.FAIL, D.FAIL])

    def test_both_limits_random_zones(self):
        # Property: against the zone arithmetic written out independently, over random zones.
        rng = np.random.default_rng(5)
        for _ in range(2000):
            lo = rng.uniform(-1, 1)
            hi = lo + rng.uniform(0.01, 1)
            U = rng.uniform(0, 0.3)
            v = rng.uniform(lo - 0.5, hi + 0.5)
            iso = D.decide(v, U, lo, hi).verdict
            if lo + U <= v <= hi - U:
                self.assertEqual(iso, D.PASS)
            elif v < lo - U or v > hi + U:
                self.assertEqual(iso, D.FAIL)
            else:
                self.assertEqual(iso, D.NOT_PROVEN)
            self.assertEqual(D.decide(v, U, lo, hi, "simple").verdict,
                             D.PASS if lo <= v <= hi else D.FAIL)

    def test_uncertainty_wider_than_the_zone_proves_no_conformance(self):
        self.assertEqual(D.decide(0.0, 0.06, -0.05, 0.05).verdict, D.NOT_PROVEN)
        self.assertEqual(D.decide(0.2, 0.06, -0.05, 0.05).verdict, D.FAIL)

    def test_lower_limit_only_and_ratio(self):
        self.assertEqual(D.decide(1.0, 0.1, lower=0.85).verdict, D.PASS)
        self.assertEqual(D.decide(0.9, 0.1, lower=0.85).verdict, D.NOT_PROVEN)
        self.assertIsNone(D.decide(1.0, 0.1, lower=0.85).test_uncertainty_ratio)
        self.assertAlmostEqual(D.decide(0, 0.01, -0.04, 0.04).test_uncertainty_ratio, 4.0)

    def test_part_verdict(self):
        self.assertEqual(D.combine([D.PASS, D.NOT_PROVEN, D.PASS]), D.NOT_PROVEN)
        self.assertEqual(D.combine([D.PASS, D.NOT_PROVEN, D.FAIL]), D.FAIL)
        self.assertEqual(D.combine([D.PASS, D.PASS]), D.PASS)
        self.assertIsNone(D.combine([]))

    def test_bad_arguments(self):
        for args in ((0.0, -1.0, 0, 1), (np.nan, 0.1, 0, 1), (0.0, 0.1, 1, 0), (0.0, 0.1)):
            with self.assertRaises(ValueError):
                D.decide(*args)
        with self.assertRaises(ValueError):
            D.decide(0.0, 0.1, 0, 1, rule="guess")


if __name__ == "__main__":
    unittest.main()
