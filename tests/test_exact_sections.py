"""The nominal cut is the exact intersection of the CAD's faces and the plane
(cad.sections.exact_cut), checked against independent truths: an elliptic blade, extruded and
turned to an arbitrary pose and given as rational B-spline faces, whose cut by any plane has
closed-form points; and OCC's own exact point-to-face distance on the demo blade. A section
whose cut is not the airfoil's (it runs over a root block's faces) or whose measured points
cover only part of the profile is refused with its reason, and the others are measured."""
import dataclasses
import unittest

import numpy as np

import FreeCAD
import Part
from FreeCAD import Vector

from BladeInspect.cad import sections as cad_sections
from BladeInspect.cad.demo_blade import make_demo_blade

# The exact cut's promise: every point within 0.2 um of the exact profile.
EXACT_MM = 2e-4


def ellipse_distance(xy, a, b):
    """Distance of 2D points near it to the ellipse x^2/a^2 + y^2/b^2 = 1: the foot's angle t
    by Newton on (p - E(t)) . E'(t) = 0, from the point's own eccentric angle."""
    t = np.arctan2(xy[:, 1] / b, xy[:, 0] / a)
    for _ in range(60):
        c, s = np.cos(t), np.sin(t)
        dx, dy = a * c - xy[:, 0], b * s - xy[:, 1]
        f = -dx * a * s + dy * b * c
        fp = (a * s) ** 2 + (b * c) ** 2 - dx * a * c - dy * b * s
        t = t - f / fp
    return np.hypot(a * np.cos(t) - xy[:, 0], b * np.sin(t) - xy[:, 1])


def rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def elliptic_blade(a, b, height, rot, shift):
    """A prism of elliptic section (semi-axes a along x, b along y, extruded ``height`` along
    z), moved by x -> rot x + shift, as a solid of rational B-spline faces."""
    face = Part.Face(Part.Wire(Part.Ellipse(Vector(0, 0, 0), a, b).toShape()))
    solid = face.extrude(Vector(0, 0, height))
    m = FreeCAD.Matrix()
    m.A11, m.A12, m.A13, m.A14 = rot[0, 0], rot[0, 1], rot[0, 2], shift[0]
    m.A21, m.A22, m.A23, m.A24 = rot[1, 0], rot[1, 1], rot[1, 2], shift[1]
    m.A31, m.A32, m.A33, m.A34 = rot[2, 0], rot[2, 1], rot[2, 2], shift[2]
    moved = solid.transformGeometry(m)
    return moved.toNurbs()


def error_mm(polylines, a, b, rot, shift, point, normal):
    """Largest distance of the cut's points to the exact cut: off the plane, or (in the
    blade's own frame) off the ellipse."""
    pts = np.vstack(polylines)
    local = (pts - shift) @ rot
    return max(float(np.max(np.abs((pts - point) @ normal))),
               float(np.max(ellipse_distance(local[:, :2], a, b))))


class ExactCutOnClosedForms(unittest.TestCase):
    def test_an_elliptic_prism_in_any_pose_cut_by_tilted_planes(self):
        rng = np.random.default_rng(35)
        worst_old = 0.0
        for a, b, height in ((50.0, 8.0, 50.0), (40.0, 12.0, 90.0), (94.0, 14.0, 100.0)):
            rot, shift = rotation(rng), rng.normal(scale=20.0, size=3)
            shape = elliptic_blade(a, b, height, rot, shift)
            for frac, tilt, turn in ((0.5, 0.0, 0.0), (0.3, 0.3, 0.7), (0.7, -0.2, 2.1)):
                local_n = np.array([np.sin(tilt) * np.cos(turn), np.sin(tilt) * np.sin(turn),
                                    np.cos(tilt)])
                normal = rot @ local_n
                point = rot @ np.array([0.3, -0.2, frac * height]) + shift
                exact, faces = cad_sections.exact_cut(shape, point, normal)
                self.assertEqual(len(exact), 1)
                self.assertTrue(np.allclose(exact[0][0], exact[0][-1]))
                err = error_mm(exact, a, b, rot, shift, point, normal)
                old = error_mm(cad_sections.cut(shape, point, normal), a, b, rot, shift,
                               point, normal)
                worst_old = max(worst_old, old)
                self.assertLess(err, EXACT_MM, (a, b, frac, tilt))
                self.assertEqual(len(faces[0]), len(exact[0]))
        print("\nOCC slice's worst error on the elliptic prisms: %.2g mm" % worst_old)


