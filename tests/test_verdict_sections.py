"""One definition of an inspection's sections (issue 36, finding 2): a Registration an
inspection made is cut at its planned nominal heights from the rows measured along its
planned paths, by section analysis, airfoil analysis, Table 2 with a CMM file and the report
alike; the blind scan's rows are never a section's. Checked in FreeCADCmd against an
independent selection: the planned rows within the band of each plane, the plane's level
from OCC's bounding box of the blade along its span (Z for the demo blade)."""
import json
import os
import shutil
import tempfile
import unittest

import numpy as np

import FreeCAD

from BladeInspect.app import actions, loop, objects
from BladeInspect.core.errors import InputError
from BladeInspect.inspection.planned_sections import PlannedSections
from BladeInspect.inspection.report import write_result_report
from BladeInspect.inspection.run_options import ReportSources
from BladeInspect.inspection.simulate import simulate_measurement

HEIGHTS = (30.0, 70.0)
BAND_MM = 0.25          # inspection.sections.section_table's default band
TOLERANCE_MM = 0.05


class InspectionSections(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="bi-verdict-sections-")
        cls.doc = FreeCAD.newDocument("BladeInspectVerdictSections")
        cls.doc_name = cls.doc.Name
        cls.blade = objects.make_demo_blade(cls.doc)
        cls.doc.recompute()
        ps, _, _, _ = simulate_measurement(objects.nominal_of(cls.blade), n_points=12000,
                                           seed=3)
        measurement = objects.make_measurement(cls.doc, ps)
        cls.reg = actions.register(cls.doc.Name, measurement.Name, cls.blade.Name, 3,
                                   tolerance=TOLERANCE_MM)
        cls.n = len(cls.reg.Deviation)
        # the first third stands for the blind scan's rows
        cls.first = cls.n // 3
        loop.mark_inspection(cls.reg, HEIGHTS, cls.first, cls.tmp, tolerance=TOLERANCE_MM)
        cls.nominal = objects.nominal_of(cls.blade)
        cls.result = objects.registration_result(cls.reg, cls.nominal)

    @classmethod
    def tearDownClass(cls):
        # by name: on a CI worker the document object was once gone by now (another
        # module's clean-up in the same process), and its proxy raised
        if cls.doc_name in FreeCAD.listDocuments():
            FreeCAD.closeDocument(cls.doc_name)
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def expected_rows(self):
        """Per planned height, the planned rows within the band of its plane (independent of
        the section code: OCC's bounding box along Z, the demo blade's span)."""
        bb = self.blade.Shape.BoundBox
        z = np.asarray(self.result.points_cad)[:, 2]
        rows = np.arange(len(z))
        out = []
        for h in HEIGHTS:
            level = bb.ZMin + h / 100.0 * bb.ZLength
            out.append(set(rows[(rows >= self.first) & (np.abs(z - level) <= BAND_MM)]))
        return out

    def check_table(self, table):
        self.assertEqual([s.height_pct for s in table.sections], list(HEIGHTS))
        for sec, expected in zip(table.sections, self.expected_rows()):
            self.assertGreater(len(expected), 10)
            self.assertEqual(set(int(i) for i in sec.point_index), expected, sec.label)
            dev = np.abs(np.asarray(self.reg.Deviation)[sorted(expected)])
            self.assertAlmostEqual(sec.optical["max_abs_mm"], dev.max(), places=9)

    def test_section_analysis_takes_the_planned_sections_and_judges_them(self):
        table = actions.section_analysis(self.doc.Name, self.reg.Name)
        self.check_table(table)
        verdict = table.verdict
        self.assertEqual([s["label"] for s in verdict["sections"]],
                         [s.label for s in table.sections])
        self.assertEqual(verdict["tolerance_mm"], TOLERANCE_MM)
        for entry, expected in zip(verdict["sections"], self.expected_rows()):
            self.assertEqual(entry["n"], len(expected))
            # each judged section carries its U and TUR (T / U)
            self.assertGreater(entry["U_mm"], 0.0)
            self.assertAlmostEqual(entry["tur"], TOLERANCE_MM / entry["U_mm"], places=6)

    def test_airfoil_analysis_cuts_at_the_planned_heights(self):
        stage = actions.airfoil(self.doc.Name, self.reg.Name, draws=0)
        self.assertEqual([b["height_pct"] for b in stage.blocks], list(HEIGHTS))

    def test_report_judges_the_inspections_sections_and_tolerance(self):
        options, planned = loop.report_options(self.reg, 0.5)
        self.assertEqual(options.tolerance, TOLERANCE_MM)
        self.assertIsNone(options.airfoil)
        self.assertEqual(planned, PlannedSections(HEIGHTS, self.first))
        out = os.path.join(self.tmp, "report")
        summary = write_result_report(self.result, self.nominal, out, options,
                                      sources=ReportSources(planned=planned))
        self.check_table(summary["sections"])
        with open(os.path.join(out, "result.json")) as fh:
            written = json.load(fh)
        self.assertEqual(len(written["verdict"]["sections"]), len(HEIGHTS))
        self.assertEqual(written["tolerance_mm"], TOLERANCE_MM)

    def test_cmm_table_of_an_inspection_is_at_its_sections(self):
        nominal = self.nominal
        sec = nominal.samples.xyz[::50]
        path = os.path.join(self.tmp, "cmm.csv")
        np.savetxt(path, sec, delimiter=",", header="x,y,z", comments="")
        table, _ = loop.cmm_section_table(self.reg, path)
        self.check_table(table)

    def test_a_registration_no_inspection_made_keeps_its_own_sections(self):
        doc = FreeCAD.newDocument("BladeInspectVerdictSectionsPlain")
        try:
            blade = objects.make_demo_blade(doc)
            doc.recompute()
            ps, _, _, _ = simulate_measurement(objects.nominal_of(blade), n_points=2000,
                                               seed=4)
            reg = actions.register(doc.Name, objects.make_measurement(doc, ps).Name,
                                   blade.Name, 4)
            self.assertIsNone(loop.planned_sections(reg))
            self.assertEqual(loop.tolerance_of(reg, 0.07), 0.07)
            _, planned = loop.report_options(reg, 0.07)
            self.assertIsNone(planned)
        finally:
            FreeCAD.closeDocument(doc.Name)

    def test_planned_rows_outside_the_points_are_an_input_error(self):
        with self.assertRaises(InputError):
            PlannedSections(HEIGHTS, self.n + 5).rows(self.n)
        with self.assertRaises(InputError):
            PlannedSections(HEIGHTS, 10, self.n).rows(self.n)
        np.testing.assert_array_equal(PlannedSections(HEIGHTS, 10, 5).rows(self.n),
                                      np.arange(10, 15))


if __name__ == "__main__":
    unittest.main()
