"""A production lot: reports per file, summary.csv, bad files skipped, resume, Dask cluster."""
import csv
import os
import shutil
import tempfile
import unittest

import numpy as np

from BladeInspect.app.document import write_inspection_document
from BladeInspect.cad.demo_blade import BladeParams
from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import InputError
from BladeInspect.inspection import batch as B
from BladeInspect.inspection.run_options import RunOptions
from tests import inspection_fixtures as fx

SPAN = BladeParams().span
BUMP_HEIGHT = 0.09


def read_summary(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


class BatchTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        nominal = fx.demo_nominal()
        cls.tmp = tempfile.mkdtemp()
        cls.scans = os.path.join(cls.tmp, "scans")
        os.makedirs(cls.scans)
        on_surface, _ = fx.profile_points(nominal, np.linspace(4.0, 66.0, 25), n_profile=50)
        rng = np.random.default_rng(3)
        base = nominal.signed_distance(on_surface)
        # blade_b has a bump on its suction side at mid span
        suction = np.flatnonzero(np.isin(base.face, nominal.roles["suction"])
                                 & (np.abs(on_surface[:, 2] - 0.5 * SPAN) < 2.0))
        centre = on_surface[suction[np.argmin(np.abs(on_surface[suction, 0] - 5.0))]]
        for name, extra in (("blade_a.csv", 0.0),
                            ("blade_b.xyz", fx.bump(on_surface, centre, BUMP_HEIGHT, 3.0))):
            dev = rng.uniform(-0.005, 0.005, len(on_surface)) + extra
            pts = tf.apply_transform(tf.random_transform(rng, 40.0),
                                     fx.displaced(nominal, on_surface, dev))
            path = os.path.join(cls.scans, name)
            if name.endswith(".csv"):
                np.savetxt(path, pts, delimiter=",", header="x,y,z", comments="", fmt="%.9f")
            else:
                np.savetxt(path, pts, fmt="%.9f")
        with open(os.path.join(cls.scans, "broken.csv"), "w") as fh:
            fh.write("x,y,z\n1,2,3\n4,5,6\n")
        with open(os.path.join(cls.scans, "notes.md"), "w") as fh:
            fh.write("not a point file\n")
        cls.out = os.path.join(cls.tmp, "lot")
        # Two worker processes: the document writer must pickle to them.
        cls.lot = B.run_batch(None, cls.scans, cls.out, workers=2,
                              document=write_inspection_document)
        cls.summary = read_summary(os.path.join(cls.out, "summary.csv"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_one_report_per_file_and_bad_file_skipped(self):
        self.assertEqual([r["file"] for r in self.summary],
                         ["blade_a.csv", "blade_b.xyz", "broken.csv"])
        a, b, broken = self.summary
        self.assertEqual((a["status"], a["verdict"]), ("ok", "pass"))
        self.assertEqual((b["status"], b["verdict"]), ("ok", "fail"))
        self.assertAlmostEqual(float(b["worst_deviation_mm"]), BUMP_HEIGHT, delta=0.01)
        self.assertLess(float(a["rms_mm"]), 0.004)
        self.assertEqual(broken["status"], "error")
        self.assertIn("broken.csv", broken["error"])
        for stem in ("blade_a", "blade_b"):
            files = set(os.listdir(os.path.join(self.out, stem)))
            self.assertTrue({"result.json", "deviations.csv", "report.html", "report.pdf",
                             "inspection.FCStd"} <= files)
        self.assertFalse(os.path.exists(os.path.join(self.out, "broken", "result.json")))
        self.assertEqual(sorted(os.listdir(self.out)), ["blade_a", "blade_b", "summary.csv"])
        self.assertIn("1 pass, 1 fail, 1 error", self.lot["message"])

    def test_per_section_columns(self):
        a = self.summary[0]
        for label in "12345":
            for key in B.SECTION_FIELDS:
                self.assertIn("section_%s_%s" % (label, key), a)
        self.assertGreater(int(a["section_3_n"]), 10)
        self.assertEqual(self.summary[2]["section_3_n"], "")

    def test_resume_redoes_only_what_is_missing(self):
        out = os.path.join(self.tmp, "lot_resume")
        shutil.copytree(self.out, out)
        shutil.rmtree(os.path.join(out, "blade_b"))
        kept = os.path.join(out, "blade_a", "result.json")
        mtime = os.stat(kept).st_mtime_ns
        rows = B.run_batch(None, self.scans, out, workers=1)["rows"]
        self.assertEqual([r["reused"] for r in rows], [True, False, False])
        self.assertEqual(os.stat(kept).st_mtime_ns, mtime)
        again = read_summary(os.path.join(out, "summary.csv"))
        self.assertEqual([(r["file"], r["status"], r["verdict"]) for r in again],
                         [(r["file"], r["status"], r["verdict"]) for r in self.summary])
        self.assertAlmostEqual(float(again[1]["rms_mm"]), float(self.summary[1]["rms_mm"]),
                               delta=1e-6)

    def test_a_lot_run_again_otherwise_is_done_again(self):
        """A done file is one made from the same inputs: another tolerance redoes it (not a
        summary mixing two tolerances' verdicts), and its result says the new one."""
        import json
        scans = os.path.join(self.tmp, "scans_again")
        os.makedirs(scans)
        shutil.copy(os.path.join(self.scans, "blade_a.csv"), scans)
        out = os.path.join(self.tmp, "lot_again")
        os.makedirs(out)
        shutil.copytree(os.path.join(self.out, "blade_a"), os.path.join(out, "blade_a"))
        lot = B.run_batch(None, scans, out, RunOptions.of(tolerance=0.03), workers=1)
        self.assertEqual([r["reused"] for r in lot["rows"]], [False])
        self.assertIn("1 done again", lot["message"])
        with open(os.path.join(out, "blade_a", "result.json")) as fh:
            self.assertEqual(json.load(fh)["tolerance_mm"], 0.03)
        again = B.run_batch(None, scans, out, RunOptions.of(tolerance=0.03), workers=1)
        self.assertEqual([r["reused"] for r in again["rows"]], [True])

    def test_done_means_made_from_these_inputs(self):
        folder = os.path.join(self.out, "blade_a")
        options = B.lot_options(None, B.PROFILE_TOLERANCE_MM, 0, False, None, None, None)
        record = B.inputs_record(os.path.join(self.scans, "blade_a.csv"), options)
        self.assertIsNotNone(B._read_done(folder, record))
        # the same name scanned again: its points differ
        other = dict(record, points_sha256="0" * 64)
        self.assertIsNone(B._read_done(folder, other))
        for key, value in (("tolerance_mm", 0.05), ("seed", 1), ("allow_mismatch", True)):
            self.assertIsNone(B._read_done(folder, dict(record, **{key: value})), key)
        # a result without the record (made by `report`, or an older lot's) is taken when its
        # own tolerance is the lot's
        import json
        copy = os.path.join(self.tmp, "no_record")
        shutil.copytree(folder, copy)
        with open(os.path.join(copy, "result.json")) as fh:
            doc = json.load(fh)
        self.assertEqual(doc["batch_inputs"], record)
        del doc["batch_inputs"]
        with open(os.path.join(copy, "result.json"), "w") as fh:
            json.dump(doc, fh)
        self.assertIsNotNone(B._read_done(copy, record))
        self.assertIsNone(B._read_done(copy, dict(record, tolerance_mm=0.03)))

    def test_rig_file_enters_every_blade_u(self):
        """`batch --rig-file`: the RIG.json's calibration term in each blade's U, as `report`
        takes it (the lot's fixture has no airfoil stage, nor has this run); a bad RIG.json
        stops the lot before anything is written."""
        import json
        import subprocess
        from BladeInspect.rig.kinematics import RigKinematics
        from tests.helpers import REPO
        calibration = 0.01
        scans = os.path.join(self.tmp, "scans_rig")
        os.makedirs(scans)
        shutil.copy(os.path.join(self.scans, "blade_a.csv"), scans)
        rig = os.path.join(self.tmp, "RIG.json")
        RigKinematics().to_json(rig, extra={"calibration_uncertainty_mm": calibration})
        out = os.path.join(self.tmp, "lot_rig")

        def batch(rig_file, out_dir):
            return subprocess.run([os.path.join(REPO, "bladeinspect"), "batch", "--cad", "demo",
                                   "--scans", scans, "--out", out_dir, "--workers", "1",
                                   "--no-airfoil", "--rig-file", rig_file],
                                  cwd=REPO, capture_output=True, text=True, timeout=600)
        proc = batch(rig, out)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        with open(os.path.join(out, "blade_a", "result.json")) as fh:
            with_rig = json.load(fh)
        with open(os.path.join(self.out, "blade_a", "result.json")) as fh:
            without = json.load(fh)
        self.assertEqual(with_rig["verdict"]["measurement_model"]["calibration_mm"],
                         calibration)
        self.assertIsNone(without["verdict"]["measurement_model"]["calibration_mm"])
        # The same points and seed: each section's and the part's U grows by the calibration's independent
        # term alone, U^2 = U0^2 + (k u_cal)^2 (k = 2).
        judged = [(a, b) for a, b in zip(with_rig["verdict"]["sections"],
                                         without["verdict"]["sections"]) if "U_mm" in b]
        self.assertGreaterEqual(len(judged), 1)    # this lot's points cross few planes
        judged.append((with_rig["verdict"]["part"], without["verdict"]["part"]))
        for a, b in judged:
            self.assertAlmostEqual(a["U_mm"] ** 2 - b["U_mm"] ** 2, (2 * calibration) ** 2,
                                   delta=1e-3 * (2 * calibration) ** 2)
        # (the airfoil stage takes its term from this same measurement model: attach,
        # tests/test_airfoil_calibration_u.py)
        broken = os.path.join(self.tmp, "RIG_broken.json")
        with open(broken, "w") as fh:
            fh.write('{"calibration_uncertainty_mm": -1}')
        out_bad = os.path.join(self.tmp, "lot_rig_bad")
        proc = batch(broken, out_bad)
        self.assertNotEqual(proc.returncode, 0)
        self.assertIn("RIG_broken.json", proc.stderr.strip().splitlines()[-1])
        self.assertFalse(os.path.exists(os.path.join(out_bad, "blade_a")))

    def test_bad_folders(self):
        with self.assertRaises(InputError):
            B.run_batch(None, os.path.join(self.tmp, "missing"), self.out)
        empty = os.path.join(self.tmp, "empty")
        os.makedirs(empty, exist_ok=True)
        with self.assertRaises(InputError):
            B.run_batch(None, empty, os.path.join(self.tmp, "lot_empty"))

    def test_dask_cluster_gives_the_same_summary(self):
        try:
            from distributed import LocalCluster
        except ImportError:
            self.skipTest("python3-distributed is not installed (apt-get install "
                          "python3-distributed)")
        # In-process workers: a spawned worker process would need a Python that imports
        # FreeCAD, which the test runner's own executable (FreeCADCmd) is not.
        cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                               protocol="tcp://", host="127.0.0.1", dashboard_address=":0")
        try:
            self.assertTrue(cluster.scheduler_address.startswith("tcp://127.0.0.1:"))
            out = os.path.join(self.tmp, "lot_dask")
            B.run_batch(None, self.scans, out, scheduler=cluster.scheduler_address,
                        document=write_inspection_document)
        finally:
            cluster.close()
        dask_rows = read_summary(os.path.join(out, "summary.csv"))
        self.assertEqual(list(dask_rows[0].keys()), list(self.summary[0].keys()))
        for mine, theirs in zip(dask_rows, self.summary):
            self.assertEqual((mine["file"], mine["status"], mine["verdict"]),
                             (theirs["file"], theirs["status"], theirs["verdict"]))
            for key in ("rms_mm", "worst_deviation_mm", "section_3_max_abs_mm"):
                if theirs[key]:
                    self.assertAlmostEqual(float(mine[key]), float(theirs[key]), delta=1e-6)


if __name__ == "__main__":
    unittest.main()
