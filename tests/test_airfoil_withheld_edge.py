"""A withheld edge (the nominal's TE is a corner: core.airfoil.withhold_corner_edges makes the
measured TE radius and metal angle null, and the nominal's own radius is null too -- a
corner's radius is zero, not the circle fitted about its camber line's end) gets no edge
circle: not in the document's EdgeCircles object, not in the report's profile figure; the
rounded LE keeps its circle, of the radius the characteristics report (issue 15 item 5). A TE
radius toleranced on that section cannot be signed off unless the drawing gives its nominal.

The section is the one of tests/test_airfoil_sharp_edge.py: a double-circular-arc section
whose TE circle is replaced by the corner where its two side arcs cross, built from its
circles; its LE is an exact circle of radius ArcSection.r_le.
"""
import types
import unittest

import numpy as np

from BladeInspect.core import airfoil
from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import airfoil_verdicts as verdicts
from BladeInspect.inspection import airfoil_values as values
from BladeInspect.inspection import airfoil_measure as measure_mod
from tests.test_airfoil_sharp_edge import SIGMA, sharp_te_section

EDGE_GREEN = "#2ca02c"   # inspection.airfoil_report's colour of the edge circles


def _measured_sharp_section():
    pts, sec, corner = sharp_te_section()
    nominal = airfoil.characteristics(pts, le_upstream=(-1.0, 0.0))
    prof = airfoil.Profile(pts)
    normal = prof.outward_normal(prof.point_params)
    rng = np.random.default_rng(20261203)
    noisy = pts + rng.normal(0.0, SIGMA, len(pts))[:, None] * normal
    measured = measure_mod.measure(noisy, nominal, stage_mod.Options(draws=0), SIGMA,
                                  nominal.le_point)[0]
    return nominal, measured, sec, corner


