"""The complete scan (measurement.complete, `inspect --complete`) of the demo blade at a coarse pitch,
judged by the simulator's truth pose and by OCC's own distance and normals, not by the ray
cast the plan itself is made from."""
import json
import os
import shutil
import tempfile
import unittest

import numpy as np
from scipy.spatial import cKDTree

from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import InputError
from BladeInspect.inspection.run_options import RunOptions
from tests.helpers import demo_nominal

PITCH = 2.0
SEED = 11
# A CAD sample is covered when a measured point lies this close: half the pitch to the nearest
# line (lines lean up to 5 deg off the sections), plus half a reading step along a surface
# leaning up to 40 deg from the beam, plus margin.
COVER_RADIUS_MM = 0.5 * PITCH / np.cos(np.radians(5.0)) + 0.5 * 0.25 / np.cos(np.radians(40.0)) \
    + 0.1
EDGE_ZONE_MM = 1.0
# End to end: lines no farther apart than Table 2's band (+-0.25 mm), so every nominal plane
# has raster points in its band wherever the lines lean.
INSPECT_PITCH = 0.5
HEIGHTS = (30.0, 70.0)
# A bump of 30 um on the suction side near the 30 % plane (span 70 mm along CAD z).
BUMP_HEIGHT = 0.03
BUMP_RADIUS = 6.0


class TestCompleteRaster(unittest.TestCase):
    """Plan and scan at the truth pose: what the raster measures is the blade, all of it."""

    @classmethod
    def setUpClass(cls):
        from BladeInspect.measurement.complete import plan_complete, scan_complete
        from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose
        cls.nominal = demo_nominal()
        cls.truth = random_fixture_pose(np.random.default_rng(SEED))
        cls.rig = SimulatedRig(cls.nominal, cls.truth, seed=SEED)
        cls.plan = plan_complete(cls.nominal, cls.truth, cls.rig.sensor, cls.rig.limits,
                                 pitch=PITCH, kinematics=cls.rig.kinematics)
        (cls.xyz, cls.snr, cls.line, cls.angle, cls.rows, cls.reading,
         cls.records) = scan_complete(cls.rig, cls.plan, cls.rig.kinematics)
        cls.cad = tf.apply_transform(cls.truth, cls.xyz)

    def test_every_planned_point_read_once(self):
        self.assertEqual(len(self.xyz), self.plan.n_points)
        rows = np.sort(np.concatenate([p.rows for p in self.plan.passes]))
        np.testing.assert_array_equal(rows, np.arange(self.plan.n_points))
        for p in self.plan.passes:
            self.assertTrue(np.all(self.plan.angle_deg[p.rows] == p.angle_deg))
        self.assertGreaterEqual(len(self.plan.angles_deg), 3)

    def noise_bound(self):
        """The sensor model's largest error at the plan's 40 deg incidence limit: the noise
        grows as sqrt(snr_ref / snr), plus the reading's resolution."""
        sensor = self.rig.sensor
        snr = float(sensor.snr(np.array([sensor.standoff]), np.array([np.radians(40.0)]))[0])
        return sensor.accuracy * np.sqrt(sensor.snr_ref / snr) + sensor.resolution

    def test_points_on_the_cad_within_sensor_noise(self):
        d = self.nominal.signed_distance(self.cad).distance
        self.assertLess(np.max(np.abs(d)), self.noise_bound())
        # OCC's own distance on a subset, independent of the fast distance code.
        sub = np.random.default_rng(1).choice(len(self.cad), 60, replace=False)
        occ = self.nominal.signed_distance_occ(self.cad[sub]).distance
        self.assertLess(np.max(np.abs(occ)), self.noise_bound())

    def test_standoff_within_epsilon(self):
        # At the true pose every reading is the standoff up to the sensor's noise.
        err = np.abs(self.reading - self.rig.sensor.standoff)
        self.assertLess(err.max(), self.noise_bound())

    def test_lines_every_pitch_along_the_axis(self):
        steps = np.diff(self.plan.line_y)
        np.testing.assert_allclose(steps, PITCH, atol=1e-9)
        stage_y = self.plan.stage_xyz[:, 1]
        np.testing.assert_allclose(stage_y, self.plan.line_y[self.plan.line], atol=1e-9)

    def test_both_sides_and_both_edges_covered(self):
        nominal = self.nominal
        s = nominal.samples
        tree = cKDTree(self.cad)
        near, _ = tree.query(s.xyz, distance_upper_bound=COVER_RADIUS_MM)
        covered = np.isfinite(near)
        for role in ("suction", "pressure"):
            on = np.isin(s.face, nominal.roles[role])
            self.assertGreater(covered[on].mean(), 0.99, role)
            self.assertTrue(np.isin(self.plan.face, nominal.roles[role]).any())
        # Edges: per span band of the demo blade (span along CAD z, chord along x), the
        # samples within EDGE_ZONE_MM of the chord's two ends.
        blade = np.isin(s.face, nominal.roles["suction"] + nominal.roles["pressure"])
        for z in np.arange(5.0, 70.0, 10.0):
            band = blade & (np.abs(s.xyz[:, 2] - z) < 1.0)
            x = s.xyz[band, 0]
            for name, zone in (("leading", x < x.min() + EDGE_ZONE_MM),
                               ("trailing", x > x.max() - EDGE_ZONE_MM)):
                self.assertGreater(covered[band][zone].mean(), 0.98, "%s edge at z=%g"
                                   % (name, z))

    def test_each_point_from_its_most_head_on_angle(self):
        # OCC's normal at the nearest CAD point, turned into the machine at every planned angle:
        # the angle a point was measured from must face it best (ties within 0.5 deg).
        sub = np.random.default_rng(2).choice(len(self.cad), 80, replace=False)
        occ = self.nominal.signed_distance_occ(self.cad[sub])
        normal_table = occ.normal @ tf.invert_transform(self.truth)[:3, :3].T
        kin = self.rig.kinematics
        cos = np.array([normal_table @ kin.rotation(a)[2] for a in self.plan.angles_deg])
        used = np.searchsorted(self.plan.angles_deg, self.angle[sub])
        chosen = cos[used, np.arange(len(sub))]
        self.assertTrue(np.all(chosen >= cos.max(axis=0) - np.sin(np.radians(0.5))))
        self.assertTrue(np.all(chosen >= np.cos(np.radians(40.0)) - 1e-6))

    def test_bad_pitch(self):
        from BladeInspect.measurement.complete import plan_complete
        for bad in (0.0, -1.0, float("nan"), "abc"):
            with self.assertRaises(InputError):
                plan_complete(self.nominal, self.truth, self.rig.sensor, self.rig.limits,
                              pitch=bad)


