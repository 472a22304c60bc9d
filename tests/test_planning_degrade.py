"""What a blade or the rig cannot allow leaves points or sections out of the plan with a note;
it never stops the inspection (issue 35, item 5).

- `inspect --complete` on the demo blade with the Y soft limit (the rotary axis; a raster
  line's Y does not change with the angle) through the top of its span, or a rotary limit
  that excludes some of its angles: the raster keeps
  exactly the unrestricted raster's rows at or below the limit (counted from that raster
  alone), says how many it left out, at which angles and span heights, and the inspection
  runs to its result; a section above the limit is reported not measured, with the reason.
- A section height whose plane does not cut the blade (the demo blade's 0 % plane lies on
  its hub face's boundary): that section is not measured, with the note; the others are,
  unchanged; `inspect` runs to its result with "measured": false and the reason.
- The edge rule on a cut the airfoil kernel cannot read (a cylinder's circle): the section
  keeps the even spacing, whose count round a circle of radius r is floor(2 pi r / spacing),
  with a note saying its edges were not planned densely.
- A soft limit that leaves a section fewer points than a section needs: those are left out
  too, the section reported not measured with the count.
- The report lists the notes under "Planning notes".
"""
import json
import os
import shutil
import tempfile
import unittest

import numpy as np

from BladeInspect.inspection.run_options import RunOptions
from BladeInspect.measurement import planning
from BladeInspect.rig.base import AxisLimits
from tests.helpers import demo_nominal

SEED = 11
PITCH = 0.5
SCAN_OPTIONS = {"n_sections": 5, "point_spacing": 0.25, "probe_spacing": 1.0}


def _pose(seed):
    from BladeInspect.rig.simulated import random_fixture_pose
    return random_fixture_pose(np.random.default_rng(seed))


def _sensor():
    from BladeInspect.rig.sensor import SensorModel
    return SensorModel()


class TestCompleteRasterSoftLimits(unittest.TestCase):
    """The raster's setpoints beyond the soft limits are left out, the rest planned."""

    @classmethod
    def setUpClass(cls):
        from BladeInspect.measurement.complete import plan_complete
        cls.nominal, cls.pose = demo_nominal(), _pose(SEED + 1)
        cls.free = plan_complete(cls.nominal, cls.pose, _sensor(), AxisLimits(), pitch=PITCH)
        y = cls.free.line_y
        cls.y_hi = float(y[0] + 0.8 * (y[-1] - y[0]))
        cls.plan = plan_complete(cls.nominal, cls.pose, _sensor(),
                                 AxisLimits(y=(-20.0, cls.y_hi)), pitch=PITCH)

    def test_keeps_exactly_the_rows_within_the_limit(self):
        beyond = self.free.stage_xyz[:, 1] > self.y_hi + 1e-9
        self.assertGreater(beyond.sum(), 100)
        self.assertEqual(self.plan.n_points, int(np.count_nonzero(~beyond)))
        self.assertTrue(np.all(self.plan.stage_xyz[:, 1] <= self.y_hi + 1e-9))
        np.testing.assert_allclose(np.sort(self.plan.stage_xyz[:, 1]),
                                   np.sort(self.free.stage_xyz[~beyond, 1]), atol=1e-9)
        self.assertEqual(sum(len(p.rows) for p in self.plan.passes), self.plan.n_points)

    def test_note_names_the_count_angles_and_span(self):
        info = self.plan.info["unreachable"]
        beyond = self.free.stage_xyz[:, 1] > self.y_hi + 1e-9
        self.assertEqual(info["n_dropped"], int(beyond.sum()))
        per_angle = {a["angle_deg"]: a["n_dropped"] for a in info["angles"]}
        for a, n in per_angle.items():
            self.assertEqual(n, int(np.count_nonzero(beyond & (self.free.angle_deg == a))))
        # the limit cuts the top fifth of the raster's lines: the points left out are there
        for a in info["angles"]:
            self.assertGreater(a["span_pct"][0], 70.0)
        [line] = info["warnings"]
        self.assertIn("%d of %d raster points left out" % (info["n_dropped"],
                                                            self.free.n_points), line)
        self.assertIn("soft limit", line)
        self.assertNotIn("\n", line)

    def test_no_note_within_the_limits(self):
        self.assertNotIn("unreachable", self.free.info)

    def test_angles_beyond_the_rotary_limit_are_left_out(self):
        from BladeInspect.measurement.complete import plan_complete
        a_hi = 230.0
        beyond = self.free.angle_deg > a_hi
        self.assertTrue(beyond.any() and not beyond.all())
        plan = plan_complete(self.nominal, self.pose, _sensor(),
                             AxisLimits(a=(0.0, a_hi)), pitch=PITCH)
        self.assertEqual(plan.n_points, int(np.count_nonzero(~beyond)))
        self.assertTrue(np.all(plan.angle_deg <= a_hi))
        info = plan.info["unreachable"]
        self.assertEqual({a["angle_deg"]: a["n_dropped"] for a in info["angles"]},
                         {a: int(np.count_nonzero(self.free.angle_deg == a))
                          for a in np.unique(self.free.angle_deg[beyond])})
        self.assertIn("A=", info["warnings"][0])

    def test_nothing_within_the_limits_is_a_one_line_device_error(self):
        from BladeInspect.core.errors import DeviceError
        from BladeInspect.measurement.complete import plan_complete
        with self.assertRaises(DeviceError) as ctx:
            plan_complete(self.nominal, self.pose, _sensor(),
                          AxisLimits(y=(-20.0, float(self.free.line_y[0]) - 1.0)),
                          pitch=PITCH)
        self.assertNotIn("\n", str(ctx.exception))


