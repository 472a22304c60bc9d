"""The fit with a uniform normal offset (core.fits, --fit least-squares-size) and the plain
fit's take-up of a size error, against independent truths:

- a hemisphere: the linearised take-up of a unit offset by a translation is the closed form
  (E[n n^T])^-1 E[n] = 1.5 along the axis (E[n_z] = 1/2, E[n_z^2] = 1/3 over the area), no
  rotation; the size fit of an offset, moved cap on an exact sphere recovers the motion and
  the offset;
- the demo blade's CAD: its sampled points moved out by delta along their exact normals
  (their distance to the CAD is then delta, checked) and carried by a known rigid transform:
  the size fit recovers the transform and s = delta; the plain fit's pose moves by -delta r,
  r the linearised take-up;
- the `airfoil` command end to end with --fit least-squares-size on such a scan: the pose,
  the size and the thickness and chord deviations of an offset profile (2 delta: both sides,
  both ends moved out by delta).
"""
import contextlib
import io
import json
import os
import shutil
import tempfile
import types
import unittest

import numpy as np

from BladeInspect.core import fits
from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import InputError
from tests.helpers import demo_nominal

UM = 1e-3   # mm


def hemisphere(radius, n_theta=120, n_phi=240):
    """Midpoint-rule points of the cap z >= 0 of a sphere about the origin, their outward
    normals and area weights."""
    theta = (np.arange(n_theta) + 0.5) * (0.5 * np.pi / n_theta)
    phi = (np.arange(n_phi) + 0.5) * (2.0 * np.pi / n_phi)
    T, P = np.meshgrid(theta, phi, indexing="ij")
    n = np.column_stack([(np.sin(T) * np.cos(P)).ravel(), (np.sin(T) * np.sin(P)).ravel(),
                         np.cos(T).ravel()])
    return radius * n, n, np.sin(T).ravel()


def sphere_closest(radius):
    def closest(points):
        norm = np.linalg.norm(points, axis=1)
        n = points / norm[:, None]
        return radius * n, n, norm - radius
    return closest


def rotation_angle(T):
    """The angle of T's rotation (rad), from the skew part (accurate at small angles)."""
    R = T[:3, :3]
    return float(0.5 * np.linalg.norm([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]))


def near_start(rng, truth, angle=2e-3, shift=0.05):
    """A start pose off ``truth`` by about ``angle`` rad and ``shift`` mm."""
    return tf.make_transform(tf.rotation_from_vector(rng.normal(0.0, angle, 3)),
                             rng.normal(0.0, shift, 3)) @ truth


class Hemisphere(unittest.TestCase):
    def test_take_up_of_a_cap_is_one_and_a_half_along_its_axis(self):
        p, n, w = hemisphere(20.0)
        r = fits.size_take_up(p, n, w, np.zeros(3))
        np.testing.assert_allclose(r[:3], [0.0, 0.0, 1.5], atol=2e-4)
        np.testing.assert_allclose(r[3:], 0.0, atol=1e-9)
        # with only the axial translation free the same; with only a sideways one, none
        r = fits.size_take_up(p, n, w, np.zeros(3), fits.parse_free("tx"))
        np.testing.assert_allclose(r, 0.0, atol=1e-9)

    def test_size_fit_recovers_centre_and_offset_and_the_plain_fit_takes_it_up(self):
        # A sphere turned about its centre is the same sphere: only the centre's motion is
        # determined, and it is what is checked.
        rng = np.random.default_rng(3)
        radius = 20.0
        p, n, w = hemisphere(radius, 40, 80)
        closest = sphere_closest(radius)
        origin = np.zeros((1, 3))
        for delta in (0.03, -0.02):
            truth = tf.random_transform(rng, 5.0)
            measured = tf.apply_transform(tf.invert_transform(truth), p + delta * n)
            fit = fits.least_squares_fit(measured, closest, near_start(rng, truth), w,
                                         size=True)
            self.assertTrue(fit.converged)
            self.assertEqual(fit.objective, fits.SIZE_OBJECTIVE)
            self.assertAlmostEqual(fit.size, delta, delta=1e-9)
            G = fit.transform @ tf.invert_transform(truth)
            self.assertLess(np.abs(tf.apply_transform(G, origin)).max(), 1e-6)
            plain = fits.least_squares_fit(measured, closest, near_start(rng, truth), w)
            G = plain.transform @ tf.invert_transform(truth)
            # the cap slides down its axis by 1.5 delta (to first order; the start's tilt of
            # the axis, 2e-3 rad, and delta / R are the rest)
            np.testing.assert_allclose(tf.apply_transform(G, origin)[0],
                                       [0.0, 0.0, -1.5 * delta], atol=0.02 * abs(delta))


