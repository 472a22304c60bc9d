"""Document objects, headless: what they store is checked against independent computations
(numpy transforms, the colour map applied point by point, bounding boxes, files parsed with
numpy), they survive save and reopen, recompute when an input changes, and an error leaves no
half-built objects. Packaging files are checked here too."""
import dataclasses
import os
import shutil
import subprocess
import tempfile
import unittest
import xml.etree.ElementTree as ET

import numpy as np

import FreeCAD

from BladeInspect.app import objects, registration_fit
from BladeInspect.app.objects import reconstruction, registration
from BladeInspect.core import icp
from BladeInspect.core.errors import InputError
from tests.helpers import REPO

COMMAND_VERBS = ("DemoBlade", "LoadCad", "ConnectRig", "Scan", "ImportPoints", "Reconstruct",
                 "Register", "DeviationMap", "SectionAnalysis", "Airfoil", "Report", "Preferences",
                 "CamberLine", "EdgeCircles")


class FakePointSet:
    """The PointSet fields make_measurement reads, without depending on core.pointio."""

    def __init__(self, xyz, snr=None, columns=None, n_rows_skipped=0, source=""):
        self.xyz, self.snr = xyz, snr
        self.columns = columns or {}
        self.n_rows_skipped, self.source = n_rows_skipped, source


def random_rotation(rng):
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def synthetic_result(rng, n=300, deviation=None):
    """A RegistrationResult with a random pose and known deviations, as the pipeline makes."""
    from BladeInspect.core.stats import deviation_statistics
    from BladeInspect.inspection.result import RegistrationResult
    T = np.eye(4)
    T[:3, :3] = random_rotation(rng)
    T[:3, 3] = rng.uniform(-50, 50, 3)
    measured = rng.uniform(-30, 30, (n, 3))
    points_cad = measured @ T[:3, :3].T + T[:3, 3]
    dev = rng.normal(0, 0.01, n) if deviation is None else np.asarray(deviation, float)
    A = rng.normal(size=(6, 6))
    cov = A @ A.T * 1e-8
    normal = rng.normal(size=(n, 3))
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    return measured, RegistrationResult(
        measured_to_cad=T, points_cad=points_cad, deviation=dev,
        inlier=np.abs(dev) < 0.03, closest=points_cad - dev[:, None] * normal, normal=normal,
        face=np.zeros(n, int), snr=rng.uniform(10, 90, n), columns={}, n_rows_skipped=0,
        rms_mm=float(np.sqrt(np.mean(dev ** 2))), pose_covariance=cov,
        center=rng.uniform(-5, 5, 3), pose_uncertainty_mm=0.0007,
        deviation_stats=deviation_statistics(dev), coarse={"warning": None},
        warnings=["a warning"])


class DocumentCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="bi-app-")
        self.doc = FreeCAD.newDocument("BladeInspectAppTest")

    def tearDown(self):
        for doc in list(FreeCAD.listDocuments().values()):
            if doc.Name.startswith("BladeInspectAppTest"):
                FreeCAD.closeDocument(doc.Name)
        shutil.rmtree(self.tmp, ignore_errors=True)

    def reopen(self):
        path = os.path.join(self.tmp, "doc.FCStd")
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        return self.doc