class TestInspectCompleteSoftLimits(unittest.TestCase):
    """`inspect --complete` on a rig whose Y travel ends below the blade's tip."""

    HEIGHTS = (30.0, 70.0, 95.0)

    @classmethod
    def setUpClass(cls):
        from BladeInspect.inspection.closed_loop import run_inspect
        from BladeInspect.measurement.complete import plan_complete
        from BladeInspect.rig.simulated import SimulatedRig
        nominal, truth = demo_nominal(), _pose(SEED + 1)
        free = plan_complete(nominal, truth, _sensor(), AxisLimits(), pitch=PITCH)
        cls.y_hi = float(free.line_y[0] + 0.8 * (free.line_y[-1] - free.line_y[0]))
        rig = SimulatedRig(nominal, truth, seed=SEED, limits=AxisLimits(y=(-20.0, cls.y_hi)))
        cls.tmp = tempfile.mkdtemp(prefix="bi-degrade-")
        cls.out = os.path.join(cls.tmp, "out")
        run_inspect(None, cls.out,
                    RunOptions.of(complete=True, pitch=PITCH, seed=SEED,
                                  section_heights=cls.HEIGHTS, scan_options=SCAN_OPTIONS),
                    rig=rig, nominal=nominal, document=False)
        with open(os.path.join(cls.out, "result.json")) as fh:
            cls.result = json.load(fh)
        with open(os.path.join(cls.out, "plan.json")) as fh:
            cls.plan = json.load(fh)
        with open(os.path.join(cls.out, "report.html"), encoding="utf-8") as fh:
            cls.report = fh.read()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_finishes_with_the_note_naming_the_count(self):
        info = self.plan["info"]["unreachable"]
        self.assertGreater(info["n_dropped"], 0)
        self.assertEqual(self.result["unreachable_points"], info)
        [note] = [w for w in self.result["warnings"] if "raster points left out" in w]
        self.assertEqual(note, info["warnings"][0])
        self.assertIn("%d of %d raster points left out" % (
            info["n_dropped"], info["n_dropped"] + self.plan["n_points"]), note)

    def test_sections_below_the_limit_measured_the_one_above_not(self):
        by_height = {s["height_pct"]: s for s in self.result["sections"]}
        self.assertEqual(sorted(by_height), list(self.HEIGHTS))
        for h in (30.0, 70.0):
            self.assertNotEqual(by_height[h].get("measured"), False)
            self.assertGreater(by_height[h]["optical"]["n"], 0)
        top = by_height[95.0]
        self.assertIs(top["measured"], False)
        self.assertIn("section at 95 %", top["reason"])

    def test_report_lists_the_planning_notes(self):
        self.assertIn("<h2>Planning notes</h2>", self.report)
        self.assertIn("raster points left out of the plan", self.report)


class TestSectionWithoutACut(unittest.TestCase):
    """The demo blade's 0 % plane lies on the edge of its hub face and cuts nothing."""

    @classmethod
    def setUpClass(cls):
        cls.nominal, cls.pose = demo_nominal(), _pose(3)
        cls.alone = planning.plan_sections(cls.nominal, cls.pose, (50.0,), _sensor(),
                                           AxisLimits())
        cls.plan = planning.plan_sections(cls.nominal, cls.pose, (0.0, 50.0), _sensor(),
                                          AxisLimits())

    def test_the_plane_misses(self):
        from BladeInspect.core.errors import InputError
        s = self.plan.sections[0]
        with self.assertRaises(InputError):
            planning.nominal_section(self.nominal, s.plane_point, s.plane_normal, 0.1)

    def test_that_section_is_left_out_with_a_note_the_other_unchanged(self):
        self.assertEqual([s.n_points for s in self.plan.sections],
                         [0, self.alone.sections[0].n_points])
        np.testing.assert_allclose(self.plan.sections[1].target_cad,
                                   self.alone.sections[0].target_cad)
        self.assertEqual({p.section for p in self.plan.paths}, {1})
        [line] = self.plan.info["unreachable"]["warnings"]
        self.assertTrue(line.startswith("section at 0 %: not measured, the plane does not "
                                        "cut the CAD's blade"), line)
        self.assertNotIn("\n", line)

    def test_no_section_at_all_is_a_one_line_error(self):
        from BladeInspect.core.errors import InputError
        with self.assertRaises(InputError) as ctx:
            planning.plan_sections(self.nominal, self.pose, (0.0,), _sensor(), AxisLimits())
        self.assertIn("no section can be measured", str(ctx.exception))
        self.assertNotIn("\n", str(ctx.exception))


