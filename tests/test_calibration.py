"""Rotary-axis calibration with a reference sphere: the analytic sphere part, the axis from
centres turned about a known axis (closed form), and the whole calibration on the simulated
rig with injected axis offset and tilt, judged against the injected truth."""
import json
import os
import tempfile
import unittest

import numpy as np

from BladeInspect.core.errors import InputError
from BladeInspect.measurement import calibration as cal
from tests.helpers import rodrigues


def tilted_axis(tilt_z_deg, tilt_x_deg):
    """+Y leaned by the two tilts: towards +X (about Z) and towards +Z (about X)."""
    d = np.array([np.tan(np.radians(tilt_z_deg)), 1.0, np.tan(np.radians(tilt_x_deg))])
    return d / np.linalg.norm(d)


class TestSpherePart(unittest.TestCase):
    def test_raycast_closed_form(self):
        rng = np.random.default_rng(0)
        c, R = np.array([3.0, -2.0, 5.0]), 12.5
        part = cal.SpherePart(R, c)
        # Vertical rays at random x, y: the hit height is c_z + sqrt(R^2 - rho^2).
        xy = c[:2] + rng.uniform(-15, 15, (500, 2))
        origins = np.column_stack([xy, np.full(500, 60.0)])
        down = np.tile([0.0, 0.0, -1.0], (500, 1))
        t, face, normal = part.raycast(origins, down)
        rho2 = np.sum((xy - c[:2]) ** 2, axis=1)
        inside = rho2 < R * R
        np.testing.assert_allclose(60.0 - t[inside], c[2] + np.sqrt(R * R - rho2[inside]),
                                   atol=1e-10)
        self.assertTrue(np.all(np.isnan(t[~inside])))
        hits = origins[inside] + t[inside, None] * down[inside]
        np.testing.assert_allclose(normal[inside], (hits - c) / R, atol=1e-12)

    def test_ray_from_inside_hits_the_far_wall(self):
        part = cal.SpherePart(2.0)
        t, _, _ = part.raycast(np.zeros((1, 3)), np.array([[1.0, 0, 0]]))
        self.assertAlmostEqual(t[0], 2.0)
        t, _, _ = part.raycast(np.array([[5.0, 0, 0]]), np.array([[1.0, 0, 0]]))
        self.assertTrue(np.isnan(t[0]))


class TestAxisFromCentres(unittest.TestCase):
    def test_exact_centres_give_the_axis(self):
        rng = np.random.default_rng(1)
        for _ in range(20):
            direction = tilted_axis(*rng.uniform(-2, 2, 2))
            point = np.array([rng.uniform(-1, 1), 0.0, rng.uniform(-1, 1)])
            start = np.array([rng.uniform(20, 60), rng.uniform(0, 50), rng.uniform(-10, 10)])
            angles = np.sort(rng.choice(np.arange(0, 360, 15), size=7, replace=False))
            centres = np.vstack([rodrigues(start, a, direction, point) for a in angles])
            axis = cal.axis_from_centres(centres, angles)
            np.testing.assert_allclose(axis["point"], point, atol=1e-9)
            np.testing.assert_allclose(axis["direction"], direction, atol=1e-11)
            self.assertLess(np.max(axis["angle_model_residual_mm"]), 1e-9)

    def test_direction_follows_the_angle_sense(self):
        # Turning by -a about -u is turning by a about u: the sign is fixed by the angles.
        point, u = np.zeros(3), tilted_axis(0.5, -0.3)
        start = np.array([40.0, 30.0, 0.0])
        angles = np.arange(0, 360, 45.0)
        centres = np.vstack([rodrigues(start, -a, u, point) for a in angles])
        axis = cal.axis_from_centres(centres, angles)
        np.testing.assert_allclose(axis["direction"], -u, atol=1e-11)

    def test_wrong_angles_show_in_the_angle_model(self):
        point, u = np.zeros(3), np.array([0.0, 1.0, 0.0])
        angles = np.arange(0, 360, 45.0)
        centres = np.vstack([rodrigues([40.0, 30.0, 0.0], a, u, point) for a in angles])
        told = angles.copy()
        told[3] += 0.01    # one angle reported 0.01 deg off: 7 um at 40 mm
        axis = cal.axis_from_centres(centres, told)
        self.assertGreater(np.max(axis["angle_model_residual_mm"]), 0.004)

    def test_too_few_angles(self):
        with self.assertRaises(InputError):
            cal.axis_from_centres(np.eye(3)[:2], [0.0, 90.0])


def simulated_sphere_rig(seed, offset_mm=0.2, tilt_deg=0.1, stage_scale=(0.0, 0.0, 0.0),
                         position_error=2.0):
    """A SimulatedRig whose TRUE axis is off the nominal by the given offset (in a random
    direction across it) and tilt (in a random direction), the sphere mounted within
    position_error of where calibrate() is told to look."""
    from BladeInspect.core import transforms as tf
    from BladeInspect.rig.kinematics import RigKinematics
    from BladeInspect.rig.simulated import SimulatedRig
    rng = np.random.default_rng(seed)
    lean = rng.uniform(0, 2 * np.pi)
    direction = tilted_axis(tilt_deg * np.cos(lean), tilt_deg * np.sin(lean))
    shift = rng.uniform(0, 2 * np.pi)
    point = offset_mm * np.array([np.cos(shift), 0.0, np.sin(shift)])
    truth = RigKinematics(axis_point=point, axis_direction=direction, stage_scale=stage_scale)
    mount = np.asarray(cal.DEFAULT_SPHERE_POSITION) + rng.uniform(-1, 1, 3) * position_error
    rig = SimulatedRig(cal.SpherePart(12.5), tf.make_transform(np.eye(3), -mount),
                       kinematics=truth, seed=seed)
    return rig, truth


