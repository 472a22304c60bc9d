"""cad.nominal's exact signed distance and ray cast against OpenCASCADE's own answers, point by
point: Shape.distToShape for the distance and closest point, Solid.isInside / Face.normalAt for
the sign, closed forms where they exist (sphere, box). Shapes cover every kind of face: planar
trimmed faces and a cylinder (box with a hole), a surface of revolution, a sphere, open B-spline
faces, a small interpolated twisted blade, and the demo / Rotor 67 blades when present."""
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect.cad.nominal import nominal_from_shape
from BladeInspect.core.errors import InputError
from tests import helpers

V = FreeCAD.Vector
TOL = 1e-6


def occ_reference(shape, points):
    """Distance, closest point and sign straight from OCC (independent of cad.nominal)."""
    solids = shape.Solids
    faces = Part.makeCompound(shape.Faces)     # a solid is at distance 0 from points inside
    dist, closest, sign = [], [], []
    for p in points:
        d, pairs, info = faces.distToShape(Part.Vertex(V(*p)))
        c = np.array(pairs[0][0])
        if solids:
            s = -1.0 if any(so.isInside(V(*p), 1e-9, True) for so in solids) else 1.0
        else:
            kind, idx, uv = info[0][0], info[0][1], info[0][2]
            if kind != "Face":
                s = np.nan          # an open edge: sign is the library's convention, not OCC's
            else:
                n = np.array(shape.Faces[idx].normalAt(*uv))
                s = 1.0 if np.dot(p - c, n) >= 0 else -1.0
        dist.append(d)
        closest.append(c)
        sign.append(s)
    return np.array(dist), np.array(closest), np.array(sign)


def points_near(nominal, rng, n, lo=0.01, hi=5.0, tangential=0.0):
    """n points at 0.01-5 mm (log-uniform) on both sides of random samples, optionally moved
    sideways too (so some fall beyond edges and corners)."""
    s = nominal.samples
    i = rng.integers(0, len(s.xyz), n)
    off = rng.choice([-1.0, 1.0], n) * 10 ** rng.uniform(np.log10(lo), np.log10(hi), n)
    return s.xyz[i] + off[:, None] * s.normal[i] + rng.normal(0, tangential, (n, 3))


def corner_points(shape, rng, n_each=6, radius=1.0):
    """Points around every vertex and along every edge of the shape: the hard cases."""
    pts = []
    for v in shape.Vertexes:
        pts.append(np.array([v.X, v.Y, v.Z]) + rng.normal(0, radius, (n_each, 3)))
    for e in shape.Edges:
        a, b = e.ParameterRange
        for t in rng.uniform(a, b, n_each):
            p = e.valueAt(t)
            pts.append(np.array([[p.x, p.y, p.z]]) + rng.normal(0, radius, (1, 3)))
    return np.concatenate(pts)


def airfoil_grid(n_sections=6, n_points=25, span=30.0, chord=20.0, twist_deg=20.0, side=+1):
    """A thin cambered airfoil side (side=+1 suction, -1 pressure) stacked and twisted."""
    grid = []
    for k in range(n_sections):
        s = k / (n_sections - 1)
        c = chord * (1 - 0.2 * s)
        ang = np.radians(twist_deg * s)
        row = []
        x = 0.5 * (1 - np.cos(np.linspace(0, np.pi, n_points)))
        camber = 0.06 * c * 4 * x * (1 - x)
        thick = 0.12 * c * (1.0 - 0.5 * s) * np.sqrt(x) * (1 - x) * 1.3
        y = camber + side * thick
        for xi, yi in zip(x * c, y):
            row.append(V(xi * np.cos(ang) - yi * np.sin(ang), xi * np.sin(ang) + yi * np.cos(ang),
                         s * span))
        grid.append(row)
    return grid


def twisted_blade():
    """A small lofted solid: suction and pressure B-spline faces through interpolated grids
    (meeting along sharp leading and trailing edges) closed by planar hub and tip caps."""
    sides = []
    for side in (+1, -1):
        bs = Part.BSplineSurface()
        bs.interpolate(airfoil_grid(side=side))
        sides.append(bs.toShape())
    caps = []
    for z in (0.0, 30.0):
        edges = [e for f in sides for e in f.Edges
                 if abs(e.valueAt(0.5 * sum(e.ParameterRange)).z - z) < 1e-6]
        caps.append(Part.Face(Part.Wire(Part.__sortEdges__(edges))))
    shell = Part.Shell(sides + caps)
    shell.sewShape()
    solid = Part.Solid(Part.Shell(shell.Faces))
    if solid.Volume < 0:
        solid.reverse()
    return solid


