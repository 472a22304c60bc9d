"""Airfoil characteristics decided with their uncertainty (issue 16 item 4) and re-measured
under every fit objective (issue 16 item 2), against constructed values and known motions."""
import unittest

import numpy as np

from BladeInspect.core import transforms as tf
from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import airfoil_verdicts as verdicts
from BladeInspect.inspection import airfoil_values as values
from tests.helpers import demo_nominal
from tests.test_airfoil_pipeline import QUIET_SIGMA, Readings, _noisy, _stage


class DecisionOfOneCharacteristic(unittest.TestCase):
    def test_iso_and_simple_at_the_constructed_values(self):
        T, u = 0.010, 0.0005
        U = 2 * u
        t = stage_mod.Tolerance("max_thickness_mm", "all", -T, T)
        values = (T - 2 * U, T - U / 2, T + U / 2, T + 2 * U)
        iso = [verdicts.decision(v, u, t, "iso14253") for v in values]
        self.assertEqual([d["verdict"] for d in iso], ["pass", "not proven", "not proven",
                                                       "fail"])
        self.assertTrue(all(d["U"] == U and d["k"] == 2 and d["rule"] == "iso14253"
                            for d in iso))
        self.assertAlmostEqual(iso[0]["tur"], T / U)
        simple = [verdicts.decision(v, u, t, "simple")["verdict"] for v in values]
        self.assertEqual(simple, ["pass", "pass", "fail", "fail"])

    def test_without_a_stated_u_the_rule_used_is_named(self):
        t = stage_mod.Tolerance("chord_mm", "all", None, 0.01)
        d = verdicts.decision(0.0099, None, t, "iso14253")
        self.assertEqual((d["verdict"], d["rule"], d["U"]), ("pass", "simple", None))


class StageDecisions(unittest.TestCase):
    """The stage on the demo blade's sections (quiet noise, u by re-fits), judged by blocks
    whose limits are set from the stated U: the verdicts the ISO rule must give."""

    @classmethod
    def setUpClass(cls):
        cls.nominal = demo_nominal()
        sections = _noisy(Readings.get(cls.nominal)["sections"], QUIET_SIGMA, 3)
        cls.stage, cls.table, cls.result = _stage(cls.nominal, sections,
                                                  stage_mod.Options(draws=4))

    def _judged(self, key, upper_from_dev):
        block = dict(self.stage.blocks[0])
        dev = values.flat(block["deviation"])[key]
        u = values.flat(block["uncertainty"])[key]
        t = stage_mod.Tolerance(key, "all", None, upper_from_dev(dev, 2 * u))
        failed, unproven = verdicts.judge(block, [t], True, "iso14253")
        return block, failed, unproven

    def test_verdicts_from_the_stated_u(self):
        for key in ("max_thickness_mm", "twist_deg", "le_thickness_mm[1]"):
            block, failed, unproven = self._judged(key, lambda d, U: d + 2 * U)
            self.assertEqual(block["verdicts"][key], "pass")
            self.assertGreater(block["decisions"][key]["U"], 0)
            block, failed, unproven = self._judged(key, lambda d, U: d + U / 2)
            self.assertEqual((block["verdicts"][key], unproven, block["verdict"]),
                             ("not proven", [key], "not proven"))
            block, failed, unproven = self._judged(key, lambda d, U: d - 2 * U)
            self.assertEqual((block["verdicts"][key], failed), ("fail", [key]))

    def test_a_not_proven_characteristic_leaves_the_part_not_proven(self):
        key = "max_thickness_mm"
        dev = values.flat(self.stage.blocks[0]["deviation"])[key]
        u = values.flat(self.stage.blocks[0]["uncertainty"])[key]
        opts = stage_mod.Options(draws=4, tolerances=[
            stage_mod.Tolerance(key, "1", None, dev + u)])
        verdict = {"pass": True, "verdict": "pass", "summary": "PASS: within +-0.040 mm",
                   "decision_rule": "iso14253"}
        stage = stage_mod.attach(self.result, self.nominal, self.table, verdict, opts)
        self.assertEqual(stage.verdict["verdict"], "not proven")
        self.assertEqual(stage.verdict["not_proven"], ["section 1: %s" % key])
        self.assertFalse(verdict["pass"])
        self.assertEqual(verdict["verdict"], "not proven")
        self.assertIn("NOT PROVEN", verdict["summary"])


class FitSensitivityRows(unittest.TestCase):
    """A second 'fit' that turns the part by 0.05 deg about the span axis through section 2's
    centroid and shifts it 0.010 mm along the engine axis: its rows must read that change."""

    def test_rows_read_the_known_motion(self):
        nominal = demo_nominal()
        sections = _noisy(Readings.get(nominal)["sections"], QUIET_SIGMA, 4)
        stage, table, result = _stage(nominal, sections)
        axis = np.asarray(table.span_axis, float)
        pivot = np.asarray(stage.blocks[1]["nominal"]["centroid_mm"], float)
        angle, shift = np.radians(0.05), 0.010
        R = tf.rotation_from_vector(axis * angle)
        turn = tf.make_transform(R, pivot - R @ pivot + np.array([shift, 0.0, 0.0]))
        doc = {"objectives": ["least-squares", "turned"], "chosen": "least-squares",
               "rows": [], "cad_motion_by_fit": {"least-squares": np.eye(4).tolist(),
                                                 "turned": turn.tolist()}}
        stage_mod.add_to_sensitivity(doc, stage, result, stage_mod.Options(draws=0))
        rows = {r["characteristic"]: r for r in doc["rows"]}
        self.assertEqual(len(rows), 3 * (13 + 6 + 3 + 2))
        for label in ("1", "2", "3"):
            twist = rows["section %s twist_deg" % label]
            self.assertEqual(twist["unit"], "deg")
            sign = np.sign(np.cross(stage.sections[0].frame.e1, stage.sections[0].frame.e2)
                           @ axis)
            self.assertAlmostEqual(twist["by_fit"]["turned"]["value"]
                                   - twist["by_fit"]["least-squares"]["value"],
                                   sign * 0.05, delta=0.002)
            self.assertLess(rows["section %s max_thickness_mm" % label]["change"], 1e-4)
            self.assertLess(rows["section %s le_radius_mm" % label]["change"], 1e-3)
        # section 2 turned about its own centroid: only the shift moves it
        s2 = rows["section 2 shift_mm[0]"]
        self.assertAlmostEqual(s2["change"], shift, delta=0.0005)
        self.assertIsNone(doc["largest_change_airfoil"])     # no u stated (draws 0)
        self.assertEqual(set(doc["airfoil_verdict_by_fit"]), {"least-squares", "turned"})


class FailedDrawsAreNotScatter(unittest.TestCase):
    def test_a_failed_draw_is_left_out_and_normal_scatter_kept_whole(self):
        from BladeInspect.inspection.airfoil_uncertainty import _draws_sd
        rng = np.random.default_rng(15)
        for _ in range(20):
            draws = rng.normal(1.0, 0.003, 12)
            self.assertEqual(_draws_sd(draws), float(np.std(draws, ddof=1)))
            with_failure = np.append(draws, 14.0)   # a thickness station off the nose
            self.assertEqual(_draws_sd(with_failure), float(np.std(draws, ddof=1)))


if __name__ == "__main__":
    unittest.main()
