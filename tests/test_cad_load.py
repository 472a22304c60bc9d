"""Loading CAD and point files: exchange formats round-trip the demo blade; bad files are one
InputError line naming the file."""
import os
import shutil
import tempfile
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect.cad.demo_blade import make_demo_blade
from BladeInspect.cad.load import load_shape, read_points_any
from BladeInspect.core.errors import InputError


class LoadShape(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="bladeinspect-load-")
        cls.blade = make_demo_blade().shape

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.tmp, name)

    def assert_same_blade(self, loaded, solid=True, area_rtol=1e-6):
        self.assertEqual(len(loaded.Faces), len(self.blade.Faces))
        # Same faces: matched by area, every face of the original found once.
        areas = sorted(f.Area for f in loaded.Faces)
        np.testing.assert_allclose(areas, sorted(f.Area for f in self.blade.Faces),
                                   rtol=area_rtol)
        bb, ref = loaded.BoundBox, self.blade.BoundBox
        np.testing.assert_allclose([bb.XMin, bb.YMin, bb.ZMin, bb.XMax, bb.YMax, bb.ZMax],
                                   [ref.XMin, ref.YMin, ref.ZMin, ref.XMax, ref.YMax, ref.ZMax],
                                   atol=1e-4)
        if solid:
            self.assertEqual(len(loaded.Solids), 1)
            self.assertAlmostEqual(loaded.Volume / self.blade.Volume, 1.0, delta=1e-6)
            self.assertTrue(loaded.isValid())

    def test_step_round_trip(self):
        for ext in ("step", "stp"):
            self.blade.exportStep(self.path("blade." + ext))
            self.assert_same_blade(load_shape(self.path("blade." + ext)))

    def test_brep_round_trip(self):
        for ext in ("brep", "brp"):
            self.blade.exportBrep(self.path("blade." + ext))
            self.assert_same_blade(load_shape(self.path("blade." + ext)))

    def test_iges_round_trip(self):
        self.blade.exportIges(self.path("blade.iges"))
        shutil.copy(self.path("blade.iges"), self.path("BLADE.IGS"))
        for name in ("blade.iges", "BLADE.IGS"):
            loaded = load_shape(self.path(name))
            # IGES carries faces, not necessarily the solid, and trims the planar caps with
            # approximated curves (areas to 1e-5).
            self.assert_same_blade(loaded, solid=bool(loaded.Solids), area_rtol=5e-5)

    def test_fcstd_takes_visible_shapes_and_closes_the_document(self):
        doc = FreeCAD.newDocument("LoadTestWrite", hidden=True)
        doc.addObject("Part::Feature", "Blade").Shape = self.blade
        hidden = doc.addObject("Part::Feature", "Fixture")
        hidden.Shape = Part.makeBox(100, 100, 5)
        hidden.Visibility = False
        doc.saveAs(self.path("blade.FCStd"))
        FreeCAD.closeDocument(doc.Name)
        before = set(FreeCAD.listDocuments())
        self.assert_same_blade(load_shape(self.path("blade.FCStd")))
        self.assertEqual(set(FreeCAD.listDocuments()), before)

    def test_fcstd_with_two_visible_shapes_gives_both(self):
        doc = FreeCAD.newDocument("LoadTestTwo", hidden=True)
        doc.addObject("Part::Feature", "Blade").Shape = self.blade
        doc.addObject("Part::Feature", "Box").Shape = Part.makeBox(1, 1, 1, FreeCAD.Vector(100, 0, 0))
        doc.saveAs(self.path("two.FCStd"))
        FreeCAD.closeDocument(doc.Name)
        loaded = load_shape(self.path("two.FCStd"))
        self.assertEqual(len(loaded.Faces), len(self.blade.Faces) + 6)
        # Per solid: OCC's volume of a whole compound is integrated less precisely.
        self.assertAlmostEqual(sum(s.Volume for s in loaded.Solids), self.blade.Volume + 1.0,
                               places=6)

    def test_fcstd_containers_bodies_and_hidden_groups(self):
        doc = FreeCAD.newDocument("LoadTestGroups", hidden=True)
        try:
            body = doc.addObject("PartDesign::Body", "Body")
        except Exception:
            FreeCAD.closeDocument(doc.Name)
            self.skipTest("PartDesign is not loadable here")
        body.addObject(doc.addObject("PartDesign::AdditiveBox", "BodyBox"))
        moved = doc.addObject("App::Part", "Moved")
        moved.Placement.Base = FreeCAD.Vector(100, 0, 0)
        moved.addObject(doc.addObject("Part::Feature", "Blade"))
        doc.getObject("Blade").Shape = self.blade
        hidden = doc.addObject("App::Part", "Hidden")
        hidden.Visibility = False
        hidden.addObject(doc.addObject("Part::Box", "Fixture"))
        doc.recompute()
        doc.saveAs(self.path("groups.FCStd"))
        FreeCAD.closeDocument(doc.Name)
        loaded = load_shape(self.path("groups.FCStd"))
        # The body once (not again as its feature), the blade where its container puts it,
        # nothing of the hidden group.
        self.assertEqual(len(loaded.Faces), 6 + len(self.blade.Faces))
        volumes = sorted(s.Volume for s in loaded.Solids)
        self.assertAlmostEqual(volumes[0], 1000.0, places=6)
        self.assertAlmostEqual(volumes[1], self.blade.Volume, places=6)
        blade = max(loaded.Solids, key=lambda s: s.Volume)
        self.assertAlmostEqual(blade.BoundBox.XMin, self.blade.BoundBox.XMin + 100, places=6)

    def assert_input_error(self, path, *words):
        with self.assertRaises(InputError) as ctx:
            load_shape(path)
        msg = str(ctx.exception)
        self.assertTrue(msg.startswith(path + ": "), msg)
        self.assertNotIn("\n", msg)
        for w in words:
            self.assertIn(w, msg)

    def test_step_without_faces(self):
        Part.makeLine(FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(1, 2, 3)).exportStep(
            self.path("line.step"))
        self.assert_input_error(self.path("line.step"), "no faces")

    def test_bad_files(self):
        for name in ("garbage.step", "garbage.iges", "garbage.brep", "garbage.FCStd"):
            with open(self.path(name), "w") as fh:
                fh.write("this is not CAD\n")
            self.assert_input_error(self.path(name))
        open(self.path("empty.stp"), "w").close()
        self.assert_input_error(self.path("empty.stp"), "empty")
        self.assert_input_error(self.path("missing.step"), "no such file")
        self.assert_input_error(self.path("blade.obj"), "unsupported")
        os.mkdir(self.path("folder.step"))
        self.assert_input_error(self.path("folder.step"), "folder")


