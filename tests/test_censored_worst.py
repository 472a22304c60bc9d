"""The part's worst inlier as a censored maximum (core.uncertainty_model.censored_max_error,
inspection.uncertainty.censored_worst_terms), against independent truth: the closed form of
one reading kept under a cut-off, and the censoring process itself simulated on a defect that
straddles a fit's cut-off."""
import dataclasses
import unittest

import numpy as np

from BladeInspect.core import uncertainty_model as UM
from BladeInspect.inspection import uncertainty as U
from BladeInspect.rig.sensor import SensorModel
from tests import inspection_fixtures as fx
from tests.test_fit_pipeline import demo_cloud, suction_bump


class OneReadingUnderACutOffTest(unittest.TestCase):
    """One reading of level L and uniform noise of half-width a, kept when at most C: its kept
    error e is uniform on [-a, min(C - L, a)], so E e = (lo + hi) / 2 and
    E e^2 = (hi^3 - lo^3) / (3 (hi - lo))."""

    def test_closed_form(self):
        a = 0.006
        sigma = a / np.sqrt(3.0)
        for gap in (2.0 * a, a, 0.3 * a, 0.0, -0.5 * a):      # C - L
            terms, bias, n = UM.censored_max_error([0.010], [sigma], 0.010 + gap, draws=1000)
            lo, hi = -a, min(gap, a)
            mean = 0.5 * (lo + hi)
            rms = np.sqrt((hi ** 3 - lo ** 3) / (3.0 * (hi - lo)))
            with self.subTest(gap=gap):
                self.assertEqual(n, 1)
                self.assertAlmostEqual(terms["noise_mm"], rms, delta=0.04 * rms)
                self.assertAlmostEqual(bias, mean, delta=0.06 * a)

    def test_no_cut_off_is_the_largest_of_the_readings(self):
        # far above every reading the cut-off keeps them all: n readings on one level err by
        # the largest of n draws (uncertainty.max_of_draws' closed form)
        sigma = 0.003
        for n in (1, 5, 40):
            terms, bias, _ = UM.censored_max_error(np.full(n, 0.02), np.full(n, sigma), 1.0)
            mean, sd = U.max_of_draws(n, "uniform")
            with self.subTest(n=n):
                self.assertAlmostEqual(terms["noise_mm"], sigma * np.hypot(mean, sd),
                                       delta=0.04 * sigma)
                self.assertAlmostEqual(bias, sigma * mean, delta=0.1 * sigma)


class StraddlingDefectTest(unittest.TestCase):
    """A 30 um bump on the demo blade read with the sensor's uniform noise and one reading
    bias (uniform in +-accuracy) per scan; a cut-off at C = 15 um keeps the readings measured
    at most C, as a robust fit keeps a defect's flanks and leaves out its top. The process is
    simulated over many scans: the RMS of (largest kept reading - largest kept true value).
    The stated u, from one scan's readings alone, must agree with it (the bias included: a
    bias that lowers every reading keeps a higher band of the bump); the plain maximum's
    model (every kept reading on one plateau) over-states it."""

    CUT_MM = 0.015
    SCANS = 4000

    @classmethod
    def setUpClass(cls):
        nominal = fx.demo_nominal()
        on = demo_cloud(nominal, lambda p: np.zeros(len(p)), n_profile=800)
        cls.field = suction_bump(nominal, 0.030)(on)
        cls.nominal, cls.on = nominal, on
        cls.model = U.MeasurementModel(sensor=SensorModel())
        cls.a = cls.model.sensor.accuracy

    def scan(self, rng):
        n = len(self.field)
        return (self.field + rng.uniform(-self.a, self.a, n)
                + rng.uniform(-self.a, self.a))

    def stated(self, measured, censored=True):
        kept = measured <= self.CUT_MM
        r = fx.make_result(self.nominal, fx.displaced(self.nominal, self.on, measured),
                           inlier=kept)
        r = dataclasses.replace(r, pose_covariance=np.zeros((6, 6)))
        _, terms, _ = U.worst_terms(r, np.flatnonzero(kept), self.model,
                                    np.flatnonzero(~kept) if censored else None)
        return np.sqrt(sum(t ** 2 for t in terms.values()))

    def test_stated_against_the_simulated_process(self):
        rng = np.random.default_rng(3)
        error = []
        for _ in range(self.SCANS):
            measured = self.scan(rng)
            kept = measured <= self.CUT_MM
            error.append(measured[kept].max() - self.field[kept].max())
        rms = float(np.sqrt(np.mean(np.square(error))))
        self.assertGreater(np.count_nonzero(self.field > self.CUT_MM + self.a), 5)
        stated = [self.stated(self.scan(rng)) for _ in range(6)]
        plain = [self.stated(self.scan(rng), censored=False) for _ in range(2)]
        print("censored worst: simulated RMS %.2f um, stated %.2f um, plain %.2f um"
              % (rms * 1e3, np.mean(stated) * 1e3, np.mean(plain) * 1e3))
        self.assertLess(abs(np.mean(stated) / rms - 1.0), 0.1)
        self.assertGreater(np.mean(plain) / rms, 1.2)

    def test_a_gross_error_left_out_is_no_cut_off(self):
        # the part within its noise and one gross error the fit left out: nothing the fit cut
        # competes with the worst inlier, which stays a plain maximum
        rng = np.random.default_rng(5)
        measured = rng.uniform(-self.a, self.a, len(self.on))
        measured[100] = 0.2
        kept = np.ones(len(measured), dtype=bool)
        kept[100] = False
        r = fx.make_result(self.nominal, fx.displaced(self.nominal, self.on, measured),
                           inlier=kept)
        inliers = np.flatnonzero(kept)
        worst = inliers[np.argmax(np.abs(measured[inliers]))]
        self.assertIsNone(U.censored_worst_terms(r, worst, inliers, [100], self.model))
        self.assertEqual(U.worst_terms(r, inliers, self.model, [100]),
                         U.worst_terms(r, inliers, self.model))


if __name__ == "__main__":
    unittest.main()
