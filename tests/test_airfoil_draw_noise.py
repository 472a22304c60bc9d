"""The airfoil draws' sensor noise (inspection.airfoil_uncertainty.point_noise_model) against the
simulated sensor's own readings (rig.sensor.SensorModel.read): a reading errs along its beam
by sigma_beam(SNR), so the draws lay it there, not along the profile's normal. And the draws'
base (inspection.airfoil_uncertainty.beam_feet): each reading's beam where it meets a profile, against the
line-circle intersection in closed form."""
import dataclasses
import unittest

import numpy as np

from BladeInspect.core import airfoil as kernel
from BladeInspect.inspection import airfoil_measure as measure_mod
from BladeInspect.inspection import airfoil_uncertainty as draws_mod
from BladeInspect.rig.sensor import SensorModel
from tests import inspection_fixtures as fx
from tests.test_worst_uncertainty import head_on_readings

READINGS = 4000


class DrawNoiseAlongTheBeam(unittest.TestCase):
    def test_against_the_sensors_readings(self):
        nominal = fx.demo_nominal()
        on, normal, angles, beams, pick, cos = head_on_readings(nominal)
        sensor = SensorModel()
        incidence = np.arccos(np.clip(cos, -1.0, 1.0))
        snr = sensor.snr(np.full(len(on), sensor.standoff), incidence)
        result = dataclasses.replace(
            fx.make_result(nominal, on, columns={"angle_deg": angles[pick]}), snr=snr)
        idx = np.arange(0, len(on), 60)
        sigma, spread, along, unit = draws_mod.point_noise_model(result, idx, sensor, 0.003,
                                                                normal[idx])
        np.testing.assert_allclose(along, beams[pick][idx], atol=1e-9)
        rng = np.random.default_rng(3)
        d = np.full(READINGS, sensor.standoff)
        for j, i in enumerate(idx):
            reading, _ = sensor.read(d, np.full(READINGS, incidence[i]), rng)
            err = reading - d
            # the sensor's rare gross errors (0.1 mm and more) are the fit's to reject
            err = err[np.isfinite(err) & (np.abs(err) < 5.0 * sensor.accuracy)]
            with self.subTest(point=int(i), incidence_deg=float(np.degrees(incidence[i]))):
                self.assertAlmostEqual(spread[j], np.std(err), delta=0.05 * np.std(err))
                # the deviations' model is the normal part of that error
                self.assertAlmostEqual(sigma[j], np.std(err) * cos[i],
                                       delta=0.05 * np.std(err) * cos[i])
        x = unit(rng, 100000)
        self.assertAlmostEqual(float(np.std(x)), 1.0, delta=0.01)


RADIUS = 3.0


def circle_profile():
    a = np.linspace(0.0, 2.0 * np.pi, 4000, endpoint=False)
    return kernel.Profile(RADIUS * np.column_stack([np.cos(a), np.sin(a)]))


def tilted_beams(normal, rng, max_deg):
    """Unit beams against the outward normals, each turned by an incidence uniform in
    +-max_deg."""
    tilt = np.radians(rng.uniform(-max_deg, max_deg, len(normal)))
    c, s = np.cos(tilt), np.sin(tilt)
    return -np.column_stack([c * normal[:, 0] - s * normal[:, 1],
                             s * normal[:, 0] + c * normal[:, 1]])


def readings_on_circle(rng, n, error_mm):
    """(true points on the circle, their readings moved along the beams, unit beams): beams
    at incidences up to 80 deg against the inward normal, errors uniform in +-error_mm."""
    a = rng.uniform(0.0, 2.0 * np.pi, n)
    normal = np.column_stack([np.cos(a), np.sin(a)])
    beams = tilted_beams(normal, rng, 80.0)
    true = RADIUS * normal
    return true, true + rng.uniform(-error_mm, error_mm, n)[:, None] * beams, beams


def line_circle_hit(p, b):
    """The point of the line p + t b nearer p on the circle |x| = RADIUS (closed form)."""
    pb, pp = np.einsum("ij,ij->i", p, b), np.einsum("ij,ij->i", p, p)
    root = np.sqrt(pb ** 2 - (pp - RADIUS ** 2))
    t = np.where(np.abs(-pb - root) < np.abs(-pb + root), -pb - root, -pb + root)
    return p + t[:, None] * b