class DemoBlade(unittest.TestCase):
    """Points on the demo blade's suction and pressure faces, moved out along the CAD's exact
    normals: a part uniformly oversize (or undersize) by delta."""

    @classmethod
    def setUpClass(cls):
        from BladeInspect.inspection.closest_fn import exact_closest_fn
        cls.nominal = demo_nominal()
        cls.closest = staticmethod(exact_closest_fn(cls.nominal))
        rng = np.random.default_rng(11)
        faces = cls.nominal.roles["suction"] + cls.nominal.roles["pressure"]
        on_sides = np.flatnonzero(np.isin(cls.nominal.samples.face, faces))
        idx = rng.choice(on_sides, 3000, replace=False)
        cls.q, cls.n = cls.nominal.samples.xyz[idx], cls.nominal.samples.normal[idx]

    def offset(self, delta):
        cad = self.q + delta * self.n
        # the independent check that the offset is one: every point lies delta off the CAD
        np.testing.assert_allclose(self.nominal.signed_distance(cad).distance, delta,
                                   atol=1e-9)
        return cad

    def test_size_fit_recovers_pose_and_size(self):
        rng = np.random.default_rng(12)
        w = np.ones(len(self.q))
        for delta in (0.04, -0.02, 0.0):
            truth = tf.random_transform(rng, 10.0)
            measured = tf.apply_transform(tf.invert_transform(truth), self.offset(delta))
            fit = fits.fit(fits.SIZE_OBJECTIVE, measured, self.closest,
                           near_start(rng, truth), w)
            self.assertTrue(fit.converged)
            self.assertAlmostEqual(fit.size, delta, delta=1e-6)
            G = fit.transform @ tf.invert_transform(truth)
            self.assertLess(np.abs(tf.apply_transform(G, self.q) - self.q).max(), 1e-4)
            self.assertLess(rotation_angle(G), 1e-6)
            self.assertLess(fit.max_abs_deviation - abs(delta), 1e-6)
            doc = fit.to_json()
            self.assertAlmostEqual(doc["size_mm"], delta, delta=1e-6)
            self.assertEqual(np.asarray(fit.covariance).shape, (6, 6))

    def test_the_plain_fit_moves_by_the_linearised_take_up(self):
        rng = np.random.default_rng(13)
        w = np.ones(len(self.q))
        delta = 0.002
        truth = tf.random_transform(rng, 10.0)
        measured = tf.apply_transform(tf.invert_transform(truth), self.offset(delta))
        plain = fits.least_squares_fit(measured, self.closest, near_start(rng, truth), w)
        self.assertTrue(plain.converged)
        moved = tf.apply_transform(plain.transform @ tf.invert_transform(truth), self.q) - self.q
        c = self.q.mean(axis=0)
        r = fits.size_take_up(self.q, self.n, w, c)
        predicted = -delta * (r[:3] + np.cross(r[3:], self.q - c))
        largest = np.abs(predicted).max()
        # a twisted blade: the take-up is a screw along the span, far larger than delta
        self.assertGreater(largest, 5.0 * delta)
        self.assertLess(np.abs(moved - predicted).max(), 0.01 * largest)

    def test_noise_gives_a_size_sigma_that_covers_its_scatter(self):
        rng = np.random.default_rng(14)
        w = np.ones(len(self.q))
        sigma, delta, sizes, sigmas = 0.002, 0.01, [], []
        truth = tf.random_transform(rng, 10.0)
        for _ in range(8):
            cad = self.q + (delta + rng.normal(0.0, sigma, len(self.q)))[:, None] * self.n
            measured = tf.apply_transform(tf.invert_transform(truth), cad)
            fit = fits.least_squares_fit(measured, self.closest, near_start(rng, truth), w,
                                         size=True)
            sizes.append(fit.size)
            sigmas.append(np.sqrt(fit.size_variance))
        # sigma of a weighted mean of n equal readings is sigma / sqrt(n) when s is
        # uncorrelated with the pose; correlation with the pose only makes it larger
        self.assertGreater(np.mean(sigmas), 0.9 * sigma / np.sqrt(len(self.q)))
        self.assertLess(np.mean(sigmas), 10.0 * sigma / np.sqrt(len(self.q)))
        self.assertLess(np.abs(np.array(sizes) - delta).max(), 4.0 * np.mean(sigmas))


