"""Plane sections of the demo blade against the faces' own points at the plane, found
independently by solving z(u, v) = z0 on each B-spline face with OCC's evaluator."""
import unittest

import numpy as np
from scipy.optimize import brentq

import FreeCAD
import Part

from BladeInspect.cad.demo_blade import make_demo_blade
from BladeInspect.cad.sections import cut
from BladeInspect.core.errors import InputError

V = FreeCAD.Vector


def face_points_at_height(face, z0, n_u=60):
    """Points of a side face (u chordwise, v spanwise, z increasing with v) with z = z0."""
    srf = face.Surface
    u0, u1, v0, v1 = face.ParameterRange
    pts = []
    for u in np.linspace(u0, u1, n_u):
        v = brentq(lambda v: srf.value(u, v).z - z0, v0, v1, xtol=1e-14)
        pts.append(tuple(srf.value(u, v)))
    return np.array(pts)


def distance_to_polyline(points, line):
    a, b = line[:-1], line[1:]
    ab = b - a
    out = []
    for p in points:
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
        out.append(np.min(np.linalg.norm(a + t[:, None] * ab - p, axis=1)))
    return np.array(out)


def shoelace_xy(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


class CutDemoBlade(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.model = make_demo_blade()
        cls.shape = cls.model.shape
        cls.sides = [cls.shape.Faces[cls.model.roles[r][0]] for r in ("suction", "pressure")]

    def test_cut_across_the_span_is_the_faces_profile(self):
        # Heights between the lofted sections (z = 0, 8.75, 17.5, ...).
        for z0 in (4.1, 37.9):
            lines = cut(self.shape, [0, 0, z0], [0, 0, 1])
            self.assertEqual(len(lines), 1)
            line = lines[0]
            np.testing.assert_array_equal(line[0], line[-1])
            np.testing.assert_allclose(line[:, 2], z0, atol=1e-9)
            spacing = np.linalg.norm(np.diff(line, axis=0), axis=1)
            self.assertLessEqual(spacing.max(), 0.02)
            truth = [face_points_at_height(f, z0) for f in self.sides]
            # Chord sag of 0.02 mm steps round the smallest edge radius (0.15 mm) < 0.34 um.
            for pts in truth:
                self.assertLess(distance_to_polyline(pts, line).max(), 0.02 ** 2 / 1.2 + 1e-6)
            fine = cut(self.shape, [0, 0, z0], [0, 0, 1], spacing=0.002)[0]
            for pts in truth:
                self.assertLess(distance_to_polyline(pts, fine).max(), 1e-5)
            # Same enclosed area as the faces' own profile (suction LE->TE, pressure back).
            dense = [face_points_at_height(f, z0, 400) for f in self.sides]
            loop = np.vstack([dense[0], dense[1][::-1]])
            self.assertAlmostEqual(shoelace_xy(line) / shoelace_xy(loop), 1.0, delta=2e-4)

    def test_tilted_plane_points_are_on_the_shape_and_in_the_plane(self):
        normal = np.array([0.15, -0.1, 1.0])
        origin = np.array([5.0, 3.0, 40.0])
        lines = cut(self.shape, origin, normal)
        self.assertEqual(len(lines), 1)
        n = normal / np.linalg.norm(normal)
        np.testing.assert_allclose((lines[0] - origin) @ n, 0.0, atol=1e-7)
        for p in lines[0][::97]:
            self.assertLess(self.shape.distToShape(Part.Vertex(V(*p)))[0], 2e-4)

    def test_plane_along_the_span_and_loose_faces(self):
        # A plane x = const crosses the blade as one loop; the two side faces alone (no caps,
        # not sewn) give one open hub-to-tip polyline each.
        loops = cut(self.shape, [10.0, 0, 0], [1, 0, 0])
        self.assertEqual(len(loops), 1)
        np.testing.assert_array_equal(loops[0][0], loops[0][-1])
        loose = Part.Compound([f.copy() for f in self.sides])
        lines = cut(loose, [10.0, 0, 0], [1, 0, 0])
        self.assertEqual(len(lines), 2)
        for line in lines:
            self.assertAlmostEqual(min(line[0, 2], line[-1, 2]), 0.0, places=6)
            self.assertAlmostEqual(max(line[0, 2], line[-1, 2]), 70.0, places=6)
        # Cut across z, the loose faces still give the closed profile.
        lines = cut(loose, [0, 0, 20.0], [0, 0, 1])
        self.assertEqual(len(lines), 1)
        np.testing.assert_array_equal(lines[0][0], lines[0][-1])

    def test_missing_plane_and_bad_normal(self):
        with self.assertRaises(InputError) as ctx:
            cut(self.shape, [0, 0, 100], [0, 0, 1])
        self.assertIn("misses", str(ctx.exception))
        for normal in ([0, 0, 0], [np.nan, 0, 1]):
            with self.assertRaises(InputError):
                cut(self.shape, [0, 0, 10], normal)


if __name__ == "__main__":
    unittest.main()