class DistanceCase:
    """Mixin: exact agreement with OCC on points near a shape and around its edges/corners."""
    max_fallback = 0.5

    def check(self, nominal, points, min_fast_points=20, max_fallback=None):
        res = nominal.signed_distance(points)
        d, c, sign = occ_reference(nominal.shape, points)
        err_d = np.abs(np.abs(res.distance) - d)
        err_c = np.linalg.norm(res.closest - c, axis=1)
        worst = int(np.argmax(err_d))
        self.assertLess(err_d.max(), TOL, "distance off by %.3g at %s (fallback %s)"
                        % (err_d.max(), points[worst], res.fallback[worst]))
        # A closest point is unique except where two are equally far (then distances agree).
        unique = err_c > TOL
        self.assertLess(np.count_nonzero(unique), max(1, 0.01 * len(points)),
                        "closest points differ by up to %.3g" % err_c.max())
        known = ~np.isnan(sign) & (d > 1e-7)
        wrong = known & (np.sign(res.distance) != sign)
        self.assertFalse(wrong.any(), "wrong sign at %s" % points[wrong][:3])
        # the answer is consistent: the distance is along the returned normal at face points
        fast = ~res.fallback
        self.assertGreaterEqual(np.count_nonzero(fast), min(min_fast_points, len(points)))
        self.assertLessEqual(res.fallback_fraction,
                             self.max_fallback if max_fallback is None else max_fallback)
        return res


class BoxWithHole(DistanceCase, unittest.TestCase):
    max_fallback = 0.6

    @classmethod
    def setUpClass(cls):
        box = Part.makeBox(10, 10, 10).cut(Part.makeCylinder(2, 10, V(5, 5, 0)))
        # a non-trivial placement: faces' surfaces must carry it
        box.Placement = FreeCAD.Placement(V(3, -2, 1), FreeCAD.Rotation(V(1, 2, 3), 27))
        cls.nominal = nominal_from_shape(box)

    def test_points_near_faces(self):
        rng = np.random.default_rng(11)
        res = self.check(self.nominal, points_near(self.nominal, rng, 300, hi=1.9), 150)
        self.assertLess(res.fallback_fraction, 0.3)

    def test_points_around_edges_and_corners(self):
        rng = np.random.default_rng(12)
        self.check(self.nominal, corner_points(self.nominal.shape, rng, 4, 1.0), 0, 1.0)

    def test_fallback_signs_without_the_inside_test(self):
        """The fallback signs a point from its foot point's normal or an edge's pseudo-normal
        instead of the solid's inside test: the same signs, around convex and concave edges
        (the hole's), where the inside test of this simple solid is reliable."""
        from BladeInspect.cad.nominal import DistanceResult
        rng = np.random.default_rng(31)
        points = corner_points(self.nominal.shape, rng, 3, 0.5)
        n = len(points)
        out = DistanceResult(np.empty((n, 3)), np.empty(n, int), np.empty((n, 2)),
                             np.empty((n, 3)), np.empty(n), np.zeros(n, bool))
        self.nominal._occ_into(points, out, np.arange(n), solid_test=False)
        d, c, sign = occ_reference(self.nominal.shape, points)
        np.testing.assert_allclose(np.abs(out.distance), d, atol=TOL)
        known = d > 1e-7
        np.testing.assert_array_equal(np.sign(out.distance[known]), sign[known])
        # Most of these points' foot points are on an edge: the pseudo-normal decided them.
        on_edge = [self.nominal._face_compound.distToShape(Part.Vertex(V(*p)))[2][0][0] == "Edge"
                   for p in points]
        self.assertGreater(np.mean(on_edge), 0.2)

    def test_face_types_and_trimming(self):
        kinds = sorted({type(f.Surface).__name__ for f in self.nominal.faces})
        self.assertEqual(kinds, ["Cylinder", "Plane"])
        # no sample inside the hole of the two trimmed planar faces
        s = self.nominal.samples
        local = np.array([list(self.nominal.shape.Placement.inverse().multVec(V(*p)))
                          for p in s.xyz[::7]])
        r = np.hypot(local[:, 0] - 5, local[:, 1] - 5)
        self.assertTrue(np.all(r > 2 - 1e-9))
        self.assertAlmostEqual(s.weight.sum(), self.nominal.shape.Area, delta=0.01 * self.nominal.shape.Area)