class WithheldEdgeHasNoCircle(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal, cls.measured, cls.sec, cls.corner = _measured_sharp_section()

    def test_the_case_is_a_withheld_te(self):
        self.assertIsNone(self.measured.te_radius_mm)
        self.assertIsNotNone(self.measured.le_radius_mm)
        self.assertEqual([name for name, _ in self.measured.edge_circles()], ["LE"])
        self.assertEqual([name for name, _ in self.nominal.edge_circles()], ["LE"])
        self.assertIsNone(self.nominal.te_radius_mm)
        # the fitted circle stays on record (a scan plan spaces its points by it)
        self.assertIsNotNone(self.nominal.te_circle)

    def test_document_object_has_the_le_circle_only(self):
        import FreeCAD
        from BladeInspect.app import airfoil_objects
        from BladeInspect.cad.airfoil_sections import plane_frame
        # a plane tilted out of the CAD's axes, so that the circle's 3D placement is checked
        normal = np.array([0.1, 0.2, 1.0]) / np.linalg.norm([0.1, 0.2, 1.0])
        frame = plane_frame((5.0, -3.0, 40.0), normal)
        doc = FreeCAD.newDocument("WithheldEdge")
        try:
            obj = doc.addObject("Part::FeaturePython", "EdgeCircles_sharp")
            airfoil_objects.EdgeCircles(obj)
            airfoil_objects.EdgeCircles.store(obj.Proxy, obj, self.measured, frame)
            edges = obj.Shape.Edges
            self.assertEqual(len(edges), 1)
            circle = edges[0].Curve
            self.assertAlmostEqual(circle.Radius, self.sec.r_le, delta=0.005)
            # its centre: the LE circle's, in the plane (not near the TE corner)
            le_xyz = frame.to_3d(self.measured.le_circle.center)[0]
            self.assertLess(np.linalg.norm(np.array(circle.Center) - le_xyz), 1e-9)
            corner_xyz = frame.to_3d(self.corner)[0]
            self.assertGreater(np.linalg.norm(np.array(circle.Center) - corner_xyz), 10.0)
            self.assertAlmostEqual(obj.LeRadiusMm, self.measured.le_radius_mm, places=12)
            self.assertTrue(np.isnan(obj.TeRadiusMm))
            # the nominal's corner gets no circle either
            nom = doc.addObject("Part::FeaturePython", "EdgeCircles_nominal")
            airfoil_objects.EdgeCircles(nom)
            airfoil_objects.EdgeCircles.store(nom.Proxy, nom, self.nominal, frame)
            self.assertEqual([round(e.Curve.Radius, 9) for e in nom.Shape.Edges],
                             [round(self.nominal.le_radius_mm, 9)])
            self.assertTrue(np.isnan(nom.TeRadiusMm))
        finally:
            FreeCAD.closeDocument(doc.Name)

    def _edge_lines(self, ch):
        from BladeInspect.inspection import airfoil_report
        from BladeInspect.inspection.report_table import mpl
        plt, _, _ = mpl()
        section = types.SimpleNamespace(
            nominal=ch, points_2d=None,
            plane=types.SimpleNamespace(label="sharp", height_pct=50.0))
        fig = airfoil_report.figure_profile(section)
        try:
            ax = fig.axes[0]
            circles = []
            for line in ax.lines:
                if line.get_color() != EDGE_GREEN:
                    continue
                # the circle through the line's points (x^2 + y^2 = 2ax + 2by + c)
                xy = np.column_stack(line.get_data())
                a, b, c = np.linalg.lstsq(np.column_stack([2 * xy, np.ones(len(xy))]),
                                          (xy ** 2).sum(axis=1), rcond=None)[0]
                circles.append((np.array([a, b]), float(np.sqrt(c + a * a + b * b))))
            labels = [t.get_text() for t in ax.texts]
            return circles, labels
        finally:
            plt.close(fig)

    def test_report_figure_draws_no_circle_for_the_withheld_edge(self):
        circles, labels = self._edge_lines(self.measured)
        self.assertEqual(len(circles), 1, circles)
        centre, radius = circles[0]
        self.assertAlmostEqual(radius, self.sec.r_le, delta=0.005)
        self.assertLess(np.linalg.norm(centre - self.measured.le_circle.center), 1e-6)
        self.assertTrue(any(t.startswith("LE r =") for t in labels), labels)
        self.assertFalse(any(t.startswith("TE") for t in labels), labels)

    def test_report_figure_of_the_nominal_draws_the_le_only(self):
        circles, labels = self._edge_lines(self.nominal)
        self.assertEqual(len(circles), 1, circles)
        self.assertAlmostEqual(circles[0][1], self.sec.r_le, delta=1e-3)
        self.assertFalse(any(t.startswith("TE") for t in labels), labels)


class WithheldEdgeJudged(unittest.TestCase):
    """A drawing's TE radius tolerance on a section whose CAD TE is a corner."""

    @classmethod
    def setUpClass(cls):
        cls.nominal, cls.measured, _, _ = _measured_sharp_section()
        frame = types.SimpleNamespace(to_3d=lambda p: np.column_stack(
            [np.atleast_2d(p), np.zeros((len(np.atleast_2d(p)), 1))]))
        cls.values = (values.char_values(cls.nominal, frame),
                      values.char_values(cls.measured, frame))

    def _judge(self, drawing_nominal):
        block = {"label": "sharp", "nominal": dict(self.values[0]),
                 "measured": dict(self.values[1]), "uncertainty": None}
        row = stage_mod.Tolerance("te_radius_mm", "all", -0.01, 0.01, drawing_nominal, 2)
        failed, _ = verdicts.judge(block, [row], True, "simple")
        return block, failed

    def test_without_a_drawing_nominal_it_is_not_measured(self):
        block, failed = self._judge(None)
        self.assertEqual(block["verdicts"]["te_radius_mm"], "not measured")
        self.assertEqual(len(failed), 1)
        self.assertTrue(failed[0].startswith("te_radius_mm"))
        self.assertEqual(block["verdict"], "fail")
        # the verdict keeps its row in airfoil.csv, the nominal cell empty
        rows = [r for r in stage_mod.csv_rows([block]) if r[1] == "te_radius_mm"]
        self.assertEqual(len(rows), 1)
        self.assertIsNone(rows[0][2])
        self.assertEqual(rows[0][-1], "not measured")
        from BladeInspect.inspection import airfoil_report
        shown = [r for r in airfoil_report.characteristics_rows(block) if r[0] == "TE radius"]
        self.assertEqual(len(shown), 1, shown)
        self.assertEqual(shown[0][2], "-")
        self.assertEqual(shown[0][-1], "not measured")

    def test_with_a_drawing_nominal_the_unmeasurable_radius_fails_too(self):
        # the measured TE radius is withheld (not measurable at this sampling): not signed off
        block, failed = self._judge(0.05)
        self.assertEqual(block["verdicts"]["te_radius_mm"], "not measured")
        self.assertEqual(block["nominal"]["te_radius_mm"], 0.05)
        self.assertEqual(block["verdict"], "fail")

    def test_a_nominal_only_check_does_not_judge_it(self):
        block = {"label": "sharp", "nominal": dict(self.values[0]), "measured": None,
                 "uncertainty": None}
        row = stage_mod.Tolerance("te_radius_mm", "all", -0.01, 0.01, None, 2)
        failed, _ = verdicts.judge(block, [row], False, "simple")
        self.assertEqual(block["verdicts"]["te_radius_mm"], "not judged")
        self.assertEqual(failed, [])


if __name__ == "__main__":
    unittest.main()