class TestMeasurement(DocumentCase):
    def test_points_snr_and_columns_survive_save_and_reopen_in_double_precision(self):
        rng = np.random.default_rng(1)
        xyz = rng.uniform(-70, 70, (500, 3)) + 1e-9 * rng.normal(size=(500, 3))
        snr = rng.uniform(0, 100, 500)
        section = rng.integers(0, 5, 500).astype(float)
        obj = objects.make_measurement(self.doc, FakePointSet(xyz, snr, {"section": section},
                                                              n_rows_skipped=3))
        name = obj.Name
        doc = self.reopen()
        obj = doc.getObject(name)
        self.assertEqual(objects.proxy_type(obj), "BladeInspect::Measurement")
        self.assertEqual(obj.NPoints, 500)
        self.assertEqual(obj.NRowsSkipped, 3)
        self.assertEqual(obj.Points.CountPoints, 500)
        self.assertAlmostEqual(obj.MeanSNR, snr.mean(), places=9)
        ps = objects.pointset_of(obj)
        xyz_back, snr_back, cols = ps.xyz, ps.snr, ps.columns
        np.testing.assert_array_equal(xyz_back, xyz)   # bit for bit: stored as doubles
        np.testing.assert_array_equal(snr_back, snr)
        np.testing.assert_array_equal(cols["section"], section)
        # The display kernel is single precision: close, not equal.
        shown = np.array([(v.x, v.y, v.z) for v in obj.Points.Points])
        np.testing.assert_allclose(shown, xyz, atol=1e-5)

    def test_recompute_rereads_the_source_file_when_it_changes(self):
        from BladeInspect.inspection.pipeline import load_points
        path = os.path.join(self.tmp, "pts.csv")
        rng = np.random.default_rng(2)
        first = np.column_stack([rng.uniform(-10, 10, (50, 3)), rng.uniform(0, 100, 50)])
        np.savetxt(path, first, delimiter=",", header="x,y,z,snr", comments="", fmt="%.9f")
        obj = objects.make_measurement(self.doc, load_points(path), source_file=path)
        self.doc.recompute()
        np.testing.assert_allclose(np.reshape(obj.Coordinates, (-1, 3)), first[:, :3],
                                   atol=1e-9)
        second = np.column_stack([rng.uniform(-10, 10, (70, 3)), rng.uniform(0, 100, 70)])
        np.savetxt(path, second, delimiter=",", header="x,y,z,snr", comments="", fmt="%.9f")
        os.utime(path, ns=(1, 10 ** 18))   # a different mtime even within the clock's tick
        obj.touch()
        self.doc.recompute()
        expected = np.loadtxt(path, delimiter=",", skiprows=1)
        self.assertEqual(obj.NPoints, 70)
        np.testing.assert_allclose(np.reshape(obj.Coordinates, (-1, 3)), expected[:, :3],
                                   atol=1e-9)
        np.testing.assert_allclose(obj.SNR, expected[:, 3], atol=1e-9)


class FakeReconstruction:
    """What cad.loft.reconstruct returns: B-spline curves through known points, a surface."""

    def __init__(self, points_per_curve):
        import Part
        self.curves = []
        for pts in points_per_curve:
            curve = Part.BSplineCurve()
            curve.interpolate([FreeCAD.Vector(*p) for p in pts])
            self.curves.append(curve)
        surface = Part.BSplineSurface()
        grid = [[FreeCAD.Vector(x, y, 0.1 * x * y) for y in range(4)] for x in range(4)]
        surface.interpolate(grid)
        self.surfaces = [surface]
        self.samples = np.zeros((0, 3))
        self.fit_errors = [{"section": i, "side": "suction", "rms": 0.001 * (i + 1),
                            "max": 0.003 * (i + 1)} for i in range(len(points_per_curve))]


class TestReconstruction(DocumentCase):
    def _curves(self, rng, shift=0.0):
        return [np.column_stack([np.linspace(0, 40, 12), rng.uniform(-2, 2, 12) + shift,
                                 np.full(12, 10.0 * k)]) for k in range(3)]

    def test_geometry_passes_through_the_fitted_points_after_reopen(self):
        import Part
        rng = np.random.default_rng(7)
        curves = self._curves(rng)
        meas = objects.make_measurement(self.doc, FakePointSet(np.vstack(curves)))
        obj = objects.make_reconstruction(self.doc, meas, FakeReconstruction(curves))
        name = obj.Name
        obj = self.reopen().getObject(name)
        self.assertEqual(obj.NCurves, 3)
        self.assertEqual(obj.NSurfaces, 1)
        self.assertEqual(len(obj.Shape.Faces), 1)
        self.assertEqual(len(obj.Shape.Edges), 3 + 4)   # three curves, the face's boundary
        np.testing.assert_allclose(obj.FitErrors, [0.001, 0.002, 0.003])
        self.assertAlmostEqual(obj.MaxFitErrorMm, 0.009)
        # Each curve interpolates its points: OCC's own distance to the stored shape is ~0.
        for pts in curves:
            for p in pts[::3]:
                d = obj.Shape.distToShape(Part.Vertex(FreeCAD.Vector(*p)))[0]
                self.assertLess(d, 1e-7)

    def test_recomputes_when_the_measurement_changes(self):
        rng = np.random.default_rng(8)
        first, second = self._curves(rng), self._curves(rng, shift=5.0)
        calls = []

        def fake_reconstruct(pointset):
            calls.append(len(pointset.xyz))
            return FakeReconstruction(second)
        from BladeInspect.cad import loft
        saved_reconstruct = loft.reconstruct
        saved_pointset_of = reconstruction.pointset_of
        loft.reconstruct = fake_reconstruct
        reconstruction.pointset_of = lambda obj: FakePointSet(
            np.reshape(obj.Coordinates, (-1, 3)))
        try:
            meas = objects.make_measurement(self.doc, FakePointSet(np.vstack(first)))
            obj = objects.make_reconstruction(self.doc, meas, FakeReconstruction(first))
            self.doc.recompute()
            self.assertEqual(calls, [])
            objects.store_pointset(meas, FakePointSet(np.vstack(second)[:30]))
            self.doc.recompute()
            self.assertEqual(calls, [30])
            ys = [v.Y for v in obj.Shape.Edges[0].Vertexes]
            self.assertTrue(all(y > 2.5 for y in ys), ys)   # the shifted curves are stored
        finally:
            reconstruction.pointset_of = saved_pointset_of
            loft.reconstruct = saved_reconstruct