class TestCalibrateOnSimulatedRig(unittest.TestCase):
    def test_recovers_injected_offset_and_tilt(self):
        for seed in range(4):
            rig, truth = simulated_sphere_rig(seed)
            result = cal.calibrate(rig, 25.0)
            # The nominal axis passes through the origin, so the truth's point is where it
            # crosses y = 0 as well: compare like with like.
            self.assertLess(np.linalg.norm(np.subtract(result["axis_point"], truth.axis_point)),
                            0.002, seed)
            angle = np.degrees(np.arccos(np.clip(np.dot(result["axis_direction"],
                                                        truth.axis_direction), -1, 1)))
            self.assertLess(angle, 0.001, seed)
            self.assertAlmostEqual(result["measured_diameter_mm"], 25.0, delta=0.01)

    def test_rig_json_round_trip(self):
        from BladeInspect.rig.kinematics import RigKinematics
        rig, truth = simulated_sphere_rig(7)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "RIG.json")
            result = cal.calibrate(rig, 25.0, out_path=path)
            loaded = RigKinematics.from_json(path)
            np.testing.assert_allclose(loaded.axis_point, result["axis_point"], atol=1e-12)
            np.testing.assert_allclose(loaded.axis_direction, result["axis_direction"], atol=1e-12)
            self.assertEqual(os.listdir(tmp), ["RIG.json"])
            json.dumps({k: v for k, v in result.items() if k != "kinematics"})

    def test_residual_returns_to_noise_with_calibration(self):
        from BladeInspect.rig.kinematics import RigKinematics
        rig, truth = simulated_sphere_rig(3)
        calibrated = cal.calibrate(rig, 25.0)["kinematics"]
        angles = (0.0, 60.0, 120.0, 180.0, 240.0, 300.0)
        before = cal.sphere_residual(rig, RigKinematics(), angles=angles)
        after = cal.sphere_residual(rig, calibrated, angles=angles)
        # The sensor's own noise at these readings (head-on to ~35 deg): sigma(SNR).
        noise = rig.sensor.sigma(rig.sensor.snr(np.full(1, 44.0), np.radians([20.0])))[0]
        self.assertGreater(before["rms_mm"], 10 * after["rms_mm"])
        self.assertLess(abs(after["rms_mm"] - noise), 0.2 * noise)

    def test_stage_error_shows_in_the_circle_residual(self):
        clean = cal.calibrate(simulated_sphere_rig(5)[0], 25.0)
        scaled = cal.calibrate(simulated_sphere_rig(5, stage_scale=(2e-4, 0.0, -2e-4))[0], 25.0)
        self.assertGreater(scaled["circle_residual_rms_mm"], 5 * clean["circle_residual_rms_mm"])

    def test_sphere_not_found(self):
        rig, _ = simulated_sphere_rig(1)
        with self.assertRaises(InputError) as ctx:
            cal.calibrate(rig, 25.0, sphere_position=(60.0, 100.0, 0.0))
        message = str(ctx.exception)
        self.assertIn("sphere not found", message)
        self.assertNotIn("\n", message)

    def test_wrong_diameter_and_too_few_angles(self):
        rig, _ = simulated_sphere_rig(2)
        with self.assertRaises(InputError) as ctx:
            cal.calibrate(rig, 24.0)
        self.assertIn("--sphere-diameter", str(ctx.exception))
        with self.assertRaises(InputError):
            cal.calibrate(rig, 25.0, angles=(0, 90, 180))
        with self.assertRaises(InputError):
            cal.calibrate(rig, -1.0)


class TestCalibrationCommand(unittest.TestCase):
    def test_run_calibration_on_the_simulated_rig(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "RIG.json")
            result = cal.run_calibration(path, "sim", 25.0, seed=9, axis_offset_mm=0.2,
                                         axis_tilt_deg=0.1)
            with open(path) as fh:
                saved = json.load(fh)
        truth = result["truth"]
        self.assertAlmostEqual(np.linalg.norm(truth["axis_point"]), 0.2, places=12)
        self.assertLess(np.linalg.norm(np.subtract(saved["axis_point"], truth["axis_point"])),
                        0.002)
        self.assertLess(np.degrees(np.arccos(np.dot(saved["axis_direction"],
                                                    truth["axis_direction"]))), 0.001)

    def test_same_axis_over_the_serial_driver(self):
        # The simulated device on a pseudo-terminal gives the very readings of the rig in
        # process, so the serial path must find exactly the same axis.
        from BladeInspect.rig.serial_rig import SerialRig
        from BladeInspect.rig.simrig_device import SimRigDevice
        angles = cal.DEFAULT_ANGLES[::2]
        device = SimRigDevice(cal.simulated_calibration_rig(seed=4, axis_offset_mm=0.2,
                                                            axis_tilt_deg=0.1)[0]).start()
        self.addCleanup(device.stop)
        rig = SerialRig(device.port_url, timeout_s=5)
        self.addCleanup(rig.close)
        over_serial = cal.calibrate(rig, 25.0, angles=angles)
        in_process = cal.calibrate(cal.simulated_calibration_rig(
            seed=4, axis_offset_mm=0.2, axis_tilt_deg=0.1)[0], 25.0, angles=angles)
        np.testing.assert_allclose(over_serial["axis_point"], in_process["axis_point"],
                                   atol=1e-12)
        np.testing.assert_allclose(over_serial["axis_direction"],
                                   in_process["axis_direction"], atol=1e-12)

    def test_bad_rig_spec(self):
        with self.assertRaises(InputError):
            cal.run_calibration(None, "usb")


if __name__ == "__main__":
    unittest.main()
