"""`./bladeinspect batch --scheduler tcp://...` as a production lot runs on Dask: a real
`dask scheduler` and two `dask worker` processes (no nanny: a killed worker stays dead) on the
loopback interface, started and stopped here; one worker is killed (SIGKILL) while it reports
a blade. The lot must complete with every blade reported exactly once, each report that of
its own scan (the known pose error and bump of each blade), and summary.csv and the command's
last line must name the blade that was retried."""
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

import numpy as np

from BladeInspect.core import transforms as tf
from tests import inspection_fixtures as fx

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLI = os.path.join(HERE, "bladeinspect")
N_BLADES = 4
BUMP_HEIGHT = 0.09
START_TIMEOUT_S = 120
LOT_TIMEOUT_S = 600


def dask_command(kind):
    """`dask scheduler` / `dask worker`, or the older `dask-scheduler` / `dask-worker`; None
    when neither is installed."""
    dask = shutil.which("dask")
    if dask and subprocess.run([dask, kind, "--help"], capture_output=True,
                               timeout=60).returncode == 0:
        return [dask, kind]
    older = shutil.which("dask-" + kind)
    return [older] if older else None


def read_summary(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def wait_for(condition, what, timeout_s, procs=()):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        for proc, log in procs:
            if proc.poll() is not None:
                raise AssertionError("%s ended (exit %s) before %s: %s"
                                     % (proc.args[0], proc.returncode, what,
                                        open(log).read()[-2000:]))
        time.sleep(0.02)
    raise AssertionError("no %s within %d s" % (what, timeout_s))


@unittest.skipUnless(dask_command("scheduler") and dask_command("worker"),
                     "the dask scheduler/worker executables are not installed "
                     "(apt-get install python3-distributed)")
class TestLotOnDaskProcesses(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        from BladeInspect.cad.demo_blade import BladeParams, make_demo_blade
        nominal = fx.demo_nominal()
        cls.tmp = tempfile.mkdtemp(prefix="bi-dask-")
        cls.cad = os.path.join(cls.tmp, "blade.step")
        make_demo_blade().shape.exportStep(cls.cad)
        cls.scans = os.path.join(cls.tmp, "scans")
        os.makedirs(cls.scans)
        span = BladeParams().span
        on_surface, _ = fx.profile_points(nominal, np.linspace(4.0, 66.0, 25), n_profile=50)
        rng = np.random.default_rng(8)
        suction = np.flatnonzero(np.isin(nominal.signed_distance(on_surface).face,
                                         nominal.roles["suction"])
                                 & (np.abs(on_surface[:, 2] - 0.5 * span) < 2.0))
        centre = on_surface[suction[np.argmin(np.abs(on_surface[suction, 0] - 5.0))]]
        # Odd blades carry the bump: each report must be its own blade's.
        cls.bumped = {}
        for k in range(N_BLADES):
            extra = fx.bump(on_surface, centre, BUMP_HEIGHT, 3.0) if k % 2 else 0.0
            dev = rng.uniform(-0.005, 0.005, len(on_surface)) + extra
            pts = tf.apply_transform(tf.random_transform(rng, 40.0),
                                     fx.displaced(nominal, on_surface, dev))
            name = "blade_%d.csv" % k
            np.savetxt(os.path.join(cls.scans, name), pts, delimiter=",", header="x,y,z",
                       comments="", fmt="%.9f")
            cls.bumped[name] = bool(k % 2)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def start(self, args, name):
        log = os.path.join(self.tmp, name + ".log")
        # Only the checkout on the path: a worker starts FreeCAD itself (batch.report_one).
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [HERE] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else [])))
        with open(log, "w") as fh:
            proc = subprocess.Popen(args, stdout=fh, stderr=subprocess.STDOUT, cwd=self.tmp,
                                    env=env)
        self.addCleanup(self.stop, proc)
        return proc, log

    @staticmethod
    def stop(proc):
        if proc.poll() is None:
            proc.kill()
        proc.wait(timeout=30)

    def test_a_worker_killed_mid_lot(self):
        from distributed import Client
        scheduler_file = os.path.join(self.tmp, "scheduler.json")
        scheduler = self.start(dask_command("scheduler") + [
            "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
            "--scheduler-file", scheduler_file], "scheduler")

        def address():
            try:
                with open(scheduler_file) as fh:
                    return json.load(fh)["address"]
            except (OSError, ValueError, KeyError):
                return None
        address = wait_for(address, "scheduler address", START_TIMEOUT_S, [scheduler])
        self.assertTrue(address.startswith("tcp://127.0.0.1:"), address)
        workers = {}
        for k in range(2):
            proc, log = self.start(dask_command("worker") + [
                address, "--host", "127.0.0.1", "--no-nanny", "--nthreads", "1",
                "--no-dashboard", "--name", "worker-%d" % k, "--death-timeout", "60",
                "--local-directory", os.path.join(self.tmp, "worker-%d" % k)],
                "worker-%d" % k)
            workers[proc.pid] = (proc, log)
        client = Client(address, timeout=START_TIMEOUT_S)
        try:
            client.wait_for_workers(2, timeout=START_TIMEOUT_S)
            self.assertTrue(all(w.startswith("tcp://127.0.0.1:")
                                for w in client.scheduler_info()["workers"]))
        finally:
            client.close()

        out = os.path.join(self.tmp, "lot")
        lot, lot_log = self.start([CLI, "batch", "--cad", self.cad, "--scans", self.scans,
                                   "--out", out, "--scheduler", address,
                                   # the lost worker, not the airfoil stage, is under test
                                   "--no-airfoil"], "batch")
        attempts_dir = os.path.join(out, ".attempts")

        def blade_in_flight():
            """(blade, worker pid) of a blade begun on one of our workers and not done."""
            try:
                stems = os.listdir(attempts_dir)
            except FileNotFoundError:
                return None
            for stem in stems:
                with open(os.path.join(attempts_dir, stem)) as fh:
                    lines = fh.read().split("\n")
                pid = int(lines[0].split()[1]) if len(lines) > 1 else None
                if pid in workers and not os.path.exists(os.path.join(out, stem,
                                                                      "result.json")):
                    return stem, pid
            return None
        stem, pid = wait_for(blade_in_flight, "blade in flight on a worker", LOT_TIMEOUT_S,
                             [(lot, lot_log)] + list(workers.values()))
        os.kill(pid, signal.SIGKILL)
        workers[pid][0].wait(timeout=30)
        self.assertFalse(os.path.exists(os.path.join(out, stem, "result.json")),
                         "the blade finished before its worker was killed")

        status = lot.wait(timeout=LOT_TIMEOUT_S)
        output = open(lot_log).read()
        self.assertEqual(status, 0, output[-2000:])
        rows = read_summary(os.path.join(out, "summary.csv"))
        names = sorted(self.bumped)
        self.assertEqual([r["file"] for r in rows], names)        # each exactly once
        retried = stem + ".csv"
        for row in rows:
            self.assertEqual(row["status"], "ok", row)
            self.assertEqual(int(row["attempts"]), 2 if row["file"] == retried else 1, row)
            worst = float(row["worst_deviation_mm"])
            if self.bumped[row["file"]]:
                self.assertAlmostEqual(worst, BUMP_HEIGHT, delta=0.01)
                self.assertEqual(row["verdict"], "fail")
            else:
                self.assertLess(abs(worst), 0.02)
                self.assertEqual(row["verdict"], "pass")
        self.assertRegex(output, r"retried after a lost worker: %s \(2 attempts\)"
                         % re.escape(retried))
        survivor = next(p for p in workers if p != pid)
        self.assertEqual(sorted(n for n in os.listdir(out) if not n.startswith(".")),
                         sorted(os.path.splitext(n)[0] for n in names) + ["summary.csv"])
        self.assertFalse(os.path.exists(attempts_dir))
        self.assertIsNone(workers[survivor][0].poll())


if __name__ == "__main__":
    unittest.main()