class TestRegistration(DocumentCase):
    def test_pose_and_uncertainty_match_the_result_after_reopen(self):
        rng = np.random.default_rng(3)
        for trial in range(3):
            measured, result = synthetic_result(rng)
            n = len(result.deviation)
            result.inlier_cut = icp.InlierCut(
                rng.uniform(0.5, 1.5, n), 0.0123, rng.uniform(0.01, 0.02, n),
                rng.uniform(0.0, 0.004, n), 0.0031,
                icp.Neighbourhoods(result.points_cad, 16)) if trial else None
            obj = objects.make_registration(self.doc, result, name="Reg%d" % trial)
            name = obj.Name
            obj = self.reopen().getObject(name)
            T = result.measured_to_cad
            # The Placement maps measured points exactly as the 4x4 does (independent numpy).
            for p in measured[:20]:
                q = obj.Pose.multVec(FreeCAD.Vector(*p))
                np.testing.assert_allclose([q.x, q.y, q.z], T[:3, :3] @ p + T[:3, 3],
                                           atol=1e-9)
            np.testing.assert_allclose(objects.matrix_array(obj.MeasuredToCad), T, atol=1e-12)
            cov = result.pose_covariance
            np.testing.assert_allclose(np.reshape(obj.PoseCovariance, (6, 6)), cov)
            np.testing.assert_allclose(tuple(obj.TranslationSigmaMm),
                                       np.sqrt(np.diag(cov)[:3]), rtol=1e-12)
            np.testing.assert_allclose(tuple(obj.RotationSigmaDeg),
                                       np.degrees(np.sqrt(np.diag(cov)[3:])), rtol=1e-12)
            self.assertAlmostEqual(obj.PoseUncertaintyMm, 0.0007)
            self.assertAlmostEqual(obj.RmsMm, np.sqrt(np.mean(result.deviation ** 2)))
            self.assertAlmostEqual(obj.DeviationMaxMm, result.deviation.max())
            self.assertEqual(obj.NInliers, int(np.count_nonzero(np.abs(result.deviation) < 0.03)))
            points, dev, inlier = objects.registration_points(obj)
            np.testing.assert_allclose(points, measured @ T[:3, :3].T + T[:3, 3], atol=1e-9)
            np.testing.assert_array_equal(dev, result.deviation)
            self.assertEqual(list(obj.Warnings), ["a warning"])
            # the fit's zero-weight boundaries come back to the bit (none stored: none)
            restored = dataclasses.replace(result, inlier_cut=None)
            registration_fit.restore(obj, restored)
            if result.inlier_cut is None:
                self.assertIsNone(restored.inlier_cut)
                continue
            for field in ("root", "limit", "allowance", "point_cut", "neighbourhood_cut"):
                np.testing.assert_array_equal(getattr(restored.inlier_cut, field),
                                              getattr(result.inlier_cut, field))
            np.testing.assert_array_equal(
                restored.inlier_cut.neighbourhoods.members(np.arange(n)),
                result.inlier_cut.neighbourhoods.members(np.arange(n)))

    def test_re_registers_only_when_an_input_changes(self):
        """The pipeline is replaced by a stand-in whose answer is known (identity pose,
        deviation = z), to check when the object recomputes and what it then stores."""
        import BladeInspect.inspection.pipeline as pipeline
        rng = np.random.default_rng(4)
        calls = []
        _, template = synthetic_result(rng, n=40)

        def fake_register(nominal, pointset, seed=0, progress=None):
            calls.append(seed)
            xyz = np.asarray(pointset.xyz)
            r = synthetic_result(np.random.default_rng(0), n=len(xyz), deviation=xyz[:, 2])[1]
            r.measured_to_cad = np.eye(4)
            r.points_cad = xyz
            return r

        saved = pipeline.register, registration.nominal_of, registration.pointset_of
        pipeline.register = fake_register
        registration.nominal_of = lambda obj: "nominal"
        registration.pointset_of = lambda obj: FakePointSet(np.reshape(obj.Coordinates, (-1, 3)))
        try:
            box = self.doc.addObject("Part::Feature", "Box")
            import Part
            box.Shape = Part.makeBox(1, 1, 1)
            xyz = rng.uniform(-0.05, 0.05, (40, 3))
            meas = objects.make_measurement(self.doc, FakePointSet(xyz))
            reg = objects.make_registration(self.doc, template, meas, box, seed=0)
            dmap = objects.make_deviation_map(self.doc, reg, 0.05)
            self.doc.recompute()
            self.assertEqual(calls, [])          # inputs unchanged: the stored result stands
            new_xyz = rng.uniform(-0.05, 0.05, (40, 3))
            objects.store_pointset(meas, FakePointSet(new_xyz))
            self.doc.recompute()
            self.assertEqual(calls, [0])
            np.testing.assert_allclose(dmap.Deviation, new_xyz[:, 2])
            from BladeInspect.core.colourmap import deviation_colours
            np.testing.assert_allclose(np.array(dmap.Color)[:, :3],
                                       deviation_colours(new_xyz[:, 2], 0.05),
                                       atol=0.5 / 255 + 1e-9)
            reg.Seed = 7
            self.doc.recompute()
            self.assertEqual(calls, [0, 7])
            self.doc.recompute()
            self.assertEqual(calls, [0, 7])
        finally:
            pipeline.register, registration.nominal_of, registration.pointset_of = saved


