"""NASA Rotor 67 from its section table: values read as the file prints them, a valid solid
through the sections, and an independent point cloud of the same blade lying on it."""
import math
import os
import shutil
import tempfile
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect.cad.rotor67 import (FOOT_MM, blade_sections, make_rotor67_blade,
                                      read_rotor67)
from BladeInspect.core.errors import InputError
from tests.helpers import ROTOR67_CLOUD, ROTOR67_SECTIONS, have_rotor67

V = FreeCAD.Vector


def xyz_mm(axial_ft, r_theta_ft, radius_ft):
    r = radius_ft * FOOT_MM
    theta = r_theta_ft / radius_ft
    return np.array([r * math.cos(theta), r * math.sin(theta), axial_ft * FOOT_MM])


@unittest.skipUnless(have_rotor67(), "Rotor 67 data not present")
class Rotor67Reading(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.table = read_rotor67(ROTOR67_SECTIONS)

    def test_header_and_blocks(self):
        t = self.table
        self.assertEqual((t["jm"], t["ns"], t["jle"], t["jte"]), (110, 14, 16, 85))
        self.assertEqual(t["radius"].shape, (14, 110))
        # Surface 1 as printed in the file: first axial values, J=16 radius.
        np.testing.assert_array_equal(t["axial"][0, :3], [-0.830950, -0.756702, -0.682454])
        self.assertEqual(t["radius"][0, 15], 0.313693)
        self.assertEqual(t["thickness"][0, 16], 0.000646)
        self.assertEqual(t["r_theta"][0, 7], 0.001941)

    def test_section_points_in_mm_match_hand_values(self):
        upper, lower = blade_sections(self.table)
        self.assertEqual(upper.shape, (14, 70, 3))
        # Surface 1, J=16 (leading edge, thickness 0): axial -0.002474, r*theta 0.002090,
        # radius 0.313693 ft. J=17: axial -0.002439, r*theta 0.002413, thickness 0.000646,
        # radius 0.313701 ft.
        le = xyz_mm(-0.002474, 0.002090, 0.313693)
        np.testing.assert_allclose(upper[0, 0], le, atol=1e-9)
        np.testing.assert_allclose(lower[0, 0], le, atol=1e-9)
        np.testing.assert_allclose(le, [95.611504, 0.637032, -0.754075], atol=1e-5)
        np.testing.assert_allclose(upper[0, 1], xyz_mm(-0.002439, 0.002413, 0.313701),
                                   atol=1e-9)
        np.testing.assert_allclose(lower[0, 1], xyz_mm(-0.002439, 0.002413 - 0.000646,
                                                       0.313701), atol=1e-9)
        # Both sides meet at the trailing edge too, and the upper side has the larger theta.
        np.testing.assert_array_equal(upper[:, -1], lower[:, -1])
        th_u = np.arctan2(upper[:, 1:-1, 1], upper[:, 1:-1, 0])
        th_l = np.arctan2(lower[:, 1:-1, 1], lower[:, 1:-1, 0])
        self.assertTrue(np.all(th_u > th_l))


@unittest.skipUnless(have_rotor67(), "Rotor 67 data not present")
class Rotor67Solid(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.model = make_rotor67_blade(ROTOR67_SECTIONS)
        cls.shape = cls.model.shape
        cls.upper, cls.lower = blade_sections(read_rotor67(ROTOR67_SECTIONS))

    def test_valid_solid_with_four_roled_faces(self):
        self.assertEqual(self.shape.ShapeType, "Solid")
        self.assertTrue(self.shape.isValid())
        self.assertGreater(self.shape.Volume, 0)
        self.assertEqual(sorted(i for v in self.model.roles.values() for i in v), [0, 1, 2, 3])
        # Span from hub to casing radius, chord ~ 92-95 mm (PROVENANCE figures).
        bb = self.shape.BoundBox
        r_max = max(np.hypot(p.x, p.y) for p in (v.Point for v in self.shape.Vertexes))
        # The tip LE vertex: surface 14, J=16, radius 0.838238 ft as printed.
        self.assertAlmostEqual(r_max, 0.838238 * FOOT_MM, delta=1e-6)
        self.assertTrue(85 < bb.ZLength < 105, bb)

    def test_sections_lie_on_their_faces(self):
        faces = {role: self.shape.Faces[self.model.roles[role][0]]
                 for role in ("suction", "pressure", "hub", "tip")}
        for side, pts in (("suction", self.upper), ("pressure", self.lower)):
            for q in pts[::3, ::7].reshape(-1, 3):
                self.assertLess(faces[side].distToShape(Part.Vertex(V(*q)))[0], 1e-6)
        for role, k in (("hub", 0), ("tip", -1)):
            for q in np.vstack([self.upper[k, ::9], self.lower[k, 4::9]]):
                self.assertLess(faces[role].distToShape(Part.Vertex(V(*q)))[0], 1e-6)

    def test_normals_point_outward(self):
        for face in self.shape.Faces:
            # Start from the area centre projected onto the surface (a cap's centre of mass
            # is off its curved surface).
            uv = face.Surface.parameter(face.CenterOfMass)
            self.assertTrue(face.isPartOfDomain(*uv))
            p, n = face.valueAt(*uv), face.normalAt(*uv)
            self.assertFalse(self.shape.isInside(p + n * 0.05, 1e-7, False))
            self.assertTrue(self.shape.isInside(p - n * 0.05, 1e-7, False))

    def test_upper_side_is_the_convex_one(self):
        # In each streamsurface's unrolled (axial, r*theta) plane the upper side (which the
        # suction face interpolates, see test_sections_lie_on_their_faces) turns one way
        # almost everywhere; the lower side turns both ways (concave aft).
        t = read_rotor67(ROTOR67_SECTIONS)
        blade = slice(t["jle"] - 1, t["jte"])
        for k in range(t["ns"]):
            z, rt = t["axial"][k, blade], t["r_theta"][k, blade]
            for side, y in (("upper", rt), ("lower", rt - t["thickness"][k, blade])):
                d = np.column_stack([np.diff(z), np.diff(y)])
                turn = d[:-1, 0] * d[1:, 1] - d[:-1, 1] * d[1:, 0]
                share = np.mean(turn < 0)
                if side == "upper":
                    self.assertGreater(share, 0.85, "surface %d" % (k + 1))
                else:
                    self.assertLess(share, 0.7, "surface %d" % (k + 1))

    def test_cached_copies_are_independent(self):
        again = make_rotor67_blade(ROTOR67_SECTIONS)
        again.shape.translate(V(0, 0, 10))
        again.roles["hub"].append(99)
        third = make_rotor67_blade(ROTOR67_SECTIONS)
        self.assertAlmostEqual(third.shape.BoundBox.ZMin, self.shape.BoundBox.ZMin, places=9)
        self.assertEqual(third.roles, self.model.roles)

    def test_independent_cloud_lies_on_the_loft(self):
        cloud = np.loadtxt(ROTOR67_CLOUD)[:, 1:4] * 1000.0
        rng = np.random.default_rng(67)
        pick = cloud[rng.choice(len(cloud), 200, replace=False)]
        d = np.array([self.shape.distToShape(Part.Vertex(V(*q)))[0] for q in pick])
        self.assertLess(np.median(d), 0.1)
        self.assertLess(np.percentile(d, 99), 0.35)


@unittest.skipUnless(have_rotor67(), "Rotor 67 data not present")
class Rotor67RealCloudRegistration(unittest.TestCase):
    def test_register_finds_the_provenance_frame(self):
        """The independent CFD cloud, moved to a random pose (any rotation, 150 mm away),
        through `register` against the loft of the section table: both are in one frame by
        their provenance, and the geometries differ by up to 0.3 mm, so the pose must come
        back to within a few hundredths of a millimetre of it."""
        import json
        from BladeInspect import cli
        from BladeInspect.core import transforms as tf
        cloud = np.loadtxt(ROTOR67_CLOUD)[:, 1:4] * 1000.0
        move = tf.random_transform(np.random.default_rng(2067), 150.0)
        folder = tempfile.mkdtemp(prefix="bladeinspect-r67cloud-")
        self.addCleanup(shutil.rmtree, folder, True)
        points = os.path.join(folder, "cloud.csv")
        np.savetxt(points, tf.apply_transform(move, cloud), delimiter=",", header="x,y,z",
                   comments="")
        out = os.path.join(folder, "out")
        self.assertEqual(cli.main(["register", "--cad", ROTOR67_SECTIONS, "--points", points,
                                   "--out", out]), 0)
        with open(os.path.join(out, "result.json")) as fh:
            result = json.load(fh)
        lo, hi = cloud.min(axis=0), cloud.max(axis=0)
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                            for z in (lo[2], hi[2])])
        err = tf.corner_displacement(np.array(result["measured_to_cad"]),
                                     tf.invert_transform(move), corners)
        self.assertLess(err, 0.08, "pose %.4f mm from the provenance frame" % err)
        # The points the robust fit keeps are the blade's own differences, microns not tenths.
        self.assertLess(result["rms_mm"], 0.02)
        self.assertGreater(result["n_inliers"], 0.8 * len(cloud))


