"""scan_to_dir and open_rig: the files and their record, points on the part through the
recorded truth, no silent overwrite, and resume after an injected device failure giving exactly
the points of an uninterrupted scan."""
import csv
import json
import os
import re
import tempfile
import unittest

import numpy as np

from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import DeviceError, InputError
from BladeInspect.measurement.scan import open_rig, scan_to_dir
from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose
from tests.rig_parts import TwistedEllipse

OPTIONS = dict(n_sections=3, edges=False, sides=2)
SEED = 21


class FailingRig(SimulatedRig):
    """A simulated rig whose port 'vanishes' at a given pass."""

    def __init__(self, *args, fail_at_pass=None, **kwargs):
        super().__init__(*args, **kwargs)
        self.fail_at_pass = fail_at_pass

    def scan_path(self, path_xyz, angle_deg):
        if self.pass_index == self.fail_at_pass:
            raise DeviceError("serial:/dev/ttyFAKE: motion port lost (injected)")
        return super().scan_path(path_xyz, angle_deg)


def make_rig(seed=SEED, fail_at_pass=None):
    part = TwistedEllipse()
    centre = part.bbox_corners.mean(axis=0)
    pose = random_fixture_pose(np.random.default_rng(seed), (0, 0, 1.0), centre)
    return part, FailingRig(part, pose, seed=seed, fail_at_pass=fail_at_pass)


def read_rows(path):
    with open(path) as f:
        return list(csv.reader(f))