class TestDeviationMap(DocumentCase):
    def test_colours_follow_each_points_deviation_and_survive_reopen(self):
        from BladeInspect.core.colourmap import deviation_colours
        rng = np.random.default_rng(5)
        limit = 0.04
        dev = rng.uniform(-0.1, 0.1, 400)
        dev[:3] = (0.0, 0.5, -0.5)
        _, result = synthetic_result(rng, n=400, deviation=dev)
        obj = objects.make_deviation_map(self.doc, result, limit)
        name = obj.Name
        obj = self.reopen().getObject(name)
        colours = np.array(obj.Color)[:, :3]
        self.assertEqual(len(colours), 400)
        self.assertEqual(obj.Points.CountPoints, 400)
        # Colours are saved as 8 bits per channel. Within the limit (the tolerance here) the
        # ramp's; beyond it the out-of-tolerance classes' own colours.
        within = np.abs(dev) <= limit
        np.testing.assert_allclose(colours[within], deviation_colours(dev[within], limit),
                                   atol=0.5 / 255 + 1e-9)
        # The map's meaning, independent of its implementation: green at zero; beyond the
        # tolerance magenta above (red and blue, no green), near-black below, all alike.
        g0 = colours[0]
        self.assertGreater(g0[1], max(g0[0], g0[2]))
        self.assertGreater(min(colours[1][0], colours[1][2]), 0.9)
        self.assertLess(colours[1][1], 0.1)
        self.assertLess(max(colours[2]), 0.15)
        above, below = dev > limit, dev < -limit
        np.testing.assert_allclose(colours[above], np.tile(colours[1], (above.sum(), 1)))
        np.testing.assert_allclose(colours[below], np.tile(colours[2], (below.sum(), 1)))
        self.assertEqual(list(obj.OutOfTolerance), [int(below.sum()), int(above.sum())])
        shown = np.array([(v.x, v.y, v.z) for v in obj.Points.Points])
        np.testing.assert_allclose(shown, result.points_cad, atol=1e-4)
        self.assertAlmostEqual(obj.LegendValues[0], -limit)
        self.assertAlmostEqual(obj.LegendValues[-1], limit)
        # A new limit recolours: points between the old and new limit are back on the ramp.
        obj.Limit = 0.1
        self.doc.recompute()
        within = np.abs(dev) <= 0.1
        np.testing.assert_allclose(np.array(obj.Color)[within, :3],
                                   deviation_colours(dev[within], 0.1), atol=0.5 / 255 + 1e-9)
        self.assertEqual(list(obj.OutOfTolerance), [1, 1])
        # A tolerance of its own inside a wider ramp: the classes follow the tolerance.
        obj.Tolerance = 0.05
        self.doc.recompute()
        self.assertEqual(list(obj.OutOfTolerance),
                         [int(np.sum(dev < -0.05)), int(np.sum(dev > 0.05))])
        inside = np.abs(dev) <= 0.05
        np.testing.assert_allclose(np.array(obj.Color)[inside, :3],
                                   deviation_colours(dev[inside], 0.1), atol=0.5 / 255 + 1e-9)

    def test_an_error_leaves_no_half_built_objects(self):
        rng = np.random.default_rng(6)
        _, result = synthetic_result(rng, n=50)
        before = [o.Name for o in self.doc.Objects]
        with self.assertRaises(InputError):
            objects.make_deviation_map(self.doc, result, -1.0)   # makes a Registration first
        with self.assertRaises(InputError):
            objects.make_cad_model(self.doc, os.path.join(self.tmp, "missing.step"))
        with self.assertRaises(InputError):
            objects.make_measurement(self.doc, FakePointSet(np.zeros((5, 2))))
        self.assertEqual([o.Name for o in self.doc.Objects], before)