class DrawsBaseAlongTheBeam(unittest.TestCase):
    def test_the_beam_meets_the_circle_where_the_closed_form_says(self):
        profile = circle_profile()
        for seed in range(4):
            rng = np.random.default_rng(seed)
            true, read, beams = readings_on_circle(rng, 300, 0.02)
            _, closest = profile.closest(read)
            feet = draws_mod.beam_feet(profile, read, closest, beams, np.full(300, 1.0))
            with self.subTest(seed=seed):
                np.testing.assert_allclose(feet, line_circle_hit(read, beams), atol=2e-7)
                np.testing.assert_allclose(feet, true, atol=2e-7)

    def test_a_beam_that_misses_within_reach_keeps_the_closest_point(self):
        profile = circle_profile()
        true, read, beams = readings_on_circle(np.random.default_rng(7), 50, 0.02)
        _, closest = profile.closest(read)
        feet = draws_mod.beam_feet(profile, read, closest, beams, np.full(50, 1e-9))
        np.testing.assert_array_equal(feet, closest)
        # a beam along the tangent never meets the circle near the point
        tangent = np.column_stack([-read[:, 1], read[:, 0]]) / RADIUS
        feet = draws_mod.beam_feet(profile, read, closest, tangent, np.full(50, 0.05))
        np.testing.assert_allclose(feet, closest, atol=1e-12)

    def test_the_scans_noise_along_the_surface_is_taken_out(self):
        """On the smooth fit of noisy readings, the closest points keep each reading's error
        along the surface (e sin theta, white); the beam's feet leave the fit's own error (its
        smooth normal error times tan theta), whose point-to-point part is small."""
        rng = np.random.default_rng(11)
        a = np.linspace(0.0, 2.0 * np.pi, 3000, endpoint=False)
        normal = np.column_stack([np.cos(a), np.sin(a)])
        beams = tilted_beams(normal, rng, 70.0)
        true = RADIUS * normal
        read = true + rng.uniform(-0.006, 0.006, len(a))[:, None] * beams
        smooth = kernel.Profile(read, 0.006 / np.sqrt(3.0))     # sigma_beam: >= the normal noise
        _, closest = smooth.closest(read)
        feet = draws_mod.beam_feet(smooth, read, closest, beams, np.full(len(a), 0.1))

        def white_along_surface(points):
            e = RADIUS * np.angle(np.exp(1j * (np.arctan2(points[:, 1], points[:, 0]) - a)))
            return np.sqrt(np.mean(np.diff(e) ** 2) / 2.0)
        kept = white_along_surface(closest)
        left = white_along_surface(feet)
        self.assertGreater(kept, 1.5e-3)            # ~ 3.5 um rms x sin(theta)
        self.assertLess(left, 0.25 * kept)


class BeamsCarriedIntoThePlane(unittest.TestCase):
    def test_as_into_plane_carries_a_move_along_the_beam(self):
        """_into_plane is affine in the point for fixed normals: a move eps b of a point turns
        into the in-plane move eps _beams_in_plane(b)."""
        from BladeInspect.cad.airfoil_sections import plane_frame
        rng = np.random.default_rng(5)
        for normal in ((0.0, 0.0, 1.0), (0.1, -0.2, 1.0)):
            frame = plane_frame((1.0, 2.0, 3.0), normal)
            n = 200
            surface = rng.standard_normal((n, 3))
            surface[:, :2] *= 4.0      # mostly across the plane normal, some inclined
            surface /= np.linalg.norm(surface, axis=1)[:, None]
            beams = rng.standard_normal((n, 3))
            beams /= np.linalg.norm(beams, axis=1)[:, None]
            x0 = frame.to_3d(rng.uniform(-5, 5, (n, 2))) + 0.01 * rng.standard_normal((n, 1)) \
                * frame.normal
            eps = 1e-3
            moved = frame.to_2d(measure_mod.into_plane(x0 + eps * beams, surface, frame.origin,
                                                    frame.normal))
            still = frame.to_2d(measure_mod.into_plane(x0, surface, frame.origin, frame.normal))
            with self.subTest(plane_normal=normal):
                np.testing.assert_allclose(moved - still,
                                           eps * draws_mod._beams_in_plane(beams, surface, frame),
                                           atol=1e-12)


if __name__ == "__main__":
    unittest.main()