class TestScanToDir(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.out = os.path.join(cls.tmp.name, "full")
        cls.part, cls.rig = make_rig()
        cls.messages = []
        cls.summary = scan_to_dir(cls.out, cls.rig, seed=SEED,
                                  progress=lambda f, m: cls.messages.append((f, m)), **OPTIONS)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_points_file(self):
        rows = read_rows(os.path.join(self.out, "points.csv"))
        self.assertEqual(rows[0], ["x", "y", "z", "snr", "section", "angle_deg"])
        self.assertEqual(len(rows) - 1, self.summary["points"])
        six = re.compile(r"^-?\d+\.\d{6}$")
        for row in rows[1:50]:
            for i in (0, 1, 2, 3, 5):
                self.assertRegex(row[i], six)
        sections = np.array([int(r[4]) for r in rows[1:]])
        self.assertEqual(sorted(set(sections)), [0, 1, 2])
        self.assertTrue(np.all(np.diff(sections) >= 0))

    def test_record(self):
        with open(os.path.join(self.out, "scan.json")) as f:
            record = json.load(f)
        self.assertTrue(record["complete"])
        self.assertEqual([s["index"] for s in record["sections"]], [0, 1, 2])
        for s in record["sections"]:
            for key in ("points", "passes", "max_standoff_error_mm", "simulated_s"):
                self.assertIn(key, s)
            self.assertLessEqual(s["max_standoff_error_mm"], 2.0)
        self.assertEqual(sum(s["points"] for s in record["sections"]), record["points"])
        self.assertGreaterEqual(record["simulated_s"],
                                sum(s["simulated_s"] for s in record["sections"]))
        self.assertAlmostEqual(record["simulated_s"], self.rig.elapsed_s, places=6)
        self.assertGreater(record["real_time_s"], record["simulated_s"])
        np.testing.assert_array_equal(np.array(record["table_to_cad"]), self.rig.table_to_cad)
        self.assertEqual(self.messages[-1][0], 1.0)

    def test_points_on_the_part_through_the_recorded_truth(self):
        rows = np.array(read_rows(os.path.join(self.out, "points.csv"))[1:], dtype=float)
        with open(os.path.join(self.out, "scan.json")) as f:
            T = np.array(json.load(f)["table_to_cad"])
        dev = self.part.signed_distance(tf.apply_transform(T, rows[:, :3]))
        snr = rows[:, 3]
        bound = 0.006 * np.sqrt(100.0 / snr) + 2e-4     # 6-decimal rounding included
        good = snr >= 25.0
        self.assertTrue(np.all(np.abs(dev[good]) <= bound[good]))
        self.assertLess(np.mean(np.abs(dev) > bound), 0.02)

    def test_refuses_a_folder_with_a_previous_scan(self):
        before = open(os.path.join(self.out, "points.csv")).read()
        _, rig = make_rig()
        with self.assertRaises(InputError) as cm:
            scan_to_dir(self.out, rig, seed=SEED, **OPTIONS)
        self.assertIn("--resume", str(cm.exception))
        self.assertEqual(open(os.path.join(self.out, "points.csv")).read(), before)

    def test_resume_after_device_error_gives_the_same_points(self):
        out = os.path.join(self.tmp.name, "interrupted")
        # Fail somewhere inside the second section.
        with open(os.path.join(self.out, "scan.json")) as f:
            passes = [s["passes"] for s in json.load(f)["sections"]]
        fail_at = self.rig.pass_index - passes[2] - passes[1] // 2
        _, rig = make_rig(fail_at_pass=fail_at)
        with self.assertRaises(DeviceError):
            scan_to_dir(out, rig, seed=SEED, **OPTIONS)
        with open(os.path.join(out, "scan.json")) as f:
            record = json.load(f)
        self.assertFalse(record["complete"])
        self.assertEqual(len(record["sections"]), 1)
        self.assertEqual(len(read_rows(os.path.join(out, "points.csv"))) - 1, record["points"])
        # Rows of an unfinished section written just before a crash are dropped on resume.
        with open(os.path.join(out, "points.csv"), "a") as f:
            f.write("1.000000,2.000000,3.000000,50.000000,1,0.000000\n")
        _, fresh = make_rig()
        summary = scan_to_dir(out, fresh, seed=SEED, resume=True, n_sections=9)
        self.assertTrue(summary["complete"])
        self.assertEqual(len(summary["sections"]), 3)     # the saved options stand
        with open(os.path.join(out, "points.csv")) as a, \
                open(os.path.join(self.out, "points.csv")) as b:
            self.assertEqual(a.read(), b.read())
        # Resuming a complete scan measures nothing more.
        _, again = make_rig()
        scan_to_dir(out, again, seed=SEED, resume=True)
        self.assertEqual(again.elapsed_s, 0.0)

    def test_resume_checks_the_rig(self):
        out = os.path.join(self.tmp.name, "other")
        _, rig = make_rig(fail_at_pass=3)
        with self.assertRaises(DeviceError):
            scan_to_dir(out, rig, seed=SEED, **OPTIONS)
        _, other = make_rig(seed=SEED + 1)
        with self.assertRaises(InputError):
            scan_to_dir(out, other, seed=SEED + 1, resume=True)


class TestDemoBlade(unittest.TestCase):
    """The demo blade's CAD at a random fixture pose, judged by the CAD's own exact distance."""

    def test_section_of_the_demo_blade_lies_on_its_cad(self):
        from BladeInspect.measurement.scan import demo_nominal
        nominal = demo_nominal()
        rig = open_rig("sim", nominal=nominal, seed=8)
        # The span is given (from the truth) to keep the test short; the probe is tested on
        # the analytic blade.
        table = tf.apply_transform(np.linalg.inv(rig.table_to_cad), nominal.bbox_corners)
        with tempfile.TemporaryDirectory() as out:
            summary = scan_to_dir(out, rig, seed=8, n_sections=1, edges=False,
                                  span_range=(table[:, 1].min(), table[:, 1].max()))
            rows = np.array(read_rows(os.path.join(out, "points.csv"))[1:], dtype=float)
        self.assertGreater(len(rows), 500)
        self.assertLessEqual(summary["sections"][0]["max_standoff_error_mm"], 2.0)
        dev = nominal.signed_distance(tf.apply_transform(rig.table_to_cad, rows[:, :3])).distance
        snr = rows[:, 3]
        bound = 0.006 * np.sqrt(100.0 / snr) + 2e-4
        good = snr >= 25.0
        self.assertTrue(np.all(np.abs(dev[good]) <= bound[good]),
                        np.max(np.abs(dev[good]) - bound[good]))
        self.assertLess(np.mean(np.abs(dev) > bound), 0.02)


class TestNothingLeftBehind(unittest.TestCase):
    def test_bad_options_and_empty_table_leave_no_files(self):
        with tempfile.TemporaryDirectory() as tmp:
            _, rig = make_rig()
            with self.assertRaises(InputError):
                scan_to_dir(os.path.join(tmp, "a"), rig, sides=3)
            self.assertFalse(os.path.exists(os.path.join(tmp, "a")))
            empty = SimulatedRig(TwistedEllipse(), tf.make_transform(np.eye(3), [0, 0, 500.0]))
            with self.assertRaises(InputError):
                scan_to_dir(os.path.join(tmp, "b"), empty, n_sections=1, search_radius=10.0)
            self.assertEqual(os.listdir(os.path.join(tmp, "b")), [])


class TestOpenRig(unittest.TestCase):
    def test_sim_is_clamped_by_the_seed(self):
        part = TwistedEllipse()
        rig = open_rig("sim", nominal=part, seed=4)
        self.assertIsInstance(rig, SimulatedRig)
        centre = 0.5 * (part.bbox_corners.min(axis=0) + part.bbox_corners.max(axis=0))
        expected = random_fixture_pose(np.random.default_rng(4), (0, 0, 1.0), centre)
        np.testing.assert_array_equal(rig.table_to_cad, expected)

    def test_bad_specs(self):
        for spec in ("simulated", "serial:", "usb:/dev/x"):
            with self.assertRaises(InputError):
                open_rig(spec, nominal=TwistedEllipse())

    def test_missing_serial_port_is_a_device_error(self):
        with self.assertRaises(DeviceError):
            open_rig("serial:/dev/nonexistent-bladeinspect-port")


if __name__ == "__main__":
    unittest.main()
