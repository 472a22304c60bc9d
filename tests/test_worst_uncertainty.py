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


def head_on_readings(nominal, min_cos=0.3):
    """The demo cloud on the nominal, each point read from the rotary angle (10 deg steps) that
    sees it most head-on, those seen at a cosine above ``min_cos``: (points, CAD normals, the
    angles, their beams in the table frame, each point's angle index, its cosine)."""
    from BladeInspect.rig.kinematics import RigKinematics
    on = demo_cloud(nominal, lambda p: np.zeros(len(p)))
    normal = nominal.signed_distance(on).normal
    angles = np.arange(0.0, 360.0, 10.0)
    k = RigKinematics()
    beams = np.array([k.rotation(a).T @ U.BEAM_MACHINE for a in angles])
    pick = np.argmin(normal @ beams.T, axis=1)
    cos = -(normal @ beams.T)[np.arange(len(on)), pick]
    seen = cos > min_cos
    return on[seen], normal[seen], angles, beams, pick[seen], cos[seen]


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



class SystematicThroughTheFitTest(unittest.TestCase):
    """The systematic term's coefficients (uncertainty.systematic_coefficients, a linearised
    fit) against the pipeline's own ICP run on points moved along their beams by a known bias:
    each deviation's change after the re-fit is s_i * bias."""

    def test_against_a_refit_with_a_known_bias(self):
        from BladeInspect.core import transforms as tf
        from BladeInspect.inspection import pipeline
        nominal = fx.demo_nominal()
        on, _, angles, beams, pick, _ = head_on_readings(nominal)
        result = fx.make_result(nominal, on, columns={"angle_deg": angles[pick]})
        np.testing.assert_allclose(U.beam_directions(result), beams[pick], atol=1e-12)
        bias = 0.005
        moved = on + bias * beams[pick]
        fit = pipeline.fine_register(moved, None, nominal, np.eye(4))
        # The weights the fit ran with (its robust weights drop the points it rejected), as a
        # RegistrationResult carries them.
        s = U.systematic_coefficients(dataclasses.replace(result, icp_weights=fit.weights))
        after = nominal.signed_distance(tf.apply_transform(fit.transform, moved)).distance
        change = after - result.deviation
        self.assertLess(np.max(np.abs(change - s * bias)), 0.05 * bias)
        # The fit takes up part of the bias: the coefficients are not simply beam . n.
        beta = np.einsum("ij,ij->i", beams[pick], result.normal)
        self.assertGreater(np.max(np.abs(s - beta)), 0.1)
        # ... by the rigid motion bias_take_up states (the airfoil draws move the points by
        # it, along the surface too): each point where the re-fit put it.
        b, r = U.bias_take_up(dataclasses.replace(result, icp_weights=fit.weights))
        np.testing.assert_allclose(b, beams[pick], atol=1e-12)
        model = moved - bias * (r[:3] + np.cross(r[3:], on - result.center))
        where = tf.apply_transform(fit.transform, moved)
        self.assertLess(np.max(np.linalg.norm(where - model, axis=1)), 0.05 * bias)

    def test_a_reading_past_the_end_takes_up_nothing(self):
        """A reading just past the blade's end has its foot on the face's edge and the normal
        p - c, square to a beam that read the side: its weight in the loop's fit sits at the
        sensor weights' grazing floor (41 against a median of 0.6 on the demo loop). The
        coefficients of the surface's points must still be those of a re-fit of the surface's
        readings, not a linearised fit held along the span by that one point."""
        from BladeInspect.core import transforms as tf
        from BladeInspect.inspection import pipeline
        nominal = fx.demo_nominal()
        on, normal, angles, beams, pick, _ = head_on_readings(nominal)
        low = int(np.argmin(on[:, 2]))
        past = on[low].copy()
        past[2] = -0.002                   # the demo blade's hub end is at z = 0
        # read by the beam square to the span that meets the side there most head-on
        level = np.flatnonzero(np.abs(beams[:, 2]) < 0.05)
        angle_past = level[np.argmin(beams[level] @ normal[low])]
        points = np.vstack([on, past])
        result = fx.make_result(nominal, points,
                                columns={"angle_deg": angles[np.append(pick, angle_past)]})
        self.assertLess(abs(beams[angle_past] @ result.normal[-1]),
                        np.cos(SensorModel().max_incidence_rad))
        bias = 0.005
        moved = on + bias * beams[pick]
        fit = pipeline.fine_register(moved, None, nominal, np.eye(4))
        weights = np.append(fit.weights, 70.0 * np.median(fit.weights))
        s = U.systematic_coefficients(dataclasses.replace(result, icp_weights=weights))
        after = nominal.signed_distance(tf.apply_transform(fit.transform, moved)).distance
        change = after - result.deviation[:-1]
        self.assertLess(np.max(np.abs(change - s[:-1] * bias)), 0.05 * bias)


if __name__ == "__main__":
    unittest.main()