class TestProxyModules(DocumentCase):
    """A document names each proxy's module and class; FreeCAD imports them when it opens."""

    def _saved_with_module(self, module):
        """This document saved, every BladeInspect proxy recorded as ``module``'s (what a
        document made when one module held the six classes records), and reopened."""
        import re
        import zipfile
        path = os.path.join(self.tmp, "doc.FCStd")
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        older = os.path.join(self.tmp, "older.FCStd")
        recorded = []

        def rename(match):
            recorded.append(match.group(1))
            return 'module="%s" class=' % module
        with zipfile.ZipFile(path) as src, zipfile.ZipFile(older, "w") as dst:
            for item in src.infolist():
                data = src.read(item.filename)
                if item.filename == "Document.xml":
                    data = re.sub(r'module="(BladeInspect\.app\.objects[\w.]*)" class=',
                                  rename, data.decode()).encode()
                dst.writestr(item, data)
        self.doc = FreeCAD.openDocument(older)
        return recorded

    def test_documents_naming_app_objects_reopen_and_recompute(self):
        rng = np.random.default_rng(11)
        curves = TestReconstruction._curves(None, rng)
        blade = objects.make_demo_blade(self.doc)
        meas = objects.make_measurement(self.doc, FakePointSet(np.vstack(curves)))
        objects.make_reconstruction(self.doc, meas, FakeReconstruction(curves))
        _, result = synthetic_result(rng, n=36)
        reg = objects.make_registration(self.doc, result, meas, blade)
        objects.make_deviation_map(self.doc, reg, 0.05)
        brep = os.path.join(self.tmp, "box.brep")
        import Part
        Part.makeBox(1, 2, 3).exportBrep(brep)
        objects.make_cad_model(self.doc, brep)
        kinds = {type(o.Proxy) for o in self.doc.Objects if objects.proxy_type(o)}
        self.assertEqual(len(kinds), 6)
        blade_name, reg_name = blade.Name, reg.Name
        recorded = self._saved_with_module("BladeInspect.app.objects")
        # new documents name each class's own module
        self.assertEqual(set(recorded), {cls.__module__ for cls in kinds})
        for obj in self.doc.Objects:
            if objects.proxy_type(obj) is None:
                continue
            self.assertIn(type(obj.Proxy), kinds, obj.Name)
            self.assertIs(getattr(objects, type(obj.Proxy).__name__), type(obj.Proxy))
        self.doc.getObject(blade_name).touch()
        self.doc.recompute()
        self.assertEqual([o.Name for o in self.doc.Objects if "Invalid" in o.State], [])
        self.assertEqual(self.doc.getObject(reg_name).NPoints, 36)

    def test_proxies_store_no_state_of_their_own(self):
        for cls in (objects.DemoBlade, objects.CadModel, objects.Measurement,
                    objects.Reconstruction, objects.Registration, objects.DeviationMap):
            proxy = cls.__new__(cls)
            self.assertIsNone(proxy.dumps())
            self.assertIsNone(proxy.__getstate__())
            self.assertIsNone(proxy.loads(None))
            self.assertIsNone(proxy.__setstate__(None))


