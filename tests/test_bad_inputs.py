"""Inputs a user brings that no registration can trust (issue 13, item 3): each ends with one
line `bladeinspect: error: <file>: <problem>`, exit status 2 and nothing in --out; and a pose
direction the points do not measure is named, not given an absurd uncertainty.

Truths are independent of the code: the factor a scan was scaled by, the direction of the line
or plane the points were put on, another blade's geometry, the axis of a prism."""
import contextlib
import io
import json
import os
import re
import shutil
import tempfile
import unittest
from types import SimpleNamespace

import numpy as np

from tests.helpers import demo_nominal

SENSOR_ACCURACY_MM = 0.006   # docs/contracts.md: the ConoProbe's accuracy, uniform error on +-0.006


def run_main(*args):
    from BladeInspect import cli
    err, out = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        status = cli.main(list(args))
    return status, out.getvalue(), err.getvalue()


def write_csv(path, xyz, snr=None):
    header = "x,y,z" + (",snr" if snr is not None else "")
    cols = [xyz] if snr is None else [xyz, np.asarray(snr)[:, None]]
    np.savetxt(path, np.hstack(cols), delimiter=",", header=header, comments="", fmt="%.9g")
    return path


def prism_shape(span):
    """An extruded closed B-spline profile with no symmetry (so the pose across the span is
    unique) and planar caps: a prismatic part whose axis is +Z."""
    import FreeCAD
    import Part
    theta = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    r = 10.0 + 3.0 * np.cos(theta) + 1.5 * np.sin(2 * theta)
    curve = Part.BSplineCurve()
    curve.interpolate([FreeCAD.Vector(2.2 * a * np.cos(t), a * np.sin(t), 0.0)
                       for a, t in zip(r, theta)], PeriodicFlag=True)
    face = Part.Face(Part.Wire(curve.toShape()))
    return face.extrude(FreeCAD.Vector(0.0, 0.0, span)), curve