class ReadPointsAny(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="bladeinspect-points-")
        rng = np.random.default_rng(3)
        cls.xyz = np.round(rng.uniform(-50, 50, (25, 3)), 4)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def write(self, name, header, rows):
        path = os.path.join(self.tmp, name)
        with open(path, "w") as fh:
            fh.write(header)
            for r in rows:
                fh.write(" ".join(r) + "\n")
        return path

    def rows(self):
        rows = [["%.4f" % v for v in p] for p in self.xyz]
        return rows[:5] + [["nan", "1", "2"]] + rows[5:]

    def test_ply_and_pcd_through_freecad(self):
        n = len(self.xyz) + 1
        ply = self.write("cloud.ply", "ply\nformat ascii 1.0\nelement vertex %d\n"
                         "property float x\nproperty float y\nproperty float z\nend_header\n"
                         % n, self.rows())
        pcd = self.write("cloud.pcd", "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
                         "TYPE F F F\nCOUNT 1 1 1\nWIDTH %d\nHEIGHT 1\n"
                         "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA ascii\n" % (n, n),
                         self.rows())
        before = set(FreeCAD.listDocuments())
        for path in (ply, pcd):
            ps = read_points_any(path)
            # Stored as 32-bit floats in the file header's type.
            np.testing.assert_allclose(ps.xyz, self.xyz, atol=1e-4)
            self.assertEqual(ps.n_rows_skipped, 1)
            self.assertIsNone(ps.snr)
            self.assertEqual(ps.source, path)
        self.assertEqual(set(FreeCAD.listDocuments()), before)

    def test_text_files_go_to_the_core_reader(self):
        path = self.write("cloud.xyz", "", [["%.4f" % v for v in p] for p in self.xyz])
        np.testing.assert_allclose(read_points_any(path).xyz, self.xyz)

    def test_bad_point_files(self):
        garbage = self.write("garbage.ply", "not a ply\n", [])
        few = self.write("few.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                         "property float y\nproperty float z\nend_header\n",
                         [["1", "2", "3"]] * 3)
        for path, word in ((garbage, "PLY"), (few, "usable points"),
                           (os.path.join(self.tmp, "missing.pcd"), "no such file")):
            with self.assertRaises(InputError) as ctx:
                read_points_any(path)
            self.assertTrue(str(ctx.exception).startswith(path + ": "), str(ctx.exception))
            self.assertIn(word, str(ctx.exception))


if __name__ == "__main__":
    unittest.main()