class TestDemoBlade(DocumentCase):
    def test_parameters_rebuild_the_blade_and_roles_are_kept(self):
        from BladeInspect.cad.demo_blade import BladeParams
        obj = objects.make_demo_blade(self.doc, BladeParams(span=60.0))
        self.assertTrue(obj.Shape.isValid())
        self.assertAlmostEqual(obj.Shape.BoundBox.ZLength, 60.0, delta=1e-6)
        roles = objects.roles_from_map(obj.FaceRoles)
        self.assertTrue(roles.get("suction") and roles.get("pressure"))
        for faces in roles.values():
            self.assertTrue(all(0 <= i < len(obj.Shape.Faces) for i in faces))
        obj.span = 45.0
        self.doc.recompute()
        self.assertAlmostEqual(obj.Shape.BoundBox.ZLength, 45.0, delta=1e-6)
        name = obj.Name
        obj = self.reopen().getObject(name)
        self.assertAlmostEqual(obj.Shape.BoundBox.ZLength, 45.0, delta=1e-6)
        self.assertEqual(objects.roles_from_map(obj.FaceRoles), roles)


class TestSettings(unittest.TestCase):
    """The preferences reach the code through FreeCAD's parameters; values are restored after."""

    def setUp(self):
        from BladeInspect.app import settings
        self.settings = settings
        self.group = FreeCAD.ParamGet(settings.PARAM_PATH)
        self.saved = {name: settings.value(name) for name in settings.SETTINGS}

    def tearDown(self):
        for name, value in self.saved.items():
            self.settings.store(name, value)

    def test_values_round_trip_through_freecads_parameters(self):
        s = self.settings
        s.store("StandoffMm", 50.5)
        s.store("Sections", 7)
        self.assertEqual(self.group.GetFloat("StandoffMm"), 50.5)
        self.assertEqual(self.group.GetInt("Sections"), 7)
        self.assertEqual(s.value("Sections"), 7)
        s.store("WorkingRangeMm", 6.0)
        s.store("SensorAccuracyMm", 0.004)
        sensor = s.sensor_model()
        self.assertEqual((sensor.standoff, sensor.half_range, sensor.accuracy),
                         (50.5, 6.0, 0.004))

    def test_colour_limit_falls_back_to_the_tolerance(self):
        s = self.settings
        s.store("ToleranceMm", 0.03)
        s.store("ColourLimitMm", 0.0)
        self.assertEqual(s.colour_limit(), 0.03)
        s.store("ColourLimitMm", 0.1)
        self.assertEqual(s.colour_limit(), 0.1)