class TestInspectSectionWithoutACut(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        from BladeInspect.inspection.closed_loop import run_inspect
        from BladeInspect.rig.simulated import SimulatedRig
        nominal, truth = demo_nominal(), _pose(SEED + 2)
        rig = SimulatedRig(nominal, truth, seed=SEED)
        cls.tmp = tempfile.mkdtemp(prefix="bi-degrade-")
        cls.out = os.path.join(cls.tmp, "out")
        run_inspect(None, cls.out,
                    RunOptions.of(section_heights=(0.0, 50.0), seed=SEED,
                                  scan_options=SCAN_OPTIONS),
                    rig=rig, nominal=nominal, document=False)
        with open(os.path.join(cls.out, "result.json")) as fh:
            cls.result = json.load(fh)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_the_section_is_reported_not_measured_with_the_reason(self):
        low, mid = self.result["sections"]
        self.assertEqual((low["height_pct"], mid["height_pct"]), (0.0, 50.0))
        self.assertIs(low["measured"], False)
        self.assertTrue(low["reason"].startswith("section at 0 %: not measured, the plane "
                                                 "does not cut"), low["reason"])
        self.assertIn(low["reason"], self.result["warnings"])
        self.assertGreater(mid["optical"]["n"], 0)
        self.assertNotIn("measured", mid)


class TestEdgeRuleOnANonAirfoilCut(unittest.TestCase):
    """A cylinder's cut is a circle: the airfoil kernel finds no edges on it."""

    RADIUS = 8.0
    SPACING = 0.1

    def test_even_spacing_kept_with_a_note(self):
        import Part
        from BladeInspect.cad.nominal import nominal_from_shape
        nominal = nominal_from_shape(Part.makeCylinder(self.RADIUS, 60.0))
        plan = planning.plan_sections(nominal, _pose(3), (50.0,), _sensor(), AxisLimits(),
                                      spacing=self.SPACING,
                                      edge_radius_sigma_mm=planning.DEFAULT_EDGE_RADIUS_SIGMA_MM)
        expected = int(np.floor(2.0 * np.pi * self.RADIUS / self.SPACING))
        planned = plan.sections[0].n_points
        left_out = (plan.info.get("unreachable") or {"sections": [{"n_dropped": 0}]})
        self.assertEqual(planned + left_out["sections"][0]["n_dropped"], expected)
        rule = plan.info["edge_density"]
        self.assertEqual(rule["sections"], [[]])
        self.assertEqual(rule["sections_without_edges"], [50.0])
        [line] = rule["warnings"]
        self.assertTrue(line.startswith("section at 50 %: no extra edge points planned"), line)
        self.assertNotIn("\n", line)


class TestTooFewPointsLeft(unittest.TestCase):
    """A Y soft limit that leaves the 90 % section two points (Y, the rotary axis, does not
    change with the angle: which points lie below the limit is known without the planner)."""

    def test_the_last_points_are_left_out_and_counted(self):
        nominal, pose = demo_nominal(), _pose(3)
        free = planning.plan_sections(nominal, pose, (50.0, 90.0), _sensor(), AxisLimits())
        y = np.sort(free.sections[1].stage_xyz[:, 1])
        self.assertLess(free.sections[0].stage_xyz[:, 1].max(), y[0])
        y_hi = 0.5 * (y[1] + y[2])
        plan = planning.plan_sections(nominal, pose, (50.0, 90.0), _sensor(),
                                      AxisLimits(y=(-20.0, y_hi)))
        self.assertEqual(plan.sections[0].n_points, free.sections[0].n_points)
        self.assertEqual(plan.sections[1].n_points, 0)
        [rec] = plan.info["unreachable"]["sections"]
        self.assertEqual(rec["by_reason"], {"soft_limits": len(y) - 2, "too_few": 2})
        [line] = plan.info["unreachable"]["warnings"]
        self.assertTrue(line.startswith("section at 90 %%: not measured, none of its %d "
                                        "points" % len(y)), line)
        self.assertIn("2 were too few to measure the section", line)


if __name__ == "__main__":
    unittest.main()
