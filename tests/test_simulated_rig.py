"""The simulated rig against closed forms: readings on a sphere at a known pose and rotary
angle, coverage, error fields, determinism per (seed, pass), time, limits, fixture poses and
speed (at least 10x the real sensor's 9000 points/s, for the rig alone and on the demo
blade's CAD)."""
import unittest

import numpy as np

from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import DeviceError
from BladeInspect.rig.base import AxisLimits
from BladeInspect.rig.simulated import (SimulatedRig, make_bump, make_thickening,
                                        random_fixture_pose)
from tests.helpers import best_cpu_seconds, rodrigues
from tests.rig_parts import Sphere


class TestMeasure(unittest.TestCase):
    def setUp(self):
        rng = np.random.default_rng(5)
        self.table_to_cad = tf.random_transform(rng, 30.0)
        self.sphere = Sphere(15.0, center=[2.0, -3.0, 4.0])
        # The sphere's centre in the table frame, then in the machine frame at A=40 deg
        # (turned forward about +Y through the origin).
        cad_to_table = np.linalg.inv(self.table_to_cad)
        self.centre_table = cad_to_table[:3, :3] @ self.sphere.center + cad_to_table[:3, 3]
        self.angle = 40.0
        self.centre_machine = rodrigues(self.centre_table, self.angle, [0, 1, 0])[0]

    def grid(self, half=14.0, n=41):
        c = self.centre_machine
        xs, ys = np.meshgrid(np.linspace(-half, half, n), np.linspace(-half, half, n))
        z = c[2] + 15.0 + 44.0
        return np.column_stack([c[0] + xs.ravel(), c[1] + ys.ravel(), np.full(xs.size, z)])

    def test_readings_on_a_sphere_closed_form(self):
        rig = SimulatedRig(self.sphere, self.table_to_cad, seed=1, limits=AxisLimits(
            x=(-500, 500), y=(-500, 500), z=(-500, 500)))
        stage = self.grid()
        reading, snr = rig.measure(stage, self.angle, 0)
        c = self.centre_machine
        rho2 = (stage[:, 0] - c[0]) ** 2 + (stage[:, 1] - c[1]) ** 2
        top = c[2] + np.sqrt(np.clip(225.0 - rho2, 0, None))
        expected = stage[:, 2] - top
        incidence = np.arccos(np.sqrt(np.clip(225.0 - rho2, 0, None)) / 15.0)
        valid = np.isfinite(reading)
        self.assertGreater(valid.sum(), 0.5 * len(stage))
        bound = 0.006 * np.sqrt(100.0 / snr[valid]) + 1e-4
        err = np.abs(reading[valid] - expected[valid])
        gross = err > bound
        # Gross errors only where the SNR is low; everything else within the noise bound.
        self.assertTrue(np.all(snr[valid][gross] < 25.0))
        self.assertLess(gross.mean(), 0.05)
        self.assertTrue(np.all(incidence[valid] <= np.radians(85.0) + 1e-9))
        np.testing.assert_allclose(snr[valid], 100 * np.cos(incidence[valid])
                                   * (1 - 0.5 * ((expected[valid] - 44) / 8) ** 2), rtol=1e-6)
        # Misses of the sphere never read.
        self.assertFalse(np.any(valid[rho2 > 225.0]))

    def test_deterministic_per_seed_and_pass(self):
        rig = SimulatedRig(self.sphere, self.table_to_cad, seed=3)
        other = SimulatedRig(self.sphere, self.table_to_cad, seed=3)
        stage = self.grid(n=15)
        a = rig.measure(stage, self.angle, 7)
        rig.measure(stage, self.angle, 2)
        np.testing.assert_array_equal(a[0], other.measure(stage, self.angle, 7)[0])
        b = rig.measure(stage, self.angle, 8)
        ok = np.isfinite(a[0]) & np.isfinite(b[0])
        self.assertGreater(np.mean(a[0][ok] != b[0][ok]), 0.5)

    def test_bump_raises_the_surface(self):
        # The machine top of the sphere maps to this CAD point; a bump there of 0.05 mm.
        machine_top = self.centre_machine + [0, 0, 15.0]
        table_top = rodrigues(machine_top, -self.angle, [0, 1, 0])[0]
        top_cad = tf.apply_transform(self.table_to_cad, table_top[None])[0]
        bump = make_bump(top_cad, 3.0, 0.05)
        plain = SimulatedRig(self.sphere, self.table_to_cad, seed=2)
        bumped = SimulatedRig(self.sphere, self.table_to_cad, seed=2, error_field=bump)
        stage = np.array([machine_top + [dx, 0, 44.0] for dx in (0.0, 1.0, 5.0)])
        r0, _ = plain.measure(stage, self.angle, 0)
        r1, _ = bumped.measure(stage, self.angle, 0)
        # Same noise stream: the difference is the bump along the beam, h / cos(incidence).
        h1 = 0.05 * (1 - (1.0 / 3.0) ** 2) ** 3    # surface point ~1 mm from the top
        cos1 = np.sqrt(225 - 1) / 15
        self.assertAlmostEqual(r0[0] - r1[0], 0.05, delta=2e-4)
        self.assertAlmostEqual(r0[1] - r1[1], h1 / cos1, delta=2e-3)
        self.assertAlmostEqual(r0[2] - r1[2], 0.0, delta=2e-4)

    def test_thickening_near_a_curve(self):
        curve = np.column_stack([np.linspace(0, 10, 101), np.zeros(101), np.zeros(101)])
        field = make_thickening(curve, 1.0, 0.02)
        np.testing.assert_allclose(field(np.array([[5.0, 0, 0], [5.0, 0.5, 0], [5, 2.0, 0]])),
                                   [0.02, 0.02 * 0.75 ** 3, 0.0], atol=1e-12)


