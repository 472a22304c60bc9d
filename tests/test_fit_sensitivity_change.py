"""The fit-sensitivity table's change of a worst deviation is the change of its size, what the
verdict judges against +-T (docs/user-guide.md, "Fit objectives"): a section whose worst deviation
is +6 um under one objective and -6 um under another has not changed (same margin to the
band), and says that its worst point changed side; one whose worst deviation grows from 4 to
10 um has changed by 6 um and is the largest change.

The case is built here: fitting.sensitivity over two objectives whose deviations are given
point by point, the verdict's judging replaced by the largest |deviation| of each section's
points (what inspection.verdict.judge reports as its signed worst deviation), so that the
expected values are read off the constructed points."""
import dataclasses
import types
import unittest
from unittest import mock

import numpy as np

from BladeInspect.inspection import fitting
from BladeInspect.inspection import verdict as verdict_mod

SECTION = np.array([1, 1, 1, 2, 2, 2])   # each point's section
LEAST_SQUARES = np.array([0.006, -0.002, 0.001, 0.004, -0.001, 0.002])
MINIMAX = np.array([0.003, -0.006, 0.001, 0.010, -0.001, 0.002])
U = 0.002


@dataclasses.dataclass
class _Result:
    deviation: np.ndarray


def _judge(view, table, tolerance, **_):
    dev = np.asarray(view.deviation)
    sections = []
    for label in (1, 2):
        d = dev[SECTION == label]
        worst = float(d[np.argmax(np.abs(d))])
        sections.append({"label": str(label), "worst_deviation_mm": worst, "U_mm": U,
                         "verdict": "pass" if abs(worst) <= tolerance - U else "not proven"})
    return {"verdict": "pass", "sections": sections, "part": None}


class WorstDeviationChange(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        run = types.SimpleNamespace(distances=MINIMAX, max_abs_deviation=0.010, margin=None,
                                    transform=np.eye(4))
        runs = types.SimpleNamespace(runs={"least-squares": None, "minimax": run},
                                     start_deviation=LEAST_SQUARES, seconds={})
        choice = types.SimpleNamespace(decision_rule="iso14253", objective="least-squares",
                                       free=None)
        with mock.patch.object(verdict_mod, "judge", _judge):
            cls.doc = fitting.sensitivity(runs, _Result(LEAST_SQUARES), None, 0.040, choice)
        cls.rows = {r["characteristic"]: r for r in cls.doc["rows"]}

    def test_the_signed_values_are_kept(self):
        row = self.rows["section 1 worst deviation"]
        self.assertEqual(row["by_fit"]["least-squares"]["value_mm"], 0.006)
        self.assertEqual(row["by_fit"]["minimax"]["value_mm"], -0.006)

    def test_a_worst_deviation_that_changes_side_keeps_its_size(self):
        row = self.rows["section 1 worst deviation"]
        self.assertAlmostEqual(row["change_mm"], 0.0, places=12)
        self.assertTrue(row["side_changes"])

    def test_a_worst_deviation_that_grows_changes(self):
        row = self.rows["section 2 worst deviation"]
        self.assertAlmostEqual(row["change_mm"], 0.006, places=12)
        self.assertFalse(row["side_changes"])
        self.assertEqual(self.doc["largest_change"]["characteristic"],
                         "section 2 worst deviation")
        self.assertAlmostEqual(self.doc["largest_change"]["change_mm"], 0.006, places=12)
        self.assertIn("|worst deviation|", self.doc["change_rule"])

    def test_the_report_marks_the_side_change(self):
        header, rows = fitting.report_rows(self.doc)
        by_name = {r[0]: r for r in rows}
        self.assertEqual(header[-1], "Change")
        self.assertEqual(by_name["Section 1: Worst deviation"][-1], "0.0000 *")
        self.assertEqual(by_name["Section 2: Worst deviation"][-1], "0.0060")


if __name__ == "__main__":
    unittest.main()
