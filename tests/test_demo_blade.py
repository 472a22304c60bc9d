"""The demo blade: a valid outward solid whose geometry is what its parameters say.

Every expectation is computed independently of the builder: OCC's own volume, slices,
distances and inside tests on the built solid against closed-form properties of the
parameters (chord, twist law, stacking, section area)."""
import dataclasses
import math
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect.cad import demo_blade
from BladeInspect.cad.demo_blade import BladeParams, make_demo_blade, section_points
from BladeInspect.core.errors import InputError

V = FreeCAD.Vector


def shoelace(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def seam_points_at(shape, roles, z):
    """Where the edges shared by suction and pressure faces (LE and TE) cross the plane z."""
    suction = shape.Faces[roles["suction"][0]]
    pressure = shape.Faces[roles["pressure"][0]]
    shared = [e for e in suction.Edges if any(e.isSame(f) for f in pressure.Edges)]
    pts = []
    for edge in shared:
        d = np.array([[p.x, p.y, p.z] for p in edge.discretize(4000)])
        if d[0, 2] > d[-1, 2]:
            d = d[::-1]
        pts.append([np.interp(z, d[:, 2], d[:, k]) for k in range(3)])
    return np.array(pts)


class DemoBladeSolid(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.model = make_demo_blade()
        cls.shape = cls.model.shape
        cls.params = cls.model.params

    def test_valid_closed_solid_of_four_faces(self):
        self.assertEqual(self.shape.ShapeType, "Solid")
        self.assertTrue(self.shape.isValid())
        self.assertTrue(self.shape.Shells[0].isClosed())
        self.assertEqual(len(self.shape.Faces), 4)
        self.assertGreater(self.shape.Volume, 0)

    def test_size_about_70_by_50_by_20(self):
        bb = self.shape.BoundBox
        self.assertAlmostEqual(bb.ZMin, 0.0, places=9)
        self.assertAlmostEqual(bb.ZMax, self.params.span, places=9)
        self.assertTrue(45 < bb.XLength < 56, bb)
        self.assertTrue(12 < bb.YLength < 26, bb)

    def test_volume_matches_integral_of_section_areas(self):
        # Simpson's rule over areas of the closed-form profiles; the loft interpolates them,
        # so the two volumes agree to well under 1 %.
        s = np.linspace(0.0, 1.0, 41)
        areas = []
        for frac in s:
            up, lo, _ = section_points(dataclasses.replace(self.params, n_profile=801), frac)
            areas.append(shoelace(np.vstack([up, lo[::-1]])[:, :2]))
        h = self.params.span / (len(s) - 1)
        simpson = h / 3 * (areas[0] + areas[-1] + 4 * sum(areas[1:-1:2])
                           + 2 * sum(areas[2:-1:2]))
        self.assertAlmostEqual(self.shape.Volume / simpson, 1.0, delta=0.003)

    def test_normals_point_outward(self):
        for face in self.shape.Faces:
            u0, u1, v0, v1 = face.ParameterRange
            for fu, fv in ((0.3, 0.3), (0.5, 0.5), (0.7, 0.6)):
                uv = face.Surface.parameter(face.CenterOfMass) if face.Surface.__class__ \
                    is Part.Plane else (u0 + fu * (u1 - u0), v0 + fv * (v1 - v0))
                p, n = face.valueAt(*uv), face.normalAt(*uv)
                self.assertFalse(self.shape.isInside(p + n * 0.05, 1e-7, False))
                self.assertTrue(self.shape.isInside(p - n * 0.05, 1e-7, False))

    def test_defining_sections_lie_on_the_faces(self):
        # OCC distances from the closed-form profiles at the lofted heights.
        for frac in np.linspace(0.0, 1.0, self.params.n_sections)[::2]:
            up, lo, _ = section_points(self.params, frac)
            for pts in (up[::6], lo[3::6]):
                for q in pts:
                    d = self.shape.distToShape(Part.Vertex(V(*q)))[0]
                    self.assertLess(d, 1e-6)


class DemoBladeRoles(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.model = make_demo_blade()
        cls.shape, cls.roles = cls.model.shape, cls.model.roles

    def test_roles_cover_each_face_once(self):
        self.assertEqual(set(self.roles), {"suction", "pressure", "hub", "tip"})
        indices = sorted(i for v in self.roles.values() for i in v)
        self.assertEqual(indices, [0, 1, 2, 3])

    def test_hub_and_tip_are_the_planes_at_both_ends(self):
        for role, z in (("hub", 0.0), ("tip", self.model.params.span)):
            face = self.shape.Faces[self.roles[role][0]]
            self.assertIsInstance(face.Surface, Part.Plane)
            for vertex in face.Vertexes:
                self.assertAlmostEqual(vertex.Point.z, z, places=9)
            normal = face.normalAt(*face.Surface.parameter(face.CenterOfMass))
            self.assertAlmostEqual(normal.z, -1.0 if role == "hub" else 1.0, places=9)

    def curve_at(self, role, frac):
        face = self.shape.Faces[self.roles[role][0]]
        z = frac * self.model.params.span
        wires = face.slice(V(0, 0, 1), z)
        self.assertEqual(len(wires), 1)
        return np.array([[p.x, p.y] for p in wires[0].discretize(300)])

    def midpoints_inside(self, xy, frac):
        z = frac * self.model.params.span
        n = len(xy)
        inside = []
        for i, j in ((int(a * n), int(b * n)) for a, b in ((0.1, 0.5), (0.5, 0.9),
                                                               (0.6, 0.95), (0.2, 0.8))):
            m = 0.5 * (xy[i] + xy[j])
            inside.append(self.shape.isInside(V(m[0], m[1], z), 1e-7, False))
        return inside

    def test_suction_side_is_convex_and_pressure_side_is_not(self):
        # On a convex side every chord between two of its points runs through material.
        for frac in (0.05, 0.5, 0.95):
            self.assertTrue(all(self.midpoints_inside(self.curve_at("suction", frac), frac)))
        self.assertFalse(all(self.midpoints_inside(self.curve_at("pressure", 0.05), 0.05)))


class DemoBladeShape(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.model = make_demo_blade()
        cls.params = cls.model.params

    def test_chord_angle_length_and_stacking_follow_the_parameters(self):
        p = self.params
        for frac in np.linspace(0.0, 1.0, 7):
            z = frac * p.span
            a, b = seam_points_at(self.model.shape, self.model.roles, z)
            stack = np.array([p.sweep * frac ** 2, p.lean * frac ** 2])
            chord = p.chord_root + (p.chord_tip - p.chord_root) * frac
            # The leading edge is 40 % of the chord from the stacking point.
            le, te = (a, b) if abs(np.linalg.norm(a[:2] - stack) - 0.4 * chord) < \
                abs(np.linalg.norm(b[:2] - stack) - 0.4 * chord) else (b, a)
            angle = math.degrees(math.atan2(te[1] - le[1], te[0] - le[0]))
            expected = p.stagger_root_deg + p.twist_deg * frac ** p.twist_exponent
            # Between lofted sections the surface is a spline through them, not the law.
            self.assertAlmostEqual(angle, expected, delta=0.05, msg="z=%g" % z)
            self.assertAlmostEqual(np.linalg.norm(te - le), chord, delta=0.02)
            np.testing.assert_allclose(le[:2] + 0.4 * (te[:2] - le[:2]), stack, atol=0.02)

    def test_twist_is_not_linear(self):
        p = self.params
        a, b = seam_points_at(self.model.shape, self.model.roles, 0.5 * p.span)
        angle = abs(math.degrees(math.atan2(b[1] - a[1], b[0] - a[0])))
        angle = min(angle, 180 - angle)
        self.assertGreater(abs(angle - (p.stagger_root_deg + p.twist_deg / 2)), 2.0)

    def test_no_screw_symmetry_sections_change_along_the_span(self):
        # A screw motion keeps section area and perimeter; these must change hub to tip.
        areas, perimeters = [], []
        for frac in (0.02, 0.5, 0.98):
            wires = self.model.shape.slice(V(0, 0, 1), frac * self.params.span)
            self.assertEqual(len(wires), 1)
            areas.append(Part.Face(wires[0]).Area)
            perimeters.append(wires[0].Length)
        self.assertGreater(areas[0] / areas[2], 2.0)
        self.assertGreater(perimeters[0] - perimeters[2], 10.0)
        self.assertTrue(areas[0] > areas[1] > areas[2])


class DemoBladeBuild(unittest.TestCase):
    def test_deterministic_and_cached_copies(self):
        a = make_demo_blade()
        demo_blade._CACHE.clear()
        b = make_demo_blade()
        self.assertEqual(a.roles, b.roles)
        for fa, fb in zip(a.shape.Faces, b.shape.Faces):
            self.assertEqual(fa.Surface.__class__, fb.Surface.__class__)
            if isinstance(fa.Surface, Part.BSplineSurface):
                self.assertEqual(fa.Surface.getPoles(), fb.Surface.getPoles())
        self.assertEqual(a.shape.Volume, b.shape.Volume)
        # A caller moving its copy must not move the cached blade.
        b.shape.translate(V(5, 0, 0))
        self.assertAlmostEqual(make_demo_blade().shape.BoundBox.XMin, a.shape.BoundBox.XMin)

    def test_other_parameters_give_another_valid_blade(self):
        p = BladeParams(span=40, chord_root=30, chord_tip=20, twist_deg=-35, n_sections=7,
                        sweep=-2, lean=1, le_radius_root=0.4, le_radius_tip=0.06,
                        te_radius_root=0.2, te_radius_tip=0.05)
        m = make_demo_blade(p)
        self.assertTrue(m.shape.isValid())
        self.assertAlmostEqual(m.shape.BoundBox.ZLength, 40, places=9)
        self.assertLess(m.shape.Volume, make_demo_blade().shape.Volume / 3)

    def test_nonsense_parameters_raise_input_error(self):
        bad = [dict(chord_root=-50), dict(thickness_tip=0), dict(span=float("nan")),
               dict(n_sections=3), dict(camber_root=-0.1), dict(te_radius_root=5.0),
               dict(le_radius_tip=-1), dict(twist_deg=120), dict(n_sections=7.5),
               dict(sweep="3"), dict(lean=float("inf")), dict(n_profile=None)]
        for kwargs in bad:
            with self.assertRaises(InputError) as ctx:
                make_demo_blade(BladeParams(**kwargs))
            name = next(iter(kwargs))
            self.assertIn(name, str(ctx.exception))
            self.assertNotIn("\n", str(ctx.exception))
        with self.assertRaises(InputError):
            make_demo_blade({"span": 70})


if __name__ == "__main__":
    unittest.main()
