"""Paths planned from the CAD, judged by the simulator's truth: the demo blade clamped at random
fixture poses, the plan made with that pose, then every planned point mapped back into the CAD
frame with an independent rotation (Rodrigues' vector form) and measured by SimulatedRig."""
import json
import unittest

import numpy as np

from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import DeviceError, InputError
from BladeInspect.measurement import planning
from BladeInspect.rig.base import AxisLimits
from tests.helpers import demo_nominal


def machine_to_cad(points, angle_deg, table_to_cad):
    """Turn machine points back by the angle about the nominal axis (origin, +Y) with
    Rodrigues' formula, then into the CAD by the pose."""
    k = np.array([0.0, 1.0, 0.0])
    a = -np.radians(angle_deg)
    v = np.atleast_2d(points)
    table = v * np.cos(a) + np.cross(k, v) * np.sin(a) + np.outer(v @ k, k) * (1 - np.cos(a))
    return tf.apply_transform(table_to_cad, table)


def radius_of_curvature(points, normals):
    """Per point of a contour: arc length over normal turn between its neighbours (mm)."""
    step = np.linalg.norm(points[2:] - points[:-2], axis=1)
    turn = np.linalg.norm(normals[2:] - normals[:-2], axis=1)
    inner = step / np.maximum(turn, 1e-12)
    return np.concatenate([[inner[0]], inner, [inner[-1]]])


def incidence_of_snr(sensor, snr):
    """The incidence (deg) at which the sensor model gives this SNR at the range centre."""
    grid = np.radians(np.linspace(0.0, 89.0, 8901))
    model = planning.expected_snr(sensor, grid)
    order = np.argsort(model)
    return np.degrees(np.interp(snr, model[order], grid[order]))


class TestPlanOnSimulatedRig(unittest.TestCase):
    def check_pose(self, seed, heights):
        from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose
        nominal = demo_nominal()
        pose = random_fixture_pose(np.random.default_rng(seed))
        rig = SimulatedRig(nominal, pose, seed=seed)
        plan = planning.plan_sections(nominal, pose, heights, rig.sensor, rig.limits)
        self.assertEqual([s.height_pct for s in plan.sections], list(heights))
        standoff = rig.sensor.standoff
        edge_radius = [radius_of_curvature(s.target_cad, s.normal_cad) for s in plan.sections]
        seen = [np.zeros(s.n_points, int) for s in plan.sections]
        for path in plan.paths:
            section = plan.sections[path.section]
            seen[path.section][path.points] += 1
            self.assertTrue(np.all(section.angle_deg[path.points] == path.angle_deg))
            stage = plan.path_stage_xyz(path)
            planned_cad = machine_to_cad(stage - [0, 0, standoff], path.angle_deg, pose)
            off_plane = (planned_cad - section.plane_point) @ section.plane_normal
            self.assertLess(np.max(np.abs(off_plane)), 0.01)
            np.testing.assert_allclose(planned_cad, section.target_cad[path.points], atol=1e-9)
            # The incidence the plan states is the angle between the beam and the CAD normal
            # turned into the machine.
            normal_m = section.normal_cad[path.points] @ pose[:3, :3]
            k, a = np.array([0.0, 1.0, 0.0]), np.radians(path.angle_deg)
            normal_m = (normal_m * np.cos(a) + np.cross(k, normal_m) * np.sin(a)
                        + np.outer(normal_m @ k, k) * (1 - np.cos(a)))
            np.testing.assert_allclose(np.degrees(np.arccos(np.clip(normal_m[:, 2], -1, 1))),
                                       section.incidence_deg[path.points], atol=1e-6)
            readings = rig.scan_path(stage, path.angle_deg)
            self.assertTrue(np.all(np.isfinite(readings.reading_mm)))
            self.assertLess(np.max(np.abs(readings.reading_mm - standoff)), 0.2)
            measured = machine_to_cad(stage - np.outer(readings.reading_mm, [0, 0, 1]),
                                      path.angle_deg, pose)
            off_plane = (measured - section.plane_point) @ section.plane_normal
            self.assertLess(np.max(np.abs(off_plane)), 0.01)
            # The simulator's SNR comes from its own ray's normal: it must be what was planned.
            # On the flanks to 0.5 %; round an edge (radius of curvature under 1 mm) to 2 deg of
            # the incidence the SNR implies: on an edge of 0.2 mm radius a hit 5 um from the
            # target already turns the normal by 1.4 deg.
            flank = edge_radius[path.section][path.points] >= 1.0
            np.testing.assert_allclose(readings.snr[flank],
                                       section.expected_snr[path.points][flank], rtol=5e-3)
            np.testing.assert_allclose(incidence_of_snr(rig.sensor, readings.snr[~flank]),
                                       section.incidence_deg[path.points][~flank], atol=2.0)
        for counts in seen:
            self.assertTrue(np.all(counts == 1), "every planned point is on exactly one path")
        for section in plan.sections:
            self.assertLessEqual(section.incidence_deg.max(), planning.MAX_INCIDENCE_DEG)
            self.assertLessEqual(len(np.unique(section.angle_deg)), 8)
            steps = np.linalg.norm(np.diff(section.target_cad, axis=0), axis=1)
            self.assertAlmostEqual(np.median(steps), 0.1, delta=0.005)
            np.testing.assert_allclose(section.expected_standoff_mm, standoff, atol=1e-6)
        return nominal, plan

    def test_three_sections_at_a_random_fixture_pose(self):
        nominal, plan = self.check_pose(11, (10.0, 50.0, 90.0))
        # The targets lie on the CAD: OCC's own distance on a few of them.
        import Part
        from FreeCAD import Vector
        targets = plan.sections[1].target_cad[::97]
        for p in targets:
            d = nominal.shape.distToShape(Part.Vertex(Vector(*p)))[0]
            self.assertLess(d, 1e-5)
        doc = json.loads(plan.to_json())
        self.assertEqual(doc["n_points"], plan.n_points)
        self.assertEqual(len(doc["sections"]), 3)
        self.assertEqual(sum(len(p["points"]) for p in doc["paths"]), plan.n_points)
        self.assertEqual(doc["sections"][0]["plane"]["normal"], plan.span_axis.tolist())

    def test_another_pose(self):
        self.check_pose(12, (30.0, 70.0))

    def test_span_axis_is_the_blade_span(self):
        axis, _, lo, hi = planning.span_axis_of(demo_nominal())
        np.testing.assert_allclose(axis, [0, 0, 1], atol=0.05)
        self.assertGreater(axis[2], 0)   # hub to tip
        axis, _, lo, hi = planning.span_axis_of(demo_nominal(), span_axis=(0, 0, 2))
        np.testing.assert_allclose([lo + (hi - lo) * 0, hi - lo], [lo, 70.0], atol=1e-6)