class Sphere(DistanceCase, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = nominal_from_shape(Part.makeSphere(5, V(1, 2, 3)))

    def test_closed_form(self):
        rng = np.random.default_rng(13)
        p = points_near(self.nominal, rng, 400)
        res = self.nominal.signed_distance(p)
        r = np.linalg.norm(p - [1, 2, 3], axis=1)
        np.testing.assert_allclose(res.distance, r - 5, atol=TOL)
        np.testing.assert_allclose(res.closest, [1, 2, 3] + 5 * (p - [1, 2, 3]) / r[:, None], atol=TOL)
        np.testing.assert_allclose(res.normal, (p - [1, 2, 3]) / r[:, None], atol=1e-6)
        self.assertLess(res.fallback_fraction, 0.05)

    def test_against_occ(self):
        rng = np.random.default_rng(14)
        self.check(self.nominal, points_near(self.nominal, rng, 150))


class Revolved(DistanceCase, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        profile = Part.BSplineCurve()
        profile.interpolate([V(0, 0, 0), V(4, 0, 0.5), V(5, 0, 3), V(3.5, 0, 6), V(0, 0, 7)])
        solid = Part.Solid(Part.Shell([profile.toShape().revolve(V(0, 0, 0), V(0, 0, 1), 360)]))
        if solid.Volume < 0:
            solid.reverse()
        cls.nominal = nominal_from_shape(solid)

    def test_points_near(self):
        self.assertIn("SurfaceOfRevolution", type(self.nominal.faces[0].Surface).__name__)
        rng = np.random.default_rng(15)
        res = self.check(self.nominal, points_near(self.nominal, rng, 250, hi=2.0), 150)
        self.assertLess(res.fallback_fraction, 0.1)


class OpenBSplineFaces(DistanceCase, unittest.TestCase):
    """A compound of two open B-spline faces: sign is the side the face normal points to."""

    @classmethod
    def setUpClass(cls):
        faces = []
        for k, off in enumerate((0.0, 40.0)):
            bs = Part.BSplineSurface()
            bs.interpolate([[V(off + 5 * i, 5 * j, np.sin(0.3 * i + 0.2 * j + k)) for j in range(6)]
                            for i in range(6)])
            f = bs.toShape()
            faces.append(f.reversed() if k == 1 else f)
        cls.nominal = nominal_from_shape(Part.makeCompound(faces))

    def test_points_near(self):
        rng = np.random.default_rng(16)
        p = points_near(self.nominal, rng, 250, hi=3.0)
        res = self.check(self.nominal, p, 150)
        # sign is the side of the (orientation-corrected) face normal
        for i in range(0, 250, 10):
            f = self.nominal.faces[res.face[i]]
            uv = f.Surface.parameter(V(*res.closest[i]))
            n = np.array(f.normalAt(*uv))
            self.assertEqual(np.sign(np.dot(p[i] - res.closest[i], n)), np.sign(res.distance[i]))

    def test_beyond_free_edges(self):
        rng = np.random.default_rng(17)
        self.check(self.nominal, corner_points(self.nominal.shape, rng, 3, 1.0), 0, 1.0)


class TwistedBlade(DistanceCase, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = nominal_from_shape(twisted_blade())

    def test_is_a_closed_solid(self):
        self.assertGreater(self.nominal.shape.Volume, 0)
        self.assertTrue(self.nominal.shape.isValid())

    def test_points_near(self):
        rng = np.random.default_rng(18)
        res = self.check(self.nominal, points_near(self.nominal, rng, 300, hi=1.0), 150)
        self.assertLess(res.fallback_fraction, 0.2)

    def test_edges_and_corners(self):
        rng = np.random.default_rng(19)
        self.check(self.nominal, corner_points(self.nominal.shape, rng, 3, 0.5), 0, 1.0)

    def test_raycast_exact(self):
        """Rays along -Y onto the blade: the hit is on the surface (OCC distance ~0), it is the
        first one (the segment before it does not touch the solid), normals are outward."""
        rng = np.random.default_rng(20)
        n = 60
        o = np.column_stack([rng.uniform(0, 18, n), np.full(n, 40.0), rng.uniform(1, 29, n)])
        d = np.tile([0.0, -1.0, 0.0], (n, 1))
        t, face, nrm = self.nominal.raycast(o, d)
        hit = ~np.isnan(t)
        self.assertGreater(np.count_nonzero(hit), n // 2)
        shape = self.nominal.shape
        for i in np.flatnonzero(hit):
            x = o[i] + t[i] * d[i]
            self.assertLess(shape.distToShape(Part.Vertex(V(*x)))[0], 1e-7)
            before = Part.LineSegment(V(*o[i]), V(*(o[i] + (t[i] - 1e-4) * d[i]))).toShape()
            self.assertGreater(shape.distToShape(before)[0], 1e-5)
            self.assertLess(np.dot(nrm[i], d[i]), 0)
        for i in np.flatnonzero(~hit):
            seg = Part.LineSegment(V(*o[i]), V(*(o[i] + 80 * d[i]))).toShape()
            self.assertGreater(shape.distToShape(seg)[0], 1e-6)


class RaycastClosedForm(unittest.TestCase):
    def test_box_with_hole_from_above(self):
        box = Part.makeBox(10, 10, 10).cut(Part.makeCylinder(2, 10, V(5, 5, 0)))
        nominal = nominal_from_shape(box)
        rng = np.random.default_rng(21)
        n = 2000
        o = np.column_stack([rng.uniform(-1, 11, n), rng.uniform(-1, 11, n), np.full(n, 20.0)])
        t, face, nrm = nominal.raycast(o, np.tile([0, 0, -2.0], (n, 1)))
        xy = o[:, :2]
        expected = np.where(np.all((xy > 0) & (xy < 10), axis=1) & (np.hypot(*(xy - 5).T) > 2), 5.0, np.nan)
        sure = (np.abs(np.hypot(*(xy - 5).T) - 2) > 1e-3) & np.all(np.abs(xy - 5) < 4.999, axis=1) \
            | ~np.all((xy > -1e-3) & (xy < 10 + 1e-3), axis=1)
        np.testing.assert_array_equal(np.isnan(t[sure]), np.isnan(expected[sure]))
        np.testing.assert_allclose(t[sure & ~np.isnan(t)], 5.0, atol=1e-12)   # |d| = 2
        hits = nrm[~np.isnan(t)]
        np.testing.assert_allclose(hits, np.tile([0.0, 0, 1], (len(hits), 1)), atol=1e-12)

    def test_sphere_random_directions(self):
        nominal = nominal_from_shape(Part.makeSphere(5))
        rng = np.random.default_rng(22)
        n = 400
        d = rng.normal(size=(n, 3))
        d /= np.linalg.norm(d, axis=1)[:, None]
        o = -20 * d + rng.normal(0, 3, (n, 3))
        t, face, nrm = nominal.raycast(o, d)
        b = np.einsum("ij,ij->i", o, d)
        disc = b * b - (np.einsum("ij,ij->i", o, o) - 25)
        expected = np.where(disc >= 0, -b - np.sqrt(np.maximum(disc, 0)), np.nan)
        sure = np.abs(disc) > 0.05        # grazing rays are left to the tessellation
        np.testing.assert_array_equal(np.isnan(t[sure]), np.isnan(expected[sure]))
        ok = sure & ~np.isnan(expected)
        np.testing.assert_allclose(t[ok], expected[ok], atol=1e-9)
        x = o[ok] + t[ok, None] * d[ok]
        np.testing.assert_allclose(nrm[ok], x / 5, atol=1e-9)


class Blades(DistanceCase, unittest.TestCase):
    def test_demo_blade(self):
        from BladeInspect.cad.demo_blade import make_demo_blade
        model = make_demo_blade()
        nominal = nominal_from_shape(model.shape, roles=model.roles)
        rng = np.random.default_rng(23)
        res = self.check(nominal, points_near(nominal, rng, 200, hi=2.0), 100)
        self.assertLess(res.fallback_fraction, 0.2)
        self.check(nominal, corner_points(nominal.shape, rng, 1, 0.3)[:150], 0, 1.0)

    def test_rotor67(self):
        if not helpers.have_rotor67():
            self.skipTest("the Rotor 67 data (../shared) is not there")
        from BladeInspect.cad.rotor67 import make_rotor67_blade
        model = make_rotor67_blade(helpers.ROTOR67_SECTIONS)
        nominal = nominal_from_shape(model.shape, roles=model.roles)
        rng = np.random.default_rng(24)
        res = self.check(nominal, points_near(nominal, rng, 150, hi=2.0), 75)
        self.assertLess(res.fallback_fraction, 0.2)


class BadInput(unittest.TestCase):
    def test_errors_are_input_errors(self):
        with self.assertRaises(InputError):
            nominal_from_shape(Part.Shape())
        nominal = nominal_from_shape(Part.makeBox(1, 1, 1))
        with self.assertRaises(InputError):
            nominal.signed_distance(np.zeros((3, 2)))
        with self.assertRaises(InputError):
            nominal.signed_distance([[np.nan, 0, 0]])
        with self.assertRaises(InputError):
            nominal_from_shape(Part.makeBox(1, 1, 1), sample_spacing=-1)


if __name__ == "__main__":
    unittest.main()
