"""Planned points the rig cannot reach are left out of the plan with a note; they never stop
the inspection.

- NASA Rotor 67 (a blade the project did not design) clamped at a random fixture pose: with
  the default edge rule the extra points round the TE at 90 % span (where the cut leaves the
  blade through its tip face) cannot be seen within the sensor's coverage without the sensor
  meeting the blade; before, planning stopped there and `inspect` wrote nothing. The plan keeps every
  other point of the CAD's section (counted here from the section itself), says how many it
  left out, at which section and round which edge, and `inspect` runs to its result with that
  note in result.json and plan.json. With the edge rule off the same pose leaves out a
  handful of points at most (the rule's extra points are most of those left out).
- The demo blade with soft limits on Y (the rotary axis: a point's Y does not change with the
  angle, so which points lie beyond the limit is known here without the planner): a limit
  through the 90 % section leaves out exactly the points beyond it; a limit below the whole
  section leaves that section unmeasured with a note, the 50 % section unchanged.
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
from tests.helpers import ROTOR67_SECTIONS, demo_nominal, have_rotor67

HEIGHTS = (50.0, 90.0)
SEED = 2
_CACHE = {}


def rotor67():
    if "nominal" not in _CACHE:
        from BladeInspect.cad.load import load_nominal
        from BladeInspect.rig.simulated import random_fixture_pose_of
        nominal = load_nominal(ROTOR67_SECTIONS)
        axis = planning.span_axis_of(nominal)[0]
        _CACHE["nominal"] = nominal
        _CACHE["pose"] = random_fixture_pose_of(nominal, np.random.default_rng(SEED), axis)
    return _CACHE["nominal"], _CACHE["pose"]


def section_size(nominal, plan, k, sensor, radius_sigma):
    """How many points the CAD's cut at the plan's k-th plane has under the edge rule."""
    s = plan.sections[k]
    densify = None if radius_sigma is None else (float(sensor.sigma_ref), radius_sigma)
    return len(planning.nominal_section(nominal, s.plane_point, s.plane_normal, plan.spacing_mm,
                                        densify)[0])


@unittest.skipUnless(have_rotor67(), "Rotor 67 data not present")
class TestRotor67Plan(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        from BladeInspect.rig.sensor import SensorModel
        cls.nominal, cls.pose = rotor67()
        cls.sensor = SensorModel()
        cls.sigma = planning.DEFAULT_EDGE_RADIUS_SIGMA_MM
        cls.plan = planning.plan_sections(cls.nominal, cls.pose, HEIGHTS, cls.sensor,
                                          AxisLimits(), edge_radius_sigma_mm=cls.sigma)

    def test_plan_leaves_the_unreachable_te_points_out_and_says_so(self):
        info = self.plan.info["unreachable"]
        self.assertEqual([r["height_pct"] for r in info["sections"]], [90.0])
        rec = info["sections"][0]
        whole = section_size(self.nominal, self.plan, 1, self.sensor, self.sigma)
        kept = self.plan.sections[1].n_points
        self.assertGreater(rec["n_dropped"], 0)
        self.assertEqual(kept + rec["n_dropped"], whole)
        self.assertEqual(rec["n_planned"], kept)
        self.assertEqual(sum(rec["by_place"].values()), rec["n_dropped"])
        self.assertGreater(rec["by_place"]["TE"], rec["n_dropped"] // 2)
        self.assertEqual(rec["by_reason"], {"view": rec["n_dropped"]})
        # the 50 % section keeps every point of its cut
        self.assertEqual(self.plan.sections[0].n_points,
                         section_size(self.nominal, self.plan, 0, self.sensor, self.sigma))
        [line] = info["warnings"]
        self.assertIn("section at 90 %%: %d of %d points left out of the plan"
                      % (rec["n_dropped"], whole), line)
        self.assertIn("TE %d" % rec["by_place"]["TE"], line)
        self.assertNotIn("\n", line)

    def test_paths_cover_the_kept_points_once(self):
        seen = [np.zeros(s.n_points, int) for s in self.plan.sections]
        for path in self.plan.paths:
            seen[path.section][path.points] += 1
            section = self.plan.sections[path.section]
            self.assertTrue(np.all(section.angle_deg[path.points] == path.angle_deg))
        for counts in seen:
            self.assertTrue(np.all(counts == 1))
        doc = json.loads(self.plan.to_json())
        self.assertEqual(doc["info"]["unreachable"], self.plan.info["unreachable"])
        self.assertEqual(doc["n_points"], self.plan.n_points)

    def test_the_points_left_out_are_the_edge_rules(self):
        plan = planning.plan_sections(self.nominal, self.pose, HEIGHTS, self.sensor,
                                      AxisLimits(), edge_radius_sigma_mm="off")
        with_rule = self.plan.info["unreachable"]["sections"][0]["n_dropped"]
        without = sum(r["n_dropped"] for r in
                      (plan.info.get("unreachable") or {"sections": []})["sections"])
        self.assertLess(without, 0.01 * plan.n_points)
        self.assertGreater(with_rule, 10 * max(without, 1))


@unittest.skipUnless(have_rotor67(), "Rotor 67 data not present")
class TestRotor67Inspect(unittest.TestCase):
    """`inspect` with its defaults on the simulated rig: it completes and writes the note."""

    @classmethod
    def setUpClass(cls):
        from BladeInspect.inspection.closed_loop import run_inspect
        from BladeInspect.rig.simulated import SimulatedRig
        nominal, pose = rotor67()
        rig = SimulatedRig(nominal, pose, seed=SEED)
        cls.tmp = tempfile.mkdtemp(prefix="bi-unreachable-")
        cls.out = os.path.join(cls.tmp, "out")
        run_inspect(None, cls.out,
                    RunOptions.of(section_heights=HEIGHTS, seed=SEED,
                                  scan_options={"n_sections": 3}),
                    rig=rig, nominal=nominal, document=False)
        with open(os.path.join(cls.out, "result.json")) as fh:
            cls.result = json.load(fh)
        with open(os.path.join(cls.out, "plan.json")) as fh:
            cls.plan = json.load(fh)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_result_carries_the_note(self):
        info = self.plan["info"]["unreachable"]
        self.assertIn(90.0, [r["height_pct"] for r in info["sections"]])
        self.assertEqual(self.result["unreachable_points"], info)
        notes = [w for w in self.result["warnings"] if "left out of the plan" in w]
        self.assertEqual(notes, info["warnings"])
        self.assertTrue(any(w.startswith("section at 90 %: ") for w in notes))

    def test_both_sections_measured(self):
        self.assertEqual([s["height_pct"] for s in self.result["sections"]], list(HEIGHTS))
        self.assertEqual([s["n_planned"] for s in self.result["sections"]],
                         [s["n_points"] for s in self.plan["sections"]])
        self.assertTrue(os.path.exists(os.path.join(self.out, "report.html")))


class TestSoftLimits(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        from BladeInspect.rig.sensor import SensorModel
        from BladeInspect.rig.simulated import random_fixture_pose
        cls.nominal = demo_nominal()
        cls.pose = random_fixture_pose(np.random.default_rng(3))
        cls.sensor = SensorModel()
        cls.free = cls.plan(AxisLimits())

    @classmethod
    def plan(cls, limits):
        return planning.plan_sections(cls.nominal, cls.pose, HEIGHTS, cls.sensor, limits)

    def y_of(self, k):
        return self.free.sections[k].stage_xyz[:, 1]

    def test_a_limit_through_a_section_leaves_out_the_points_beyond_it(self):
        y_hi = float(np.median(self.y_of(1)))
        beyond = int(np.sum(self.y_of(1) > y_hi + 1e-9))
        plan = self.plan(AxisLimits(y=(-20.0, y_hi)))
        self.assertEqual(plan.sections[0].n_points, self.free.sections[0].n_points)
        self.assertEqual(plan.sections[1].n_points, self.free.sections[1].n_points - beyond)
        self.assertTrue(np.all(plan.sections[1].stage_xyz[:, 1] <= y_hi + 1e-9))
        [rec] = plan.info["unreachable"]["sections"]
        self.assertEqual((rec["height_pct"], rec["n_dropped"]), (90.0, beyond))
        self.assertEqual(rec["by_reason"], {"soft_limits": beyond})
        [line] = plan.info["unreachable"]["warnings"]
        self.assertIn("section at 90 %%: %d of %d points left out" % (
            beyond, self.free.sections[1].n_points), line)
        self.assertIn("soft limits", line)
        self.assertEqual(sum(len(p.points) for p in plan.paths), plan.n_points)

    def test_a_section_wholly_beyond_the_limit_is_not_measured(self):
        y_hi = 0.5 * (self.y_of(0).max() + self.y_of(1).min())
        self.assertLess(self.y_of(0).max(), y_hi)
        plan = self.plan(AxisLimits(y=(-20.0, y_hi)))
        self.assertEqual(plan.sections[0].n_points, self.free.sections[0].n_points)
        self.assertEqual(plan.sections[1].n_points, 0)
        self.assertEqual({p.section for p in plan.paths}, {0})
        [line] = plan.info["unreachable"]["warnings"]
        self.assertTrue(line.startswith("section at 90 %%: not measured, none of its %d points"
                                        % self.free.sections[1].n_points), line)

    def test_no_note_when_every_point_is_reached(self):
        self.assertNotIn("unreachable", self.free.info)


class TestSectionsJson(unittest.TestCase):
    """result.json's sections when a planned section has no rows (none of its points could be
    planned, or none was read): Table 2 then has no section of that label, and each planned
    section keeps its own figures."""

    def test_an_unmeasured_section_is_named_not_paired_with_the_next(self):
        from types import SimpleNamespace as NS
        from BladeInspect.inspection.closed_loop import _sections_json

        def planned(h, n):
            return NS(height_pct=h, n_points=n, plane_point=np.zeros(3),
                      plane_normal=np.array([0.0, 0.0, 1.0]))

        def row(label):
            return NS(source="section column", label=label, point_index=np.arange(3),
                      to_json=lambda: {"label": label})
        plan = NS(sections=[planned(10.0, 0), planned(50.0, 7), planned(90.0, 5)])
        table = NS(sections=[row("1"), row("2")])
        out = _sections_json(table, plan)
        self.assertEqual([d.get("label") for d in out], [None, "1", "2"])
        self.assertEqual([d["height_pct"] for d in out], [10.0, 50.0, 90.0])
        self.assertEqual([d["n_planned"] for d in out], [0, 7, 5])
        self.assertFalse(out[0]["measured"])
        self.assertEqual([d.get("measured", True) for d in out[1:]], [True, True])


if __name__ == "__main__":
    unittest.main()