class TestPlanErrors(unittest.TestCase):
    def test_heights_outside_0_100(self):
        from BladeInspect.rig.sensor import SensorModel
        for bad in ((-5.0,), (50.0, 105.0), (float("nan"),), ()):
            with self.assertRaises(InputError) as ctx:
                planning.plan_sections(demo_nominal(), np.eye(4), bad, SensorModel(),
                                       AxisLimits())
            self.assertIn("--section-heights", str(ctx.exception))
            self.assertNotIn("\n", str(ctx.exception))

    def test_plane_missing_the_cad(self):
        with self.assertRaises(InputError) as ctx:
            planning.nominal_section(demo_nominal(), (0, 0, 200.0), (0, 0, 1), 0.1)
        self.assertNotIn("\n", str(ctx.exception))

    def test_unreachable_within_soft_limits(self):
        from BladeInspect.rig.sensor import SensorModel
        from BladeInspect.rig.simulated import random_fixture_pose
        pose = random_fixture_pose(np.random.default_rng(3))
        with self.assertRaises(DeviceError) as ctx:
            planning.plan_sections(demo_nominal(), pose, (50.0,), SensorModel(),
                                   AxisLimits(z=(-40.0, 30.0)))
        self.assertIn("unreachable within soft limits", str(ctx.exception))
        self.assertNotIn("\n", str(ctx.exception))

    def test_body_clearance(self):
        spot = np.array([[0.0, 0.0, 0.0], [100.0, 0.0, 0.0]])
        # A blade point 42 mm above the first spot, 15 mm beside its beam: under the body.
        samples = np.array([[15.0, 0.0, 42.0], [100.0, 30.0, 0.0]])
        clear = planning.body_clear(samples, spot, 44.0)
        self.assertEqual(clear.tolist(), [False, True])


if __name__ == "__main__":
    unittest.main()