class TestPasses(unittest.TestCase):
    def test_whole_lines_up_to_the_limit(self):
        from BladeInspect.measurement.complete import _passes
        rng = np.random.default_rng(3)
        for _ in range(20):
            sizes = rng.integers(1, 9, rng.integers(1, 30))
            lines = np.repeat(np.arange(len(sizes)), sizes)
            limit = int(rng.integers(1, 20))
            passes = _passes(30.0, lines, 100, max_points=limit)
            rows = np.concatenate([p.rows for p in passes])
            np.testing.assert_array_equal(rows, 100 + np.arange(len(lines)))
            for p in passes:
                own = lines[p.rows - 100]
                # Whole lines only: a pass starts where a line starts and ends where it ends.
                self.assertEqual(np.count_nonzero(lines == own[0]),
                                 np.count_nonzero(own == own[0]))
                self.assertEqual(np.count_nonzero(lines == own[-1]),
                                 np.count_nonzero(own == own[-1]))
                self.assertTrue(len(p.rows) <= limit or len(np.unique(own)) == 1)
                # No pass could have taken the next line too.
                nxt = p.rows[-1] + 1 - 100
                if nxt < len(lines):
                    self.assertGreater(len(p.rows) + np.count_nonzero(lines == lines[nxt]),
                                       limit)


