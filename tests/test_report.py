"""The report files (HTML, PDF), the inspection document and the whole `report` run."""
import base64
import json
import logging
import os
import re
import shutil
import subprocess
import tempfile
import unittest
import warnings

import numpy as np

from BladeInspect.app.document import write_inspection_document
from BladeInspect.cad.demo_blade import BladeParams
from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import InputError
from BladeInspect.inspection import report as R
from BladeInspect.inspection import sections as S
from BladeInspect.inspection import verdict as V
from BladeInspect.inspection.run_options import RunOptions
from tests import inspection_fixtures as fx

SPAN = BladeParams().span
HEIGHTS = (10, 30, 50, 70, 90)


def pdf_pages(path):
    try:
        out = subprocess.run(["pdfinfo", path], capture_output=True, text=True, check=True)
        return int(re.search(r"^Pages:\s+(\d+)", out.stdout, re.M).group(1))
    except FileNotFoundError:
        # no poppler: count page objects in the file itself
        with open(path, "rb") as fh:
            return len(re.findall(rb"/Type\s*/Page[^s]", fh.read()))


def png_images(html_text):
    return [base64.b64decode(m) for m in
            re.findall(r'src="data:image/png;base64,([A-Za-z0-9+/=]+)"', html_text)]


class WriteReportTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = fx.demo_nominal()
        cls.tmp = tempfile.mkdtemp()
        levels = [h / 100.0 * SPAN + dz for h in HEIGHTS for dz in (-0.2, 0.0, 0.2)]
        on_surface, which = fx.profile_points(cls.nominal, levels, n_profile=90)
        rng = np.random.default_rng(4)
        known = rng.normal(0.0, 0.015, len(on_surface))
        pts = fx.displaced(cls.nominal, on_surface, known)
        cls.result = fx.make_result(cls.nominal, pts)
        cmm_surface, cmm_which = fx.profile_points(cls.nominal, [h / 100.0 * SPAN for h in HEIGHTS],
                                                   n_profile=30)
        cls.cmm_path = os.path.join(cls.tmp, "cmm.csv")
        with open(cls.cmm_path, "w") as fh:
            fh.write("x,y,z\n")
            for p in fx.displaced(cls.nominal, cmm_surface,
                                  rng.normal(0.0, 0.02, len(cmm_surface))):
                fh.write("%.6f,%.6f,%.6f\n" % tuple(p))
        cls.table = S.section_table(cls.result, cls.nominal, cmm=cls.cmm_path)
        cls.verdict = V.judge(cls.result, cls.table, tolerance=0.04)
        cls.out = os.path.join(cls.tmp, "report")
        # matplotlib warns through the warnings module and through its loggers: catch both
        logged = []
        handler = logging.Handler(logging.WARNING)
        handler.emit = lambda record: logged.append(record.getMessage())
        logging.getLogger("matplotlib").addHandler(handler)
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                cls.files = R.write_report(cls.out, cls.result, cls.nominal, cls.table,
                                           cls.verdict, 0.04)
        finally:
            logging.getLogger("matplotlib").removeHandler(handler)
        cls.warnings = ["%s: %s" % (w.category.__name__, w.message) for w in caught] + logged
        with open(os.path.join(cls.out, "report.html"), encoding="utf-8") as fh:
            cls.html = fh.read()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_figures_raise_no_warnings(self):
        # matplotlib 3.10 warned five times a report about the section figures' fixed limits
        self.assertEqual(self.warnings, [])

    def test_files_and_pdf_pages(self):
        self.assertEqual(sorted(os.listdir(self.out)), ["report.html", "report.pdf"])
        expected = len(R.PAGE_TITLES) + len(HEIGHTS)
        self.assertEqual(self.files["pdf_pages"], expected)
        self.assertEqual(pdf_pages(os.path.join(self.out, "report.pdf")), expected)
        # nothing else left beside it (the private write folder is gone)
        self.assertEqual([n for n in os.listdir(self.tmp) if n.startswith(".bladeinspect")], [])

    def test_html_self_contained_with_every_figure(self):
        images = png_images(self.html)
        self.assertEqual(len(images), 2 + len(HEIGHTS))     # views, histogram, sections
        for png in images:
            self.assertTrue(png.startswith(b"\x89PNG"))
            self.assertGreater(len(png), 5000)
        self.assertNotRegex(self.html, r'src="(?!data:)')     # no external files
        for sec in self.table.sections:
            self.assertIn("<h3>Section %s</h3>" % sec.label, self.html)

    def test_tables_carry_the_figures(self):
        for band in self.result.deviation_stats["histogram"]:
            self.assertIn("<td>%d</td><td>%.3f</td>" % (band["count"], band["pct"]), self.html)
        for sec in self.table.sections:
            o, c = sec.optical, sec.cmm
            self.assertIn("<td>%.4f</td>" % o["max_abs_mm"], self.html)
            self.assertIn("<td>%.4f</td>" % c["rms_mm"], self.html)
        for head in ("CMM points", "CMM max", "CMM RMS", "LE max |dev|", "TE max |dev|"):
            self.assertIn(head, self.html)
        self.assertIn("probe radius", self.html)
        self.assertIn("PASS" if self.verdict["pass"] else "FAIL", self.html)
        self.assertIn("%.2f um" % (1000 * self.result.pose_uncertainty_mm), self.html)
        self.assertIn("within +-3 sigma: %.3f %%"
                      % self.result.deviation_stats["pct_within_3sigma"], self.html)

    def test_histogram_bands_follow_the_tolerance(self):
        # +-T, +-1.5T, +-2T for the run's T; the counts straight from the deviations
        tolerance = 0.02
        out = os.path.join(self.tmp, "report-tolerance")
        verdict = V.judge(self.result, self.table, tolerance=tolerance)
        R.write_report(out, self.result, self.nominal, self.table, verdict, tolerance)
        with open(os.path.join(out, "report.html"), encoding="utf-8") as fh:
            text = fh.read()
        dev = self.result.deviation
        edges = (-0.04, -0.03, -0.02, 0.02, 0.03, 0.04)
        self.assertIn("<td>&lt; -0.040</td><td>%d</td>" % np.count_nonzero(dev < -0.04), text)
        for lo, hi in zip(edges[:-1], edges[1:]):
            count = np.count_nonzero((dev >= lo) & (dev < hi))
            self.assertIn("<td>%.3f to %.3f</td><td>%d</td>" % (lo, hi, count), text)
        self.assertIn("<td>&gt; 0.040</td><td>%d</td>" % np.count_nonzero(dev >= 0.04), text)
        self.assertNotIn("0.060 to 0.080", text)

    def test_without_cmm_no_cmm_columns(self):
        header, rows = R.section_rows(S.section_table(self.result, self.nominal))
        self.assertNotIn("CMM max", header)
        self.assertEqual(len(rows), len(HEIGHTS))
        self.assertTrue(all(len(r) == len(header) for r in rows))