class TestPackaging(unittest.TestCase):
    def test_package_xml_declares_the_workbench(self):
        ns = {"p": "https://wiki.freecad.org/Package_Metadata"}
        root = ET.parse(os.path.join(REPO, "package.xml")).getroot()
        self.assertEqual(root.get("format"), "1")
        self.assertEqual(root.find("p:name", ns).text, "BladeInspect")
        self.assertEqual(root.find("p:version", ns).text, "0.1.0")
        self.assertEqual(root.find("p:license", ns).text, "LGPL-2.1-or-later")
        wb = root.find("p:content/p:workbench", ns)
        self.assertEqual(wb.find("p:classname", ns).text, "BladeInspectWorkbench")
        self.assertEqual(wb.find("p:subdirectory", ns).text, "./")
        self.assertEqual(wb.find("p:freecadmin", ns).text, "0.20.0")
        deps = {d.text for d in wb.findall("p:depend", ns) if d.get("type") == "python"}
        self.assertEqual(deps, {"numpy", "scipy", "pyserial"})
        self.assertTrue(os.path.exists(os.path.join(REPO, root.find("p:icon", ns).text)))
        with open(os.path.join(REPO, "InitGui.py")) as fh:
            self.assertIn("class BladeInspectWorkbench", fh.read())

    def test_freecads_own_metadata_reader_accepts_package_xml(self):
        meta = FreeCAD.Metadata(os.path.join(REPO, "package.xml"))
        self.assertEqual((meta.Name, meta.Version), ("BladeInspect", "0.1.0"))
        self.assertEqual(meta.License[0]["name"], "LGPL-2.1-or-later")
        wb = meta.Content["workbench"][0]
        self.assertEqual((wb.Classname, wb.Subdirectory, wb.FreeCADMin),
                         ("BladeInspectWorkbench", "./", "0.20.0"))
        self.assertEqual([d["package"] for d in wb.Depend], ["numpy", "scipy", "pyserial"])

    def test_every_command_has_a_valid_svg_icon(self):
        for verb in COMMAND_VERBS + ("",):
            name = "BladeInspect_" + verb if verb else "BladeInspect"
            path = os.path.join(REPO, "resources", "icons", name + ".svg")
            root = ET.parse(path).getroot()
            self.assertTrue(root.tag.endswith("svg"), path)

    def test_init_registers_the_test_module_which_finds_the_tests(self):
        registered = FreeCAD.__unit_test__
        FreeCAD.__unit_test__ = []
        try:
            exec(open(os.path.join(REPO, "Init.py")).read(), {})
            self.assertEqual(FreeCAD.__unit_test__, ["TestBladeInspect"])
        finally:
            FreeCAD.__unit_test__ = registered
        import TestBladeInspect
        suite = unittest.TestLoader().loadTestsFromModule(TestBladeInspect)
        ids = set()
        stack = [suite]
        while stack:
            s = stack.pop()
            for t in s:
                (stack.append(t) if isinstance(t, unittest.TestSuite) else ids.add(t.id()))
        self.assertIn("tests.test_app_objects.TestPackaging."
                      "test_init_registers_the_test_module_which_finds_the_tests", ids)

    def test_install_script_links_the_repository_into_the_mod_folder(self):
        tmp = tempfile.mkdtemp(prefix="bi-mod-")
        try:
            env = dict(os.environ, FREECAD_USER_MOD=os.path.join(tmp, "Mod"))
            script = os.path.join(REPO, "scripts", "install-workbench.sh")
            subprocess.run([script], env=env, check=True, capture_output=True)
            subprocess.run([script], env=env, check=True, capture_output=True)  # idempotent
            link = os.path.join(tmp, "Mod", "BladeInspect")
            self.assertEqual(os.path.realpath(link), os.path.realpath(REPO))
            self.assertTrue(os.path.exists(os.path.join(link, "InitGui.py")))
        finally:
            shutil.rmtree(tmp)

    def test_app_layer_never_imports_the_gui(self):
        app_dir = os.path.join(REPO, "BladeInspect", "app")
        for folder, _, files in os.walk(app_dir):
            for name in files:
                if name.endswith(".py"):
                    with open(os.path.join(folder, name)) as fh:
                        text = fh.read()
                    for banned in ("import FreeCADGui", "from PySide", "import PySide",
                                   "pivy"):
                        self.assertNotIn(banned, text, name)

    def test_the_app_and_gui_modules_import_one_another_without_a_circle(self):
        """Every import between app/ and gui/ modules, at module level or in a function,
        read from the source: following them never comes back to where it started."""
        import ast
        from tests import test_layers
        modules = {m: p for m, p in test_layers._modules(REPO)
                   if m.split(".")[1:2] in (["app"], ["gui"])}
        graph = {}
        for module, path in modules.items():
            with open(path, encoding="utf-8") as fh:
                tree = ast.parse(fh.read(), path)
            graph[module] = set()
            for _, name in test_layers._imported(module, path, tree):
                parts = name.split(".")
                while parts and ".".join(parts) not in modules:
                    parts.pop()
                if parts and ".".join(parts) != module:
                    graph[module].add(".".join(parts))
        done, path = set(), []

        def visit(module):
            if module in path:
                self.fail("import circle: " + " -> ".join(path[path.index(module):] + [module]))
            if module in done:
                return
            path.append(module)
            for imported in sorted(graph[module]):
                visit(imported)
            path.pop()
            done.add(module)
        for module in sorted(graph):
            visit(module)


if __name__ == "__main__":
    unittest.main()