class TestRigInterface(unittest.TestCase):
    def test_scan_path_passes_time_and_limits(self):
        part = Sphere(10.0, center=[0, 0, 0])
        rig = SimulatedRig(part, np.eye(4), seed=0, feed_mm_s=20.0, rapid_mm_s=50.0,
                           rotary_deg_s=30.0)
        rig.move_to(x=-5.0, y=0.0, z=54.0, a=0.0)
        t0 = rig.elapsed_s
        path = np.column_stack([np.linspace(-5, 5, 201), np.zeros(201), np.full(201, 54.0)])
        r1 = rig.scan_path(path, 0.0)
        # 10 mm at 20 mm/s; 201 triggers at 9000/s take less.
        self.assertAlmostEqual(rig.elapsed_s - t0, 0.5, places=9)
        self.assertEqual(r1.meta["pass_index"], 0)
        r2 = rig.scan_path(path, 0.0)
        self.assertEqual(r2.meta["pass_index"], 1)
        self.assertEqual(rig.pass_index, 2)
        # The path's return to its start (10 mm rapid) plus a 90 deg turn: the turn is slower.
        t1 = rig.elapsed_s
        rig.scan_path(path, 90.0)
        self.assertAlmostEqual(rig.elapsed_s - t1, 3.0 + 0.5, places=9)
        np.testing.assert_allclose(rig.position(), (5.0, 0.0, 54.0, 90.0))
        rig.set_pass_index(1)
        again = rig.scan_path(path, 0.0)
        np.testing.assert_array_equal(again.reading_mm, r2.reading_mm)
        with self.assertRaises(DeviceError):
            rig.scan_path(path + [0, 0, 500.0], 0.0)
        with self.assertRaises(DeviceError):
            rig.move_to(x=1000.0)

    def test_speed_at_least_ten_times_the_sensor(self):
        # The rig's own cost: a part whose ray cast is nearly free (the CAD's is the CAD's;
        # bench/bench_scan.py measures the demo blade).
        part = Sphere(40.0, center=[0, 60.0, 0])
        rig = SimulatedRig(part, random_fixture_pose(np.random.default_rng(0),
                                                     cad_center=(0, 60.0, 0)), seed=0)
        n = 100000
        path = np.column_stack([np.tile(np.linspace(-30, 30, 1000), 100),
                                np.repeat(np.linspace(30, 90, 100), 1000), np.full(n, 80.0)])
        spent, readings = best_cpu_seconds(lambda: rig.scan_path(path, 0.0),
                                           enough=n / 90000.0)
        self.assertGreater(np.isfinite(readings.reading_mm).mean(), 0.3)
        self.assertLess(spent, n / 90000.0, "%.0f points/s" % (n / spent))


class TestDemoBladeSpeed(unittest.TestCase):
    def test_hundred_thousand_points_on_the_blade_ten_times_the_sensor(self):
        """Issue 4: a scan of 100,000 points simulates at least 10x faster than the sensor's
        9000 points/s, exact ray cast on the demo blade's CAD and sensor model included. The
        setpoints are a complete-scan raster at one angle, so every point reads the blade.
        CPU time, the best of up to five runs: other jobs share the machine."""
        from BladeInspect.measurement.complete import plan_complete
        from BladeInspect.measurement.scan import demo_nominal
        from BladeInspect.rig.simulated import simulated_rig_for
        nominal = demo_nominal()
        rig = simulated_rig_for(nominal, seed=0)
        plan = plan_complete(nominal, rig.table_to_cad, rig.sensor, rig.limits, pitch=0.05,
                             angles_deg=[0.0])
        path = plan.stage_xyz[:100000]
        self.assertEqual(len(path), 100000)
        best, readings = best_cpu_seconds(lambda: rig.scan_path(path, 0.0), tries=5,
                                          enough=len(path) / 90000.0)
        self.assertGreater(np.isfinite(readings.reading_mm).mean(), 0.99)
        self.assertLess(best, len(path) / 90000.0, "%.0f points/s" % (len(path) / best))


class TestFixturePose(unittest.TestCase):
    def test_span_along_axis_within_tilt_and_offset(self):
        rng = np.random.default_rng(9)
        spins = []
        for _ in range(200):
            T = random_fixture_pose(rng, blade_span_axis=(0, 0, 1), cad_center=(1.0, 2.0, 35.0))
            R = T[:3, :3]
            self.assertAlmostEqual(np.linalg.det(R), 1.0, places=12)
            np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
            table_from_cad = np.linalg.inv(T)
            span_table = table_from_cad[:3, :3] @ [0, 0, 1.0]
            self.assertLessEqual(np.degrees(np.arccos(span_table[1])), 5.0 + 1e-9)
            centre = table_from_cad[:3, :3] @ [1.0, 2.0, 35.0] + table_from_cad[:3, 3]
            self.assertLessEqual(np.hypot(centre[0], centre[2]), 10.0 + 1e-9)
            self.assertAlmostEqual(centre[1], 60.0, places=9)
            x_table = table_from_cad[:3, :3] @ [1.0, 0, 0]
            spins.append(np.degrees(np.arctan2(x_table[2], x_table[0])))
        # Any angle about the axis: all four quadrants occur.
        self.assertEqual(len(set(np.floor(np.array(spins) / 90.0))), 4)


if __name__ == "__main__":
    unittest.main()