@unittest.skipUnless(have_rotor67(), "Rotor 67 data not present")
class Rotor67BadFiles(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="bladeinspect-r67-")
        with open(ROTOR67_SECTIONS) as fh:
            cls.lines = fh.read().splitlines()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def variant(self, name, lines):
        path = os.path.join(self.tmp, name)
        with open(path, "w") as fh:
            fh.write("\n".join(lines) + "\n")
        return path

    def assert_bad(self, path, *words):
        with self.assertRaises(InputError) as ctx:
            make_rotor67_blade(path)
        msg = str(ctx.exception)
        self.assertTrue(msg.startswith(path), msg)
        for w in words:
            self.assertIn(w, msg)

    def test_malformed_files(self):
        n = len(self.lines)
        self.assert_bad(self.variant("truncated.dat", self.lines[: n // 2]), "surface")
        garbled = list(self.lines)
        k = next(i for i, l in enumerate(garbled) if "Surface number  5" in l) + 4
        garbled[k] = garbled[k][:20] + " x.y " + garbled[k][25:]
        self.assert_bad(self.variant("garbled.dat", garbled), "line %d" % (k + 1),
                        "non-number")
        self.assert_bad(self.variant("noheader.dat", [l for l in self.lines
                                                      if "JLE" not in l]), "JM NS NB JLE JTE")
        self.assert_bad(os.path.join(self.tmp, "missing.dat"), "no such")

    def test_section_choice_is_checked(self):
        with self.assertRaises(InputError):
            make_rotor67_blade(ROTOR67_SECTIONS, sections=[3])
        with self.assertRaises(InputError):
            make_rotor67_blade(ROTOR67_SECTIONS, sections=range(1, 16))


if __name__ == "__main__":
    unittest.main()
