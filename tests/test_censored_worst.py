"""The part's worst inlier as a censored maximum (core.uncertainty_model.censored_max_error,
inspection.uncertainty.censored_worst_terms), against independent truth: the closed form of
one reading kept under a cut-off, and the censoring process itself simulated on a defect that
straddles a fit's cut-off."""
import dataclasses
import unittest

import numpy as np

from BladeInspect.core import icp as core_icp
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


class ReplayedSelectionTest(unittest.TestCase):
    """core.icp.InlierCut.kept, given the fit's own neighbourhoods (its windows along the
    Morton curve), keeps exactly the readings robust_selection's tapered weights keep: random
    fields with a defect, a sensor's bias response and low-SNR readings."""

    def test_the_cut_keeps_what_the_weights_keep(self):
        rng = np.random.default_rng(2)
        for trial in range(20):
            n = 3000
            points = rng.uniform(-20.0, 20.0, (n, 3)) * [1.0, 1.0, 0.05]
            d = rng.normal(0.0, 0.002, n)
            centre = points[rng.integers(n)]
            d += 0.02 * np.exp(-np.sum((points - centre) ** 2, axis=1) / 9.0)
            d[rng.integers(n, size=5)] += 0.3
            a = rng.uniform(0.3, 1.5, n)
            response = rng.uniform(-1.0, 1.0) * np.cos(points[:, 0] / 7.0)
            options = core_icp.ICPOptions(systematic_mm=0.004 * (trial % 2))
            hoods = core_icp.Neighbourhoods(points, options.defect_neighbours)
            rho, _, cut = core_icp.robust_selection(d, a, options, hoods, response)
            # the windows as the sliding sums take them: the size points from each one's start
            # along the curve (clipped at its ends), independently of Neighbourhoods.members
            rank = np.argsort(hoods.order)
            start = np.clip(rank - hoods.size // 2, 0, n - hoods.size)
            windows = hoods.order[start[:, None] + np.arange(hoods.size)]
            np.testing.assert_array_equal(hoods.members(np.arange(n)), windows)
            self.assertIs(cut.neighbourhoods, hoods)
            kept = cut.kept(d[None, :], np.arange(n), np.arange(n), windows)[0]
            with self.subTest(trial=trial):
                self.assertGreater(np.count_nonzero(rho == 0), 10)
                np.testing.assert_array_equal(kept, rho > 0)


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

    def fit_selection(self, measured):
        """core.icp's robust weights at a fixed pose, granting each neighbourhood the bias a
        reading error of the sensor's accuracy leaves (here all of it: no fit takes it up):
        (kept, their InlierCut)."""
        n = len(measured)
        rho, _, cut = core_icp.robust_selection(
            measured, np.ones(n), core_icp.ICPOptions(systematic_mm=self.a), self.hoods,
            np.ones(n))
        return rho > 0, cut

    def test_noise_term_against_the_fit_s_own_selection(self):
        # the fit's two tests (per reading beyond 4.5 robust scales, by neighbourhood means
        # beyond 4.5 of their spread) decide which readings are kept, not a cut-off; the model
        # replays them from the scan's InlierCut. Noise alone, against the stated noise term
        # (the model's error with its shared terms left out).
        self.hoods = core_icp.Neighbourhoods(self.on, 16)
        rng = np.random.default_rng(11)
        error = []
        for _ in range(self.SCANS // 4):
            measured = self.field + rng.uniform(-self.a, self.a, len(self.field))
            kept, _ = self.fit_selection(measured)
            error.append(measured[kept].max() - self.field[kept].max())
        rms = float(np.sqrt(np.mean(np.square(error))))
        stated = []
        for _ in range(6):
            measured = self.field + rng.uniform(-self.a, self.a, len(self.field))
            kept, cut = self.fit_selection(measured)
            r = fx.make_result(self.nominal, fx.displaced(self.nominal, self.on, measured),
                               inlier=kept)
            r = dataclasses.replace(r, pose_covariance=np.zeros((6, 6)), inlier_cut=cut)
            _, terms, _ = U.worst_terms(r, np.flatnonzero(kept), self.model,
                                        np.flatnonzero(~kept))
            stated.append(terms["noise_mm"])
        print("censored worst, the fit's selection, noise alone: simulated RMS %.2f um, "
              "stated %.2f um" % (rms * 1e3, np.mean(stated) * 1e3))
        self.assertLess(abs(np.mean(stated) / rms - 1.0), 0.1)

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
