"""Never rounded to pass (issue 16 item 4): a judged value within U of its limit is "not proven"
in every file a quality engineer reads — result.json, the lot's summary.csv and the report's
text — under the default ISO 14253-1 rule, and the part's verdict is then not "pass"; the same
value under simple acceptance passes (the files follow the rule, not a fixed word).

The value is constructed: a cluster of points of one section moved along the CAD's normal to
T - U/2, U stated by the model for points without SNR and a zero pose covariance: the
systematic bias a / sqrt(3) for the sensor's accuracy a and the noise term of the largest of
the cluster's six tied readings of U(-a, a) (the order statistic's closed form, as
tests/test_fit_pipeline.py states it). The Monte Carlo that checks U itself is
bench/bench_uncertainty_mc.py."""
import csv
import dataclasses
import html
import json
import os
import shutil
import tempfile
import unittest

import numpy as np

from tests import inspection_fixtures as fx
from tests.test_fit_pipeline import T, demo_cloud
from BladeInspect.inspection.run_options import RunOptions


class NotProvenInEveryFileTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        from BladeInspect.inspection import sections
        from BladeInspect.rig.sensor import SensorModel
        cls.nominal = fx.demo_nominal()
        a = SensorModel().accuracy
        n = 6
        noise = a * np.sqrt(((n - 1.0) / (n + 1.0)) ** 2 + 4.0 * n / ((n + 1.0) ** 2 * (n + 2.0)))
        cls.U = 2.0 * np.sqrt(noise ** 2 + (a / np.sqrt(3.0)) ** 2)
        cls.value = T - cls.U / 2
        on = demo_cloud(cls.nominal, lambda p: np.zeros(len(p)))
        mid = on[np.argmin(np.abs(on[:, 2] - np.median(on[:, 2])))]
        cluster = np.argsort(np.linalg.norm(on - mid, axis=1))[:6]
        dev = np.zeros(len(on))
        dev[cluster] = cls.value
        result = fx.make_result(cls.nominal, fx.displaced(cls.nominal, on, dev))
        cls.result = dataclasses.replace(result, pose_covariance=np.zeros((6, 6)))
        axis, (lo, hi) = sections.span_axis_of(cls.nominal)
        cls.heights = [100.0 * (mid[2] - lo) / (hi - lo)]
        cls.tmp = tempfile.mkdtemp(prefix="bi-notproven-")
        cls.out = {rule: cls.write(rule) for rule in ("iso14253", "simple")}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @classmethod
    def write(cls, rule):
        """The report files of the constructed result under ``rule``, then the lot's summary
        of them (batch reuses a folder's result.json, as a resumed lot does)."""
        from BladeInspect.inspection import batch, fitting
        from BladeInspect.inspection.report import write_result_report
        lot = os.path.join(cls.tmp, rule)
        scans = os.path.join(lot, "scans")
        os.makedirs(scans)
        with open(os.path.join(scans, "blade.csv"), "w") as fh:
            fh.write("x,y,z\n")       # never read: its result.json is already there
        write_result_report(dataclasses.replace(cls.result), cls.nominal,
                            os.path.join(lot, "out", "blade"),
                            RunOptions.of(tolerance=T, section_heights=cls.heights,
                                          fit_choice=fitting.FitChoice(decision_rule=rule)))
        summary = batch.run_batch(None, scans, os.path.join(lot, "out"),
                                  RunOptions.of(tolerance=T), workers=1)
        return os.path.join(lot, "out", "blade"), summary["summary_csv"]

    def files(self, rule):
        folder, summary_csv = self.out[rule]
        with open(os.path.join(folder, "result.json")) as fh:
            doc = json.load(fh)
        with open(summary_csv, newline="") as fh:
            rows = list(csv.DictReader(fh))
        with open(os.path.join(folder, "report.html")) as fh:
            text = html.unescape(fh.read())
        return doc, rows, text

    def test_iso14253_not_proven_everywhere(self):
        doc, rows, text = self.files("iso14253")
        verdict = doc["verdict"]
        sec = verdict["sections"][0]
        self.assertAlmostEqual(sec["worst_deviation_mm"], self.value, places=6)
        self.assertAlmostEqual(sec["U_mm"], self.U, places=9)
        self.assertEqual(sec["verdict"], "not proven")
        self.assertEqual(verdict["verdict"], "not proven")
        self.assertIs(verdict["pass"], False)
        self.assertEqual(verdict["decision_rule"], "iso14253")
        self.assertEqual([r["verdict"] for r in rows], ["not proven"])
        self.assertIn("NOT PROVEN", text)
        self.assertIn(verdict["summary"], text)
        self.assertNotIn("PASS:", text)

    def test_simple_acceptance_passes_the_same_value(self):
        doc, rows, text = self.files("simple")
        self.assertEqual(doc["verdict"]["verdict"], "pass")
        self.assertIs(doc["verdict"]["pass"], True)
        self.assertEqual([r["verdict"] for r in rows], ["pass"])
        self.assertNotIn("NOT PROVEN", text)


if __name__ == "__main__":
    unittest.main()