class ExactCutByOcc(unittest.TestCase):
    def test_the_demo_blades_cut_lies_on_the_faces_it_names(self):
        shape = make_demo_blade().shape
        for z, tilt in ((10.0, 0.0), (35.0, 0.25), (62.0, -0.3)):
            normal = np.array([0.0, np.sin(tilt), np.cos(tilt)])
            point = np.array([0.0, 0.0, z])
            polylines, faces = cad_sections.exact_cut(shape, point, normal)
            pts, which = np.vstack(polylines), np.concatenate(faces)
            self.assertLess(np.max(np.abs((pts - point) @ normal)), 1e-9)
            for k in np.linspace(0, len(pts) - 1, 150).astype(int):
                face = shape.Faces[which[k]]
                d = face.distToShape(Part.Vertex(Vector(*pts[k])))[0]
                self.assertLess(d, EXACT_MM, (z, tilt, k))



def _measured_stage(nominal, planes, keep=None):
    """The airfoil stage on readings exactly on each plane's CAD cut (0.05 mm apart, identity
    pose); ``keep(label, xyz)``: a mask of a plane's readings to keep."""
    from BladeInspect.inspection import airfoil_stage as stage_mod
    from BladeInspect.measurement.planning import nominal_section
    from tests.test_airfoil_pipeline import _result
    rows, start, with_points = [], 0, []
    for plane in planes:
        xyz = nominal_section(nominal, plane.origin, plane.normal, 0.05)[0]
        if keep is not None:
            xyz = xyz[keep(plane.label, xyz)]
        rows.append(xyz)
        with_points.append(dataclasses.replace(
            plane, point_index=np.arange(start, start + len(xyz))))
        start += len(xyz)
    result = _result(nominal, np.vstack(rows))
    return stage_mod.run_stage(nominal, with_points, stage_mod.Options(draws=0), result)


class RefusedSections(unittest.TestCase):
    def test_planes_through_the_root_block_are_refused_the_others_measured(self):
        from BladeInspect.cad.nominal import nominal_from_shape
        from BladeInspect.inspection import airfoil_stage as stage_mod
        model = make_demo_blade(root_block=True)    # the block spans z -25 .. -5
        nominal = nominal_from_shape(model.shape, roles=model.roles)
        planes = stage_mod.nominal_planes(nominal, (30.0, 70.0))
        planes += [stage_mod.Plane("in block", np.array([0.0, 0.0, -7.0]),
                                   np.array([0.0, 0.0, 1.0]), -10.0),
                   stage_mod.Plane("through hub", np.array([0.0, 0.0, 2.0]),
                                   np.array([0.0, -0.5, np.sqrt(0.75)]), 3.0)]
        stage = _measured_stage(nominal, planes)
        blocks = {b["label"]: b for b in stage.blocks}
        for label in ("1", "2"):
            self.assertIsNotNone(blocks[label]["measured"], label)
            self.assertNotIn("refused", blocks[label])
        for label in ("in block", "through hub"):
            self.assertIsNone(blocks[label]["measured"])
            self.assertIn("root_block", blocks[label]["refused"])
            notes = [n for r in stage.sections if r.plane.label == label for n in r.notes]
            self.assertTrue(any(n.startswith("section refused:") for n in notes), notes)

    def test_points_on_part_of_the_profile_are_refused(self):
        from BladeInspect.inspection import airfoil_stage as stage_mod
        from tests.helpers import demo_nominal
        nominal = demo_nominal()
        planes = stage_mod.nominal_planes(nominal, (30.0, 50.0, 70.0))

        def keep(label, xyz):      # the 50 % section's scan misses the profile's x > 5 mm
            return xyz[:, 0] < 5.0 if label == "2" else np.ones(len(xyz), bool)
        stage = _measured_stage(nominal, planes, keep)
        refused = [b for b in stage.blocks if "refused" in b]
        self.assertEqual([b["label"] for b in refused], ["2"])
        self.assertIn("cover only part of the profile", refused[0]["refused"])
        self.assertIsNotNone(refused[0]["nominal"])
        self.assertTrue(all(b["measured"] is not None for b in stage.blocks if b not in refused))


if __name__ == "__main__":
    unittest.main()
