"""A withheld edge (core.airfoil.withhold_corner_edges: the nominal's TE is a corner, the
measured TE radius and metal angle null) gets no edge circle: not in the document's
EdgeCircles object, not in the report's profile figure; the rounded LE keeps its circle, of the
radius the characteristics report (issue 15 item 5).

The section is the one of tests/test_airfoil_sharp_edge.py: a double-circular-arc section
whose TE circle is replaced by the corner where its two side arcs cross, built from its
circles; its LE is an exact circle of radius ArcSection.r_le.
"""
import types
import unittest

import numpy as np

from BladeInspect.core import airfoil
from BladeInspect.inspection import airfoil as stage_mod
from tests.test_airfoil_sharp_edge import SIGMA, sharp_te_section

EDGE_GREEN = "#2ca02c"   # inspection.airfoil_report's colour of the edge circles


def _measured_sharp_section():
    pts, sec, corner = sharp_te_section()
    nominal = airfoil.characteristics(pts, le_upstream=(-1.0, 0.0))
    prof = airfoil.Profile(pts)
    normal = prof.outward_normal(prof.point_params)
    rng = np.random.default_rng(20261203)
    noisy = pts + rng.normal(0.0, SIGMA, len(pts))[:, None] * normal
    measured = stage_mod._measure(noisy, nominal, stage_mod.Options(draws=0), SIGMA,
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
        self.assertEqual([name for name, _ in self.nominal.edge_circles()], ["LE", "TE"])

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
            # the nominal's TE (its radius reported) keeps both circles
            nom = doc.addObject("Part::FeaturePython", "EdgeCircles_nominal")
            airfoil_objects.EdgeCircles(nom)
            airfoil_objects.EdgeCircles.store(nom.Proxy, nom, self.nominal, frame)
            self.assertEqual(sorted(round(e.Curve.Radius, 9) for e in nom.Shape.Edges),
                             sorted(round(r, 9) for r in (self.nominal.le_radius_mm,
                                                          self.nominal.te_radius_mm)))
        finally:
            FreeCAD.closeDocument(doc.Name)

    def _edge_lines(self, ch):
        from BladeInspect.inspection import airfoil_report
        from BladeInspect.inspection.report import _mpl
        plt, _, _ = _mpl()
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

    def test_report_figure_of_the_nominal_draws_both(self):
        circles, labels = self._edge_lines(self.nominal)
        self.assertEqual(sorted(round(r, 6) for _, r in circles),
                         sorted(round(r, 6) for r in (self.nominal.le_radius_mm,
                                                      self.nominal.te_radius_mm)))


if __name__ == "__main__":
    unittest.main()