class BadInputCase(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import FreeCAD  # noqa: F401  (FreeCAD before Part)
        from BladeInspect.cad.demo_blade import make_demo_blade
        from BladeInspect.inspection.simulate import simulate_measurement
        cls.tmp = tempfile.mkdtemp(prefix="bladeinspect-bad-")
        cls.cad = os.path.join(cls.tmp, "blade.step")
        make_demo_blade().shape.exportStep(cls.cad)
        cls.scan, cls.truth, _, _ = simulate_measurement(
            demo_nominal(), n_points=800, seed=13, outlier_fraction=0.02, section_heights=())
        cls.points = write_csv(os.path.join(cls.tmp, "scan.csv"), cls.scan.xyz, cls.scan.snr)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def out_dir(self):
        return tempfile.mkdtemp(prefix="out-", dir=self.tmp)

    def assert_refused(self, points, *words, cad=None, out=None, command="register"):
        out = out or os.path.join(self.out_dir(), "result")
        status, _, err = run_main(command, "--cad", cad or self.cad, "--points", points,
                                  "--out", out)
        self.assertEqual(status, 2, err)
        lines = [l for l in err.splitlines() if l.startswith("bladeinspect: error:")]
        self.assertEqual(len(lines), 1, err)
        self.assertNotIn("Traceback", err)
        line = lines[0]
        self.assertTrue(line.startswith("bladeinspect: error: %s: " % points), line)
        for w in words:
            self.assertIn(w, line)
        if os.path.isdir(out):
            self.assertEqual(os.listdir(out), [])
        self.assertEqual([n for n in os.listdir(os.path.dirname(out))
                          if n.startswith(".bladeinspect-")], [])
        return line


class TestRefusedFiles(BadInputCase):
    def points_with_row(self, name, at, row):
        """The good scan's file with one more line inserted before line ``at``."""
        rows = open(self.points).read().splitlines()
        rows.insert(at, row)
        path = os.path.join(self.tmp, name)
        with open(path, "w") as fh:
            fh.write("\n".join(rows) + "\n")
        return path

    def test_a_huge_coordinate_is_refused_naming_its_row(self):
        self.assert_refused(self.points_with_row("huge.csv", 4, "1e300,1,2,50"),
                            "data row 4", "1e+300", "not a measurement in millimetres")

    def test_an_infinite_coordinate_is_refused_naming_its_row(self):
        self.assert_refused(self.points_with_row("infinite.csv", 6, "3,inf,2,50"),
                            "data row 6", "y is inf", "not a measurement")

    def test_a_huge_coordinate_is_refused_by_report_too(self):
        xyz = self.scan.xyz.copy()
        xyz[7, 1] = -3e250
        path = write_csv(os.path.join(self.tmp, "huge_report.csv"), xyz)
        self.assert_refused(path, "-3e+250", command="report")

    def test_a_scan_in_another_unit_is_named_with_its_factor(self):
        for unit, factor in (("metres", 1e-3), ("inches", 1 / 25.4), ("micrometres", 1e3)):
            path = write_csv(os.path.join(self.tmp, "in_%s.csv" % unit), self.scan.xyz * factor)
            line = self.assert_refused(path, "looks like %s" % unit, "extent ratio")
            ratio = float(re.search(r"extent ratio ([0-9.e+-]+)", line).group(1))
            # The scan covers the whole blade, so its extent is the CAD's within a tenth.
            self.assertLess(abs(np.log(ratio / factor)), np.log(1.1), line)

    def test_copies_of_one_point(self):
        path = write_csv(os.path.join(self.tmp, "one.csv"), np.tile([[3.0, -2.0, 40.0]],
                                                                    (500, 1)))
        self.assert_refused(path, "coincide", "rotation about every axis")

    def test_points_on_a_line_name_the_line(self):
        direction = np.array([1.0, 2.0, -1.0]) / np.sqrt(6.0)
        xyz = np.linspace(0.0, 60.0, 500)[:, None] * direction + [5.0, 1.0, 10.0]
        path = write_csv(os.path.join(self.tmp, "line.csv"), xyz)
        line = self.assert_refused(path, "straight line", "rotation about that line")
        found = np.array([float(v) for v in re.search(r"along \(([^)]*)\)", line)
                          .group(1).split(",")])
        self.assertGreater(abs(found @ direction), 0.999, line)

    def test_points_on_a_plane_name_its_normal(self):
        rng = np.random.default_rng(3)
        normal = np.array([0.0, 0.6, 0.8])
        a = np.array([1.0, 0.0, 0.0])
        b = np.cross(normal, a)
        # A flat patch as the sensor measures it: its noise across the plane.
        xyz = (rng.uniform(-25, 25, (500, 1)) * a + rng.uniform(-10, 10, (500, 1)) * b
               + rng.uniform(-SENSOR_ACCURACY_MM, SENSOR_ACCURACY_MM, (500, 1)) * normal
               + [0.0, 3.0, 30.0])
        path = write_csv(os.path.join(self.tmp, "plane.csv"), xyz)
        line = self.assert_refused(path, "one plane", "translation along that normal")
        found = np.array([float(v) for v in re.search(r"normal \(([^)]*)\)", line)
                          .group(1).split(",")])
        self.assertGreater(abs(found @ normal), 0.999, line)

    def test_out_an_existing_file(self):
        out = os.path.join(self.tmp, "taken.txt")
        with open(out, "w") as fh:
            fh.write("keep me\n")
        for command in ("register", "report"):
            status, _, err = run_main(command, "--cad", self.cad, "--points", self.points,
                                      "--out", out)
            self.assertEqual(status, 2, err)
            self.assertNotIn("Traceback", err)
            self.assertEqual(err.strip().splitlines(),
                             ["bladeinspect: error: %s: --out is an existing file, not a "
                              "folder" % out])
            with open(out) as fh:
                self.assertEqual(fh.read(), "keep me\n")


class TestAnotherBlade(BadInputCase):
    """Another blade's scan (more twist and camber, a shorter chord: its own CAD) against the
    demo blade's CAD."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        from BladeInspect.cad.demo_blade import BladeParams, make_demo_blade
        from BladeInspect.cad.nominal import nominal_from_shape
        from BladeInspect.inspection.simulate import simulate_measurement
        other = make_demo_blade(BladeParams(twist_deg=40.0, camber_root=0.11, chord_root=46.0))
        cls.other_nominal = nominal_from_shape(other.shape, roles=other.roles)
        scan, _, _, _ = simulate_measurement(cls.other_nominal, n_points=300, seed=4,
                                             section_heights=())
        cls.other = write_csv(os.path.join(cls.tmp, "other_blade.csv"), scan.xyz, scan.snr)

    def test_refused_naming_both_files(self):
        line = self.assert_refused(self.other, "does not fit %s" % self.cad, "--allow-mismatch")
        fraction = float(re.search(r"only ([0-9.]+) %", line).group(1)) / 100
        self.assertLess(fraction, 0.5)

    def test_allow_mismatch_writes_the_result_with_the_warning(self):
        out = os.path.join(self.out_dir(), "kept")
        status, stdout, err = run_main("register", "--cad", self.cad, "--points", self.other,
                                       "--out", out, "--allow-mismatch")
        self.assertEqual(status, 0, err)
        with open(os.path.join(out, "result.json")) as fh:
            result = json.load(fh)
        self.assertFalse(result["surface_fit"]["fits"])
        self.assertIn("does not fit", result["surface_fit"]["warning"])
        self.assertIn(result["surface_fit"]["warning"], result["warnings"])
        self.assertIn("does not fit", stdout)
        # The recorded fraction is the deviations' own, recounted here from deviations.csv.
        dev = np.loadtxt(os.path.join(out, "deviations.csv"), delimiter=",", skiprows=1,
                         usecols=3)
        distance = result["surface_fit"]["distance_mm"]
        self.assertAlmostEqual(result["surface_fit"]["fraction_within"],
                               np.mean(np.abs(dev) <= distance), places=3)

    def test_report_refuses_it(self):
        self.assert_refused(self.other, "does not fit %s" % self.cad, command="report")

    def test_the_right_scan_fits(self):
        out = os.path.join(self.out_dir(), "good")
        status, _, err = run_main("register", "--cad", self.cad, "--points", self.points,
                                  "--out", out)
        self.assertEqual(status, 0, err)
        with open(os.path.join(out, "result.json")) as fh:
            result = json.load(fh)
        # 2 % gross outliers, the rest within the sensor's accuracy of the surface.
        self.assertGreater(result["surface_fit"]["fraction_within"], 0.95)
        self.assertEqual(result["pose_unmeasured"], [])


class TestTimeLimit(unittest.TestCase):
    def test_a_spent_budget_ends_the_fine_stage_with_a_message(self):
        from BladeInspect.core.errors import InputError
        from BladeInspect.inspection import pipeline
        from BladeInspect.inspection.simulate import simulate_measurement
        scan, truth, _, _ = simulate_measurement(demo_nominal(), n_points=300, seed=2,
                                                 section_heights=())
        with self.assertRaises(InputError) as ctx:
            pipeline.fine_register(scan.xyz, scan.snr, demo_nominal(), truth,
                                   time_limit_s=0.0)
        self.assertIn("time limit", str(ctx.exception))


    def test_a_spent_budget_ends_the_coarse_stage_with_a_message(self):
        from unittest import mock
        from BladeInspect.core.errors import InputError
        from BladeInspect.inspection import pipeline
        from BladeInspect.inspection.simulate import simulate_measurement
        scan, _, _, _ = simulate_measurement(demo_nominal(), n_points=300, seed=2,
                                             section_heights=())
        with mock.patch.object(pipeline, "COARSE_TIME_LIMIT_S", 0.0), \
                self.assertRaises(InputError) as ctx:
            pipeline.register(demo_nominal(), scan)
        self.assertIn("coarse registration: stopped at its 0 s time limit", str(ctx.exception))

    def test_icp_stops_at_its_time_limit(self):
        from BladeInspect.core import icp
        from BladeInspect.inspection.closest_fn import exact_closest_fn
        from BladeInspect.inspection.simulate import simulate_measurement
        scan, truth, _, _ = simulate_measurement(demo_nominal(), n_points=300, seed=2,
                                                 section_heights=())
        fit = icp.icp(scan.xyz, scan.snr, exact_closest_fn(demo_nominal()), truth,
                      icp.ICPOptions(time_limit_s=0.0))
        self.assertEqual((fit.stopped, fit.iterations, fit.converged), ("time limit", 0, False))


class TestUnmeasuredDirections(unittest.TestCase):
    """core.icp.split_information on Fisher informations whose null directions are known in
    closed form: points on a cylinder (any cross-section) slide along its axis; on a circular
    one they also turn about it."""

    @staticmethod
    def information(points, normals, center):
        from BladeInspect.core import icp
        J = np.hstack([normals, np.cross(points - center, normals)])
        return J.T @ J, icp

    def cylinder(self, ax, ay, n=600, seed=0):
        rng = np.random.default_rng(seed)
        t = rng.uniform(0, 2 * np.pi, n)
        z = rng.choice([10.0, 40.0, 70.0], n)
        points = np.c_[ax * np.cos(t), ay * np.sin(t), z]
        normals = np.c_[np.cos(t) / ax, np.sin(t) / ay, np.zeros(n)]
        normals /= np.linalg.norm(normals, axis=1)[:, None]
        return points, normals

    def test_an_elliptic_prism_leaves_only_the_axial_position(self):
        points, normals = self.cylinder(20.0, 9.0)
        center = points.mean(axis=0)
        H, icp = self.information(points, normals, center)
        split = icp.split_information(H, 1e-5, 80.0, len(points))
        self.assertEqual(split.unmeasured.shape[1], 1)
        np.testing.assert_allclose(abs(split.unmeasured[:, 0]), [0, 0, 1, 0, 0, 0], atol=1e-9)
        # The covariance of the other five is the inverse of the information restricted to
        # them (an independent computation: drop the axial coordinate and invert).
        keep = [0, 1, 3, 4, 5]
        expected = 1e-5 * np.linalg.inv(H[np.ix_(keep, keep)])
        np.testing.assert_allclose(split.covariance[np.ix_(keep, keep)], expected,
                                   rtol=1e-8, atol=1e-18)
        np.testing.assert_allclose(split.covariance[2], 0.0, atol=1e-18)
        self.assertTrue(np.isinf(icp.pose_covariance(points, normals, np.ones(len(points)),
                                                     np.zeros(len(points)), center)).all())

    def test_a_circular_cylinder_also_turns_about_its_axis(self):
        points, normals = self.cylinder(15.0, 15.0, seed=1)
        center = points[:200].mean(axis=0)       # off the axis: the turn carries a shift
        H, icp = self.information(points, normals, center)
        length = 80.0
        split = icp.split_information(H, 1e-5, length, len(points))
        self.assertEqual(split.unmeasured.shape[1], 2)
        # A turn w about the Z axis through the origin is, about c, the shift w x c with it.
        turn = np.r_[np.cross([0, 0, 1.0], center), 0, 0, length]
        for motion in (np.r_[0, 0, 1.0, 0, 0, 0], turn / np.linalg.norm(turn)):
            self.assertAlmostEqual(np.linalg.norm(split.unmeasured.T @ motion), 1.0, places=9)

    def test_a_full_rank_information_is_inverted_as_it_is(self):
        rng = np.random.default_rng(4)
        u = rng.normal(size=(400, 3))
        u /= np.linalg.norm(u, axis=1)[:, None]
        points = u * [30.0, 12.0, 5.0]
        normals = u / [30.0, 12.0, 5.0]
        normals /= np.linalg.norm(normals, axis=1)[:, None]
        H, icp = self.information(points, normals, points.mean(axis=0))
        split = icp.split_information(H, 2e-5, 60.0, len(points))
        self.assertTrue(split.complete)
        np.testing.assert_allclose(split.covariance, 2e-5 * np.linalg.inv(H), rtol=1e-9)

    def test_words_for_a_prism(self):
        from BladeInspect.inspection.checks import describe_unmeasured
        points, normals = self.cylinder(20.0, 9.0)
        H, icp = self.information(points, normals, points.mean(axis=0))
        split = icp.split_information(H, 1e-5, 80.0, len(points))
        # A stand-in nominal: samples of the prism's side (with their normals, as a
        # nominal's), span along Z.
        samples = SimpleNamespace(xyz=points, weight=np.ones(len(points)),
                                  face=np.zeros(len(points), int), normal=normals)
        words = describe_unmeasured(split, SimpleNamespace(samples=samples, roles={}))
        self.assertEqual([w["motion"] for w in words],
                         ["position along the span is not measured"])
        # A circular one turns about its axis as well, whose line is off the centre here.
        points, normals = self.cylinder(15.0, 15.0, seed=1)
        H, icp = self.information(points, normals, points[:200].mean(axis=0))
        split = icp.split_information(H, 1e-5, 80.0, len(points))
        samples = SimpleNamespace(xyz=points, weight=np.ones(len(points)),
                                  face=np.zeros(len(points), int), normal=normals)
        words = describe_unmeasured(split, SimpleNamespace(samples=samples, roles={}))
        self.assertEqual([w["motion"] for w in words],
                         ["position along the span is not measured",
                          "rotation about the span axis is not measured"])
        for w in words:
            self.assertGreater(abs(w["direction"][2]), 0.999)


class TestPrismSectionsThroughTheCommandLine(unittest.TestCase):
    """Sections scanned across a prism: the span position is free, the rest is measured."""

    def test_span_position_named_and_the_rest_measured(self):
        import FreeCAD  # noqa: F401
        from BladeInspect.core import transforms as tf
        tmp = tempfile.mkdtemp(prefix="bladeinspect-prism-")
        self.addCleanup(shutil.rmtree, tmp, True)
        span = 100.0
        shape, curve = prism_shape(span)
        cad = os.path.join(tmp, "prism.brep")
        shape.exportBrep(cad)
        rng = np.random.default_rng(5)
        u = np.linspace(curve.FirstParameter, curve.LastParameter, 300, endpoint=False)
        p = np.array([[curve.value(x).x, curve.value(x).y] for x in u])
        t = np.array([[curve.tangent(x)[0].x, curve.tangent(x)[0].y] for x in u])
        n = np.c_[t[:, 1], -t[:, 0]] / np.linalg.norm(t, axis=1)[:, None]
        xyz = []
        for z in (15.0, 40.0, 85.0):
            e = rng.uniform(-SENSOR_ACCURACY_MM, SENSOR_ACCURACY_MM, len(p))
            xyz.append(np.c_[p + e[:, None] * n, np.full(len(p), z)])
        xyz = np.vstack(xyz)
        move = tf.random_transform(rng, 40.0)
        points = write_csv(os.path.join(tmp, "sections.csv"), tf.apply_transform(move, xyz))
        out = os.path.join(tmp, "out")
        status, stdout, err = run_main("register", "--cad", cad, "--points", points,
                                       "--out", out)
        self.assertEqual(status, 0, err)
        self.assertIn("position along the span is not measured", stdout)
        with open(os.path.join(out, "result.json")) as fh:
            result = json.load(fh)
        self.assertEqual(len(result["pose_unmeasured"]), 1)
        free = result["pose_unmeasured"][0]
        self.assertEqual(free["motion"], "position along the span is not measured")
        self.assertGreater(abs(free["direction"][2]), 0.999)
        # Measured directions: the pose error across the span, with the free axial shift
        # taken out, against the truth and against an absolute bound from the noise alone.
        delta = np.array(result["measured_to_cad"]) @ move
        corners = np.array([[x, y, z] for x in (-30, 30) for y in (-15, 15) for z in (0, span)])
        moved = tf.apply_transform(delta, corners) - corners
        moved[:, 2] -= delta[2, 3]
        err_mm = np.linalg.norm(moved, axis=1).max()
        sigma = result["pose_uncertainty_mm"]
        self.assertTrue(np.isfinite(sigma))
        self.assertLess(sigma, 0.01)
        self.assertLess(err_mm, 4 * sigma)
        # Deviations are reported: the injected noise, uniform +-accuracy.
        self.assertAlmostEqual(result["deviation"]["rms"], SENSOR_ACCURACY_MM / np.sqrt(3),
                               delta=0.0005)


if __name__ == "__main__":
    unittest.main()