class ApplyToAResult(unittest.TestCase):
    """inspection.fitting.apply on a registration result of an oversize part whose pose is off
    by a known motion: the result moved to the true pose, the size deviation and its U, the
    stated pose uncertainty the size fit's, and the size fit among the sensitivity's fits."""

    def result(self, delta, motion):
        from BladeInspect.core import stats
        from BladeInspect.inspection.result import RegistrationResult
        nominal = demo_nominal()
        rng = np.random.default_rng(21)
        faces = nominal.roles["suction"] + nominal.roles["pressure"]
        idx = rng.choice(np.flatnonzero(np.isin(nominal.samples.face, faces)), 3000,
                         replace=False)
        q, n = nominal.samples.xyz[idx], nominal.samples.normal[idx]
        xyz = tf.apply_transform(motion, q + delta * n)
        dist = nominal.signed_distance(xyz)
        result = RegistrationResult(
            measured_to_cad=motion, points_cad=xyz, deviation=dist.distance,
            inlier=np.ones(len(xyz), bool), closest=dist.closest, normal=dist.normal,
            face=dist.face, snr=None, columns={}, n_rows_skipped=0, rms_mm=0.0,
            pose_covariance=np.zeros((6, 6)), center=xyz.mean(axis=0),
            pose_uncertainty_mm=0.0, deviation_stats=stats.deviation_statistics(dist.distance),
            coarse={})
        return nominal, result, q

    def test_size_fit_moves_the_result_and_records_the_size(self):
        from BladeInspect.core import icp
        from BladeInspect.inspection import fitting
        from BladeInspect.rig.sensor import SensorModel
        delta = 0.03
        motion = tf.make_transform(tf.rotation_from_vector([2e-3, -1e-3, 3e-3]),
                                   [0.05, -0.02, 0.1])
        nominal, result, q = self.result(delta, motion)
        runs = fitting.apply(result, nominal, fitting.FitChoice(objective=fits.SIZE_OBJECTIVE),
                             0.04, all_objectives=True)
        self.assertEqual(set(runs.runs), set(fits.OBJECTIVES) | {fits.SIZE_OBJECTIVE})
        # the measured points are q + delta n in the CAD's own frame, which the start pose
        # ``motion`` moved off: the fitted pose is the identity
        pose = np.asarray(result.measured_to_cad)
        self.assertLess(np.abs(tf.apply_transform(pose, q) - q).max(), 1e-4)
        size = result.fit["size_deviation"]
        self.assertAlmostEqual(size["value_mm"], delta, delta=1e-6)
        accuracy = SensorModel().accuracy
        self.assertAlmostEqual(size["U_mm"], 2.0 * np.sqrt(size["u_statistical_mm"] ** 2
                                                           + accuracy ** 2 / 3.0), delta=1e-12)
        np.testing.assert_allclose(result.deviation, delta, atol=1e-6)
        self.assertAlmostEqual(result.pose_uncertainty_mm, icp.pose_uncertainty(
            np.asarray(result.fit["covariance"]), result.center, nominal.bbox_corners))
        self.assertNotIn("size_take_up", result.fit)

    def test_plain_fit_records_its_take_up(self):
        from BladeInspect.inspection import fitting
        nominal, result, q = self.result(0.01, np.eye(4))
        fitting.apply(result, nominal, fitting.FitChoice(), 0.04)
        take_up = result.fit["size_take_up"]
        self.assertNotIn("size_deviation", result.fit)
        self.assertIn("0.020 mm of size would move the pose by up to %.3f mm"
                      % (0.02 * take_up["pose_motion_mm_per_mm"]), take_up["note"])


class Choices(unittest.TestCase):
    def test_every_command_offers_the_size_fit(self):
        from BladeInspect import cli
        from BladeInspect.inspection import fitting
        self.assertIn(fits.SIZE_OBJECTIVE, fitting.OBJECTIVE_NAMES)
        parser = cli.build_parser()
        for argv in (["report", "--cad", "c", "--points", "p", "--out", "o"],
                     ["register", "--cad", "c", "--points", "p", "--out", "o"],
                     ["batch", "--cad", "c", "--scans", "s", "--out", "o"],
                     ["inspect", "--out", "o"], ["airfoil", "--out", "o"]):
            args = parser.parse_args(argv + ["--fit", fits.SIZE_OBJECTIVE])
            self.assertEqual(fitting.from_args(args).objective, fits.SIZE_OBJECTIVE)
        choice = fitting.FitChoice(objective=fits.SIZE_OBJECTIVE, weights_by_zone="LE=2")
        self.assertEqual(choice.zone_weights(), {"LE": 2.0})
        with self.assertRaises(InputError):
            fits.fit("least-squares-sized", np.zeros((10, 3)), None, np.eye(4), np.ones(10))

    def test_report_lines_name_the_size_and_the_take_up(self):
        from BladeInspect.inspection import fit_report
        fit = {"objective": fits.SIZE_OBJECTIVE, "free": "all", "start": "ICP",
               "size_deviation": {"value_mm": 0.0213, "U_mm": 0.0071, "k": 2.0},
               "size_take_up": {"note": "the least-squares pose takes up ..."}}
        lines = fit_report.fit_lines(types.SimpleNamespace(fit=fit, weights=None))
        self.assertTrue(any("+0.0213 mm" in line and "0.0071" in line for line in lines))
        self.assertTrue(any(line.startswith("size take-up: ") for line in lines))