class RunReportTest(unittest.TestCase):
    """The `report` command end to end on a cloud in an unknown pose."""

    @classmethod
    def setUpClass(cls):
        cls.nominal = fx.demo_nominal()
        cls.tmp = tempfile.mkdtemp()
        levels = np.linspace(3.0, 67.0, 33)
        on_surface, _ = fx.profile_points(cls.nominal, levels, n_profile=70)
        rng = np.random.default_rng(9)
        cls.known = rng.uniform(-0.006, 0.006, len(on_surface))
        pts_cad = fx.displaced(cls.nominal, on_surface, cls.known)
        cls.truth = tf.random_transform(rng, 50.0)        # CAD -> measured
        measured = tf.apply_transform(cls.truth, pts_cad)
        cls.points_path = os.path.join(cls.tmp, "blade 1.csv")
        np.savetxt(cls.points_path, measured, delimiter=",", header="x,y,z", comments="",
                   fmt="%.9f")
        cls.out = os.path.join(cls.tmp, "out")
        cls.summary = R.run_report(None, cls.points_path, cls.out, nominal=cls.nominal,
                                   document=write_inspection_document)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_outputs(self):
        self.assertEqual(sorted(os.listdir(self.out)),
                         ["deviations.csv", "inspection.FCStd", "report.html", "report.pdf",
                          "result.json"])
        with open(os.path.join(self.out, "result.json")) as fh:
            doc = json.load(fh)
        T = np.array(doc["measured_to_cad"])
        corners = self.nominal.bbox_corners
        self.assertLess(tf.corner_displacement(T, tf.invert_transform(self.truth), corners),
                        0.002)
        self.assertEqual(len(doc["sections"]["sections"]), 5)
        self.assertIn("pass", doc["verdict"])
        self.assertTrue(doc["verdict"]["pass"], doc["verdict"]["summary"])
        self.assertEqual(doc["tolerance_mm"], 0.04)
        rows = np.loadtxt(os.path.join(self.out, "deviations.csv"), delimiter=",", skiprows=1,
                          usecols=3)
        np.testing.assert_allclose(rows, self.known, atol=0.002)
        self.assertEqual(self.summary["verdict"], doc["verdict"])

    def test_document_reopens_with_colours(self):
        """The workbench's own objects, reopened from the file: one colour per point, the
        colours those of the deviations, the pose, the section profiles and the verdict."""
        import FreeCAD
        from BladeInspect.app import objects
        from BladeInspect.core import colourmap
        doc = FreeCAD.openDocument(os.path.join(self.out, "inspection.FCStd"))
        try:
            maps = objects.find_objects(doc, "BladeInspect::DeviationMap")
            self.assertEqual(len(maps), 1)
            cloud = maps[0]
            self.assertEqual(len(cloud.Color), len(self.known))
            self.assertEqual(cloud.Points.CountPoints, len(self.known))
            expected = colourmap.deviation_colours(np.asarray(cloud.Deviation), 0.04)
            # the file stores colours as 8-bit RGBA
            np.testing.assert_allclose(np.asarray(cloud.Color)[:, :3], expected,
                                       atol=0.5 / 255 + 1e-6)
            reg = objects.find_objects(doc, "BladeInspect::Registration")[0]
            with open(os.path.join(self.out, "result.json")) as fh:
                T = np.array(json.load(fh)["measured_to_cad"])
            np.testing.assert_allclose(objects.matrix_array(reg.MeasuredToCad), T, atol=1e-9)
            nominal = objects.find_objects(doc, "BladeInspect::DemoBlade")[0]
            self.assertAlmostEqual(nominal.Shape.Volume, self.nominal.shape.Volume, places=6)
            profiles = doc.getObject("SectionProfiles")
            self.assertEqual(list(profiles.Sections), ["1", "2", "3", "4", "5"])
            self.assertIn("PASS", profiles.Verdict)
            self.assertFalse([o.Name for o in doc.Objects if "Touched" in o.State])
        finally:
            FreeCAD.closeDocument(doc.Name)

    def test_bad_input_leaves_nothing(self):
        bad = os.path.join(self.tmp, "bad.csv")
        with open(bad, "w") as fh:
            fh.write("x,y,z\n1,2,3\n")
        out = os.path.join(self.tmp, "bad_out")
        with self.assertRaises(InputError):
            R.run_report(None, bad, out, nominal=self.nominal)
        self.assertFalse(os.path.exists(os.path.join(out, "result.json")))
        self.assertEqual([n for n in os.listdir(self.tmp) if n.startswith(".bladeinspect")], [])
        with self.assertRaises(InputError):
            R.run_report(None, self.points_path, out, RunOptions.of(tolerance=0),
                         nominal=self.nominal)
        with self.assertRaises(InputError):
            R.run_report(None, self.points_path, out,
                         RunOptions.of(cmm=os.path.join(self.tmp, "missing_cmm.csv")),
                         nominal=self.nominal)
        self.assertFalse(os.path.exists(os.path.join(out, "result.json")))


if __name__ == "__main__":
    unittest.main()
