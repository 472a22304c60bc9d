"""Rig kinematics against closed forms: the machine-point convention, turns about the rotary
axis (points on the axis stay, quarter turns by hand), round trips, the stage error model and
RIG.json."""
import json
import os
import tempfile
import unittest

import numpy as np

from BladeInspect.core.errors import InputError
from BladeInspect.rig.kinematics import RigKinematics
from tests.helpers import rodrigues


class TestKinematics(unittest.TestCase):
    def test_machine_point_convention(self):
        k = RigKinematics()
        stage = np.array([[1.0, 2.0, 60.0], [-5.0, 7.5, 50.0]])
        np.testing.assert_allclose(k.machine_point(stage, [44.0, 43.5]),
                                   [[1.0, 2.0, 16.0], [-5.0, 7.5, 6.5]])

    def test_quarter_turns_about_nominal_axis(self):
        k = RigKinematics()
        # Turning +90 deg about +Y takes +Z to +X: a table point (0,0,1) is at machine (1,0,0),
        # and a machine point (1, 5, 0) seen at A=90 is table (0, 5, 1).
        np.testing.assert_allclose(k.machine_point_of_table([[0, 3, 1.0]], 90), [[1, 3, 0]],
                                   atol=1e-15)
        np.testing.assert_allclose(k.table_point([[1.0, 5, 0]], 90), [[0, 5, 1]], atol=1e-15)
        np.testing.assert_allclose(k.table_point([[2.0, 5, 3.0]], 180), [[-2, 5, -3]],
                                   atol=1e-14)

    def test_points_on_the_axis_do_not_move(self):
        rng = np.random.default_rng(2)
        d = rng.standard_normal(3)
        k = RigKinematics(axis_point=[3.0, -1.0, 2.0], axis_direction=d)
        on_axis = np.array([3.0, -1.0, 2.0]) + np.outer(rng.uniform(-50, 50, 10), d)
        for a in rng.uniform(-360, 360, 5):
            np.testing.assert_allclose(k.table_point(on_axis, a), on_axis, atol=1e-12)

    def test_against_rodrigues_and_round_trip(self):
        rng = np.random.default_rng(4)
        for _ in range(20):
            point = rng.uniform(-2, 2, 3)
            direction = np.array([0, 1, 0]) + rng.normal(0, 0.01, 3)
            k = RigKinematics(axis_point=point, axis_direction=direction)
            table = rng.uniform(-40, 40, (30, 3))
            a = rng.uniform(-400, 400)
            machine = k.machine_point_of_table(table, a)
            np.testing.assert_allclose(machine, rodrigues(table, a, direction, point),
                                       atol=1e-11)
            np.testing.assert_allclose(k.table_point(machine, a), table, atol=1e-11)
            T = k.table_to_machine_transform(a)
            np.testing.assert_allclose(table @ T[:3, :3].T + T[:3, 3], machine, atol=1e-11)

    def test_table_frame_is_rigid_across_angles(self):
        # A part point seen at several angles maps to one table point.
        k = RigKinematics(axis_point=[0.5, 0, -0.3], axis_direction=[0.001, 1, 0.002])
        p = np.array([[12.0, 40.0, 7.0]])
        for a in (0.0, 33.0, 90.0, 181.0, -75.0):
            np.testing.assert_allclose(k.table_point(k.machine_point_of_table(p, a), a), p,
                                       atol=1e-12)

    def test_stage_error_model(self):
        k = RigKinematics(stage_scale=[1e-4, -2e-4, 5e-5], stage_squareness=[1e-4, 0, -3e-4])
        stage = np.array([[100.0, 50.0, 60.0]])
        x = 100 * (1 + 1e-4) + 1e-4 * 50
        y = 50 * (1 - 2e-4) - 3e-4 * 60
        z = 60 * (1 + 5e-5)
        np.testing.assert_allclose(k.machine_point(stage, [44.0]), [[x, y, z - 44.0]],
                                   atol=1e-12)

    def test_json_round_trip_and_bad_files(self):
        k = RigKinematics(axis_point=[0.1, 0, -0.2], axis_direction=[0.01, 1, 0],
                          stage_scale=[1e-5, 0, 0])
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "RIG.json")
            k.to_json(path)
            back = RigKinematics.from_json(path)
            np.testing.assert_array_equal(back.axis_point, k.axis_point)
            np.testing.assert_array_equal(back.axis_direction, k.axis_direction)
            np.testing.assert_array_equal(back.stage_scale, k.stage_scale)
            with self.assertRaises(InputError):
                RigKinematics.from_json(os.path.join(tmp, "missing.json"))
            with open(path, "w") as f:
                f.write("{not json")
            with self.assertRaises(InputError) as cm:
                RigKinematics.from_json(path)
            self.assertIn(path, str(cm.exception))
            with open(path, "w") as f:
                json.dump({"axis_direction": [0, 0, 0]}, f)
            with self.assertRaises(InputError):
                RigKinematics.from_json(path)


if __name__ == "__main__":
    unittest.main()