class AirfoilCommand(unittest.TestCase):
    """`airfoil --points --fit least-squares-size` against a scan of the demo blade made
    0.02 mm oversize and carried by a known pose."""

    DELTA = 0.02

    @classmethod
    def setUpClass(cls):
        from BladeInspect.core.pointio import write_points_csv
        cls.tmp = tempfile.mkdtemp(prefix="bi-size-fit-")
        nominal = demo_nominal()
        rng = np.random.default_rng(7)
        faces = nominal.roles["suction"] + nominal.roles["pressure"]
        on_sides = np.flatnonzero(np.isin(nominal.samples.face, faces))
        idx = rng.choice(on_sides, 20000, replace=False)
        q, n = nominal.samples.xyz[idx], nominal.samples.normal[idx]
        cad = q + (cls.DELTA + rng.normal(0.0, 0.001, len(q)))[:, None] * n
        cls.truth = tf.random_transform(rng, 10.0)
        cls.points = os.path.join(cls.tmp, "points.csv")
        write_points_csv(cls.points, tf.apply_transform(tf.invert_transform(cls.truth), cad))
        cls.corners = np.asarray(nominal.bbox_corners, dtype=float)
        cls.docs = {fit: cls.airfoil(fit) for fit in ("least-squares", fits.SIZE_OBJECTIVE)}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, True)

    @classmethod
    def airfoil(cls, fit):
        from BladeInspect import cli
        out = os.path.join(cls.tmp, fit)
        stdout = io.StringIO()
        with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(io.StringIO()):
            code = cli.main(["airfoil", "--points", cls.points, "--out", out,
                             "--section-heights", "30,70", "--fit", fit])
        assert code == 0, code
        with open(os.path.join(out, "airfoil.json")) as fh:
            return dict(json.load(fh), stdout=stdout.getvalue())

    def pose_error(self, doc):
        G = np.asarray(doc["measured_to_cad"]) @ tf.invert_transform(self.truth)
        return np.abs(tf.apply_transform(G, self.corners) - self.corners).max()

    def test_size_fit_measures_pose_size_thickness_and_chord(self):
        doc = self.docs[fits.SIZE_OBJECTIVE]
        size = doc["fit"]["size_deviation"]
        self.assertAlmostEqual(size["value_mm"], self.DELTA, delta=0.5 * UM)
        self.assertEqual(size["k"], 2.0)
        self.assertGreater(size["U_mm"], abs(size["value_mm"] - self.DELTA))
        self.assertLess(self.pose_error(doc), 2 * UM)
        self.assertIn("size deviation %+.4f mm, U (k=2) %.4f mm"
                      % (size["value_mm"], size["U_mm"]), doc["stdout"])
        for block in doc["airfoil"]:
            deviation = block["deviation"]
            # an offset profile: both sides and both ends move out by delta
            self.assertAlmostEqual(deviation["max_thickness_mm"], 2 * self.DELTA,
                                   delta=3 * UM)
            # the chord rests on the edge points: withheld (with its reason) where an edge
            # zone holds too few of the 20k points, else right
            if deviation["chord_mm"] is None:
                self.assertIn("chord_mm", block["withheld"])
            else:
                self.assertAlmostEqual(deviation["chord_mm"], 2 * self.DELTA, delta=3 * UM)

    def test_plain_fit_states_its_take_up(self):
        doc = self.docs["least-squares"]
        take_up = doc["fit"]["size_take_up"]
        self.assertIn("--fit %s" % fits.SIZE_OBJECTIVE, take_up["note"])
        # the plain pose is off by far more than the sensor's noise, as the note warns
        self.assertGreater(self.pose_error(doc), 0.1)
        self.assertGreater(take_up["pose_motion_mm_per_mm"] * self.DELTA, 0.1)
        self.assertNotIn("size_deviation", doc["fit"])

    def test_fit_options_are_for_measured_points_only(self):
        from BladeInspect import cli
        for extra in (["--fit", fits.SIZE_OBJECTIVE], ["--free", "tx,ty"],
                      ["--datum-faces", "0,1,2"]):
            err = io.StringIO()
            out = os.path.join(self.tmp, "bad")
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                code = cli.main(["airfoil", "--out", out, "--section-heights", "50"] + extra)
            self.assertEqual(code, 2, extra)
            self.assertEqual(len(err.getvalue().strip().splitlines()), 1, err.getvalue())
            self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