class TestInspectComplete(unittest.TestCase):
    """`inspect --complete` end to end at a coarse pitch: files, phases, times, pose."""

    @classmethod
    def setUpClass(cls):
        from BladeInspect.inspection.closed_loop import run_inspect
        from BladeInspect.rig.sensor import SensorModel
        from BladeInspect.rig.simulated import SimulatedRig, make_bump, random_fixture_pose
        cls.nominal = demo_nominal()
        s = cls.nominal.samples
        near = np.isin(s.face, cls.nominal.roles["suction"]) & (np.abs(s.xyz[:, 2] - 21.0) < 0.5)
        centre = s.xyz[near][np.argsort(s.xyz[near][:, 0])[np.count_nonzero(near) // 2]]
        cls.bump = staticmethod(make_bump(centre, BUMP_RADIUS, BUMP_HEIGHT))
        cls.truth = random_fixture_pose(np.random.default_rng(SEED + 1))
        # A quiet sensor (0.5 um), so that Table 2 can be held to the error field within 2 um.
        cls.rig = SimulatedRig(cls.nominal, cls.truth, sensor=SensorModel(accuracy=0.0005),
                               error_field=cls.bump, seed=SEED)
        cls.tmp = tempfile.mkdtemp(prefix="bi-complete-")
        cls.out = os.path.join(cls.tmp, "out")
        cls.plans_seen = []     # (plan, rig passes run when it was shown)
        cls.summary = run_inspect(None, cls.out,
                                  RunOptions.of(complete=True, pitch=INSPECT_PITCH, seed=SEED,
                                                section_heights=HEIGHTS,
                                                scan_options={"n_sections": 5,
                                                              "point_spacing": 0.25,
                                                              "probe_spacing": 1.0}),
                                  rig=cls.rig, nominal=cls.nominal, document=False,
                                  on_plan=lambda plan: cls.plans_seen.append(
                                      (plan, cls.rig.pass_index)))
        with open(os.path.join(cls.out, "scan.json")) as fh:
            cls.scan_json = json.load(fh)
        with open(os.path.join(cls.out, "result.json")) as fh:
            cls.result_json = json.load(fh)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_files_and_phases(self):
        from BladeInspect.core.pointio import read_points
        names = set(os.listdir(self.out))
        for name in ("points.csv", "plan.json", "scan.json", "result.json", "deviations.csv",
                     "report.html"):
            self.assertIn(name, names)
        points = read_points(os.path.join(self.out, "points.csv"))
        self.assertEqual(set(points.columns["phase"].tolist()), {"blind", "complete"})
        n_complete = int(np.count_nonzero(points.columns["phase"] == "complete"))
        self.assertEqual(n_complete, self.scan_json["phases"]["complete"]["points"])
        self.assertEqual(len(self.result_json["sections"]), len(HEIGHTS))

    def test_on_plan_sees_the_raster_before_it_is_scanned(self):
        """on_plan is called with --complete too (it was once silently ignored there): once,
        with the plan that was scanned, before its first pass."""
        self.assertEqual(len(self.plans_seen), 1)
        plan, passes_before = self.plans_seen[0]
        self.assertIs(plan, self.summary["plan"])
        raster_passes = len(self.scan_json["phases"]["complete"]["passes"])
        self.assertGreater(raster_passes, 0)
        self.assertEqual(passes_before + raster_passes, self.rig.pass_index)

    def test_times_reported(self):
        phase = self.scan_json["phases"]["complete"]
        # The real rig's time: at least the sensor's acquisition at its rate.
        self.assertGreaterEqual(phase["rig_s"], phase["points"] / self.rig.sensor.rate_hz)
        self.assertAlmostEqual(phase["rig_s"] + self.scan_json["phases"]["blind"]["rig_s"],
                               self.rig.elapsed_s, places=6)
        self.assertGreater(phase["simulated_s"], 0.0)

    def test_pose_and_points_by_truth(self):
        from BladeInspect.core.pointio import read_points
        pose = np.asarray(self.summary["result"].measured_to_cad)
        points = read_points(os.path.join(self.out, "points.csv"))
        complete = points.xyz[points.columns["phase"] == "complete"]
        moved = np.linalg.norm(tf.apply_transform(pose, complete)
                               - tf.apply_transform(self.truth, complete), axis=1)
        self.assertLess(moved.max(), 0.002)
        d = self.nominal.signed_distance(tf.apply_transform(self.truth, complete)).distance
        self.assertLess(np.max(np.abs(d) - self.bump(self.nominal.signed_distance(
            tf.apply_transform(self.truth, complete)).closest)), 0.002)

    def test_table2_reads_the_error_field(self):
        from BladeInspect.core.pointio import read_points
        points = read_points(os.path.join(self.out, "points.csv"))
        cad = tf.apply_transform(self.truth, points.xyz[points.columns["phase"] == "complete"])
        field = self.bump(self.nominal.signed_distance(cad).closest)
        for sec in self.result_json["sections"]:
            p, n = np.asarray(sec["plane"]["point"]), np.asarray(sec["plane"]["normal"])
            mine = np.abs((cad - p) @ n) < 0.25
            self.assertGreater(np.count_nonzero(mine), 100)
            self.assertAlmostEqual(sec["optical"]["max_abs_mm"], np.max(np.abs(field[mine])),
                                   delta=0.002)
            self.assertAlmostEqual(sec["optical"]["rms_mm"],
                                   np.sqrt(np.mean(field[mine] ** 2)), delta=0.002)
        # The bump is seen at 30 % and not at 70 %.
        self.assertGreater(self.result_json["sections"][0]["optical"]["max_abs_mm"], 0.02)
        self.assertLess(self.result_json["sections"][1]["optical"]["max_abs_mm"], 0.005)

    def test_bad_pitch_is_input_error(self):
        from BladeInspect.inspection.closed_loop import run_inspect
        with self.assertRaises(InputError):
            run_inspect(None, os.path.join(self.tmp, "bad"),
                        RunOptions.of(complete=True, pitch=0.0), rig=self.rig,
                        nominal=self.nominal, document=False)
        self.assertFalse(os.path.exists(os.path.join(self.tmp, "bad")))


if __name__ == "__main__":
    unittest.main()
