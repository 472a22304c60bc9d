"""The headless command line as a user runs it: files in, files out, exit statuses."""
import json
import os
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

from tests.helpers import REPO

BLADEINSPECT = os.path.join(REPO, "bladeinspect")


def run_cli(*args, timeout=300):
    return subprocess.run([BLADEINSPECT] + list(args), cwd=REPO, capture_output=True,
                          text=True, timeout=timeout)


class CliCase(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="bladeinspect-cli-")
        # A STEP of the demo blade and a simulated measurement in an unknown frame, with the
        # truth the simulator used, written by the simulate command itself.
        import Part  # noqa: F401  (FreeCAD is on the path under freecadcmd)
        from BladeInspect.cad.demo_blade import make_demo_blade
        cls.step = os.path.join(cls.tmp, "blade.step")
        make_demo_blade().shape.exportStep(cls.step)
        cls.sim = os.path.join(cls.tmp, "sim")
        proc = run_cli("simulate", "--cad", cls.step, "--out", cls.sim, "--points", "3000",
                       "--seed", "7", "--outliers", "0.02")
        if proc.returncode != 0:
            raise AssertionError("simulate failed: %s" % proc.stderr)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def assert_bad_input(self, proc, out_dir, *words):
        self.assertEqual(proc.returncode, 2, proc.stderr)
        lines = [l for l in proc.stderr.splitlines() if l.startswith("bladeinspect: error:")]
        self.assertEqual(len(lines), 1, proc.stderr)
        self.assertNotIn("Traceback", proc.stderr)
        for w in words:
            self.assertIn(w, lines[0])
        self.assertFalse(os.path.exists(os.path.join(out_dir, "result.json")))
        self.assertFalse(os.path.exists(os.path.join(out_dir, "deviations.csv")))


class TestRegisterCommand(CliCase):
    def test_register_recovers_the_simulators_pose(self):
        out = os.path.join(self.tmp, "reg")
        points = os.path.join(self.sim, "points.csv")
        # A few rows a sensor would emit where it had no reading.
        noisy = os.path.join(self.tmp, "with_nan.csv")
        with open(points) as fh, open(noisy, "w") as out_fh:
            lines = fh.read().splitlines()
            out_fh.write("\n".join(lines[:5] + ["nan,nan,nan,0", "1.0,,2.0,50"] + lines[5:]) + "\n")
        proc = run_cli("register", "--cad", self.step, "--points", noisy, "--out", out)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        with open(os.path.join(out, "result.json")) as fh:
            result = json.load(fh)
        with open(os.path.join(self.sim, "simulation.json")) as fh:
            truth = np.array(json.load(fh)["truth_measured_to_cad"])
        for key in ("measured_to_cad", "rms_mm", "n_points", "n_inliers", "deviation",
                    "pose_covariance", "pose_uncertainty_mm", "timing_s", "software", "coarse"):
            self.assertIn(key, result)
        for key in ("min", "max", "mean", "rms", "std", "pct_within_1sigma",
                    "pct_within_3sigma", "histogram"):
            self.assertIn(key, result["deviation"])
        for key in ("measured_to_cad", "eigenvalues", "candidates", "warning"):
            self.assertIn(key, result["coarse"])
        self.assertEqual(result["n_rows_skipped"], 2)
        self.assertEqual(np.array(result["pose_covariance"]).shape, (6, 6))
        T = np.array(result["measured_to_cad"])
        # Corner displacement against the truth, computed here independently.
        import Part
        bb = Part.read(self.step).BoundBox
        corners = np.array([[x, y, z] for x in (bb.XMin, bb.XMax) for y in (bb.YMin, bb.YMax)
                            for z in (bb.ZMin, bb.ZMax)])
        delta = T @ np.linalg.inv(truth)
        moved = corners @ delta[:3, :3].T + delta[:3, 3] - corners
        self.assertLess(np.linalg.norm(moved, axis=1).max(), 3 * result["pose_uncertainty_mm"])
        with open(os.path.join(out, "deviations.csv")) as fh:
            header = fh.readline().strip().split(",")
            first = fh.readline().strip().split(",")
        self.assertEqual(header[:6], ["x", "y", "z", "deviation_mm", "snr", "inlier"])
        self.assertEqual(len(first[3].split(".")[1]), 6)
        rows = np.loadtxt(os.path.join(out, "deviations.csv"), delimiter=",", skiprows=1,
                          usecols=(0, 1, 2, 3, 5))
        self.assertEqual(len(rows), result["n_points"])
        self.assertEqual(int(rows[:, 4].sum()), result["n_inliers"])
        hist = result["deviation"]["histogram"]
        self.assertEqual(sum(b["count"] for b in hist), result["n_points"])

    def test_freecadcmd_runs_the_same_entry(self):
        out = os.path.join(self.tmp, "fccmd")
        code = ("import sys; sys.path.insert(0, %r); from BladeInspect import cli; "
                "sys.exit(cli.main(['register', '--cad', %r, '--points', %r, '--out', %r]))"
                % (REPO, self.step, os.path.join(self.sim, "points.csv"), out))
        proc = subprocess.run(["freecadcmd", "-c", code], capture_output=True, text=True,
                              timeout=300)
        self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)
        self.assertTrue(os.path.exists(os.path.join(out, "result.json")))


class TestBadInput(CliCase):
    def check(self, points, *words, cad=None):
        out = os.path.join(self.tmp, "bad-%d" % abs(hash((points, cad))))
        proc = run_cli("register", "--cad", cad or self.step, "--points", points, "--out", out)
        self.assert_bad_input(proc, out, *words)

    def write(self, name, text):
        path = os.path.join(self.tmp, name)
        with open(path, "w") as fh:
            fh.write(text)
        return path

    def test_missing_points_file(self):
        self.check(os.path.join(self.tmp, "nope.csv"), "nope.csv")

    def test_empty_points_file(self):
        self.check(self.write("empty.csv", ""), "empty.csv")

    def test_malformed_points_file(self):
        self.check(self.write("malformed.csv", "a,b\n1,2\n3,4\n"), "malformed.csv")

    def test_too_few_points(self):
        self.check(self.write("few.xyz", "".join("%d 0 0\n" % i for i in range(9))), "few.xyz")

    def test_all_nan(self):
        self.check(self.write("nan.csv", "x,y,z\n" + "nan,nan,nan\n" * 50), "nan.csv")

    def test_unreadable_cad(self):
        cad = self.write("garbage.step", "this is not STEP\n")
        self.check(os.path.join(self.sim, "points.csv"), "garbage.step", cad=cad)

    def test_cad_without_faces(self):
        import Part
        import FreeCAD
        cad = os.path.join(self.tmp, "wire.brep")
        Part.makeLine(FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(1, 0, 0)).exportBrep(cad)
        self.check(os.path.join(self.sim, "points.csv"), "wire.brep", cad=cad)

    def test_missing_cad(self):
        self.check(os.path.join(self.sim, "points.csv"), "missing.step",
                   cad=os.path.join(self.tmp, "missing.step"))

    def test_missing_argument(self):
        out = os.path.join(self.tmp, "noarg")
        proc = run_cli("register", "--cad", self.step, "--out", out)
        self.assert_bad_input(proc, out, "--points")


if __name__ == "__main__":
    unittest.main()
