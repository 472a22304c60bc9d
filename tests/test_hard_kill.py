"""A run killed outright (SIGKILL: a kill -9, a power cut) keeps its measurement: the real
command line, `./bladeinspect inspect --rig serial:PTY`, killed inside the 2nd blind section
(against a `./bladeinspect simrig` process), resumed and killed again inside the 2nd planned
section, resumed to the end; the same for `./bladeinspect scan`. The last resume must end with
the rows of one uninterrupted run, row for row, and the device must have served, over the
resumed runs, only the passes the killed runs had not finished (nothing measured twice, at
most the pass in flight lost).

The device of the resumed runs is served in this process (rig.simrig_device.SimRigDevice,
what `simrig` runs), so the passes it served can be counted."""
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

import numpy as np

from BladeInspect.core.errors import InputError
from BladeInspect.core.pointio import read_points
from BladeInspect.measurement.journal import JOURNAL_FILE, read_journal
from BladeInspect.inspection.run_options import RunOptions
from tests.helpers import (cli_process, demo_nominal, first_difference, process_state,
                           read_json, read_lines)
from tests.serial_support import FakeSimulatedRig, section_path

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLI = os.path.join(HERE, "bladeinspect")
SEED = 11
HEIGHTS = "30,70"
LIVE = ".checkpoint"            # closed_loop.LIVE_FOLDER, spelt out: the user sees this name
# Generous bounds for a loaded machine; a hung process fails the test, it does not hang it.
START_TIMEOUT_S = 120
RUN_TIMEOUT_S = 600


def sim_rig(nominal):
    from BladeInspect.rig.simulated import simulated_rig_for
    return simulated_rig_for(nominal, seed=SEED)


def journal_passes(folder):
    """Complete passes in the folder's journal (0 without one)."""
    try:
        return len(read_journal(os.path.join(folder, JOURNAL_FILE))[0])
    except (OSError, ValueError):
        return 0


def record_of(folder):
    """scan.json of the folder, or None while there is none."""
    try:
        return read_json(os.path.join(folder, "scan.json"))
    except (OSError, ValueError):
        return None


class Processes:
    """Child processes of one test, each stopped at the end whatever happens."""

    def __init__(self, test):
        self.procs = []
        test.addCleanup(self.stop_all)

    def start(self, args, log):
        fh = open(log, "w")
        proc = subprocess.Popen(args, stdout=fh, stderr=subprocess.STDOUT, cwd=HERE)
        fh.close()
        self.procs.append(proc)
        return proc

    def stop_all(self):
        for proc in self.procs:
            if proc.poll() is None:
                proc.kill()
            proc.wait(timeout=30)


def start_simrig(procs, log):
    """`./bladeinspect simrig --seed SEED` and the port it serves."""
    proc = procs.start([CLI, "simrig", "--seed", str(SEED)], log)
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        found = re.search(r" on (\S+)\n", open(log).read())
        if found:
            return found.group(1)
        if proc.poll() is not None:
            raise AssertionError("simrig ended: %s" % open(log).read())
        time.sleep(0.1)
    raise AssertionError("simrig printed no port within %d s" % START_TIMEOUT_S)


def wait_for_state(pid, done):
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        state = process_state(pid)
        if state is None or done(state):
            return
        time.sleep(0.001)
    raise AssertionError("process %d stuck in state %s" % (pid, process_state(pid)))


def kill_when(proc, ready, what, log):
    """SIGKILL ``proc`` as soon as ``ready()`` holds (polled); the process must still be
    running then (the kill must land mid-run).

    The CLI is stopped (SIGSTOP) before ``ready()`` is asked again and killed only if it still
    holds: on a loaded machine the run can finish the pass, or the section, between a poll and
    the kill, and the test would then judge a kill that did not land where it says."""
    deadline = time.monotonic() + RUN_TIMEOUT_S
    while time.monotonic() < deadline:
        if ready():
            cli = cli_process(proc.pid)
            if cli is None:   # ready() reads what the CLI wrote, so it has been running
                raise AssertionError("no CLI process under the wrapper %d" % proc.pid)
            os.kill(cli, signal.SIGSTOP)
            wait_for_state(cli, lambda state: state in "TtZ")
            if not ready():
                os.kill(cli, signal.SIGCONT)
                continue
            os.kill(cli, signal.SIGKILL)
            proc.send_signal(signal.SIGKILL)
            proc.wait(timeout=30)
            wait_for_state(cli, lambda state: state == "Z")
            return
        if proc.poll() is not None:
            raise AssertionError("the run ended (%s) before %s: %s"
                                 % (proc.returncode, what, open(log).read()[-2000:]))
        time.sleep(0.01)
    raise AssertionError("no %s within %d s" % (what, RUN_TIMEOUT_S))


def finish(proc, log):
    try:
        status = proc.wait(timeout=RUN_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        proc.kill()
        raise
    if status != 0:
        raise AssertionError("exit %d: %s" % (status, open(log).read()[-2000:]))


class TestInspectKilled(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        from BladeInspect.inspection.closed_loop import run_inspect
        cls.nominal = demo_nominal()
        cls.tmp = tempfile.mkdtemp(prefix="bi-kill-")
        ref_out = os.path.join(cls.tmp, "reference")
        rig = sim_rig(cls.nominal)
        run_inspect(None, ref_out,
                    RunOptions.of(seed=SEED,
                                  section_heights=[float(h) for h in HEIGHTS.split(",")]), rig=rig,
                    nominal=cls.nominal, document=False)
        cls.ref_passes = rig.pass_index
        cls.ref_lines = read_lines(os.path.join(ref_out, "points.csv"))
        cls.ref_result = read_json(os.path.join(ref_out, "result.json"))
        cls.ref_scan = read_json(os.path.join(ref_out, "scan.json"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def inspect_args(self, port, out, resume):
        return ([CLI, "inspect", "--rig", "serial:" + port, "--out", out, "--seed", str(SEED),
                 "--section-heights", HEIGHTS, "--no-airfoil"]  # as the reference run
                + (["--resume"] if resume else []))

    def kept(self, live):
        """Passes the killed run leaves: those its checkpoint counts and the journal's."""
        record = record_of(live)
        state = record["inspection"]
        held = (record["checkpoint"]["journal_passes"] if state["phase"] == "blind"
                else state["journal_passes"])
        return held + journal_passes(live)

    def test_killed_twice_then_resumed_equals_the_uninterrupted_run(self):
        from BladeInspect.rig.simrig_device import SimRigDevice
        procs = Processes(self)
        out = os.path.join(self.tmp, "killed")
        live = os.path.join(out, LIVE)

        # 1. killed inside the 2nd blind section, two of its passes done
        port = start_simrig(procs, os.path.join(self.tmp, "simrig.log"))
        log = os.path.join(self.tmp, "run1.log")
        run = procs.start(self.inspect_args(port, out, False), log)

        def inside_second_blind_section():
            record = record_of(live)
            return (record is not None and len(record["sections"]) == 1
                    and journal_passes(live) >= 2)
        kill_when(run, inside_second_blind_section, "a pass inside the 2nd blind section", log)
        record = record_of(live)
        self.assertEqual(record["inspection"]["phase"], "blind")
        self.assertFalse(os.path.exists(os.path.join(out, "result.json")))
        kept_1 = self.kept(live)
        self.assertGreaterEqual(kept_1 - record["checkpoint"]["journal_passes"], 2)
        # A fresh run into the folder is refused: it holds an interrupted inspection.
        refused = subprocess.run(self.inspect_args(port, out, False), cwd=HERE,
                                 capture_output=True, text=True, timeout=RUN_TIMEOUT_S)
        self.assertEqual(refused.returncode, 2)
        self.assertRegex(refused.stderr, r"bladeinspect: error: --out .*holds an interrupted "
                                         r"inspection \(use --resume")

        # 2. resumed, killed inside the 2nd planned section, a pass of it done
        with SimRigDevice(sim_rig(self.nominal)) as device:
            log = os.path.join(self.tmp, "run2.log")
            run = procs.start(self.inspect_args(device.port_url, out, True), log)

            def inside_second_planned_section():
                state = (record_of(live) or {}).get("inspection") or {}
                return (state.get("phase") == "planned" and len(state["sections_done"]) == 1
                        and journal_passes(live) >= 1)
            kill_when(run, inside_second_planned_section,
                      "a pass inside the 2nd planned section", log)
            served_2 = device.passes
        kept_2 = self.kept(live)
        self.assertEqual(record_of(live)["inspection"]["phase"], "planned")
        # The device measured only what the first run had not: its passes up to the kill,
        # and perhaps the one in flight then.
        self.assertIn(served_2 - (kept_2 - kept_1), (0, 1))

        # 3. resumed to the end
        with SimRigDevice(sim_rig(self.nominal)) as device:
            log = os.path.join(self.tmp, "run3.log")
            finish(procs.start(self.inspect_args(device.port_url, out, True), log), log)
            served_3 = device.passes
        self.assertEqual(served_3, self.ref_passes - kept_2)

        self.assertFalse(os.path.exists(live))
        self.assertIsNone(first_difference(read_lines(os.path.join(out, "points.csv")),
                                           self.ref_lines))
        result = read_json(os.path.join(out, "result.json"))
        np.testing.assert_allclose(np.asarray(result["measured_to_cad"]),
                                   np.asarray(self.ref_result["measured_to_cad"]),
                                   rtol=0, atol=1e-9)
        scan = read_json(os.path.join(out, "scan.json"))
        self.assertNotIn("inspection", scan)
        self.assertEqual(
            [(p["section"], p["readings"], p["pass_index"])
             for p in scan["phases"]["planned"]["paths"]],
            [(p["section"], p["readings"], p["pass_index"])
             for p in self.ref_scan["phases"]["planned"]["paths"]])


class TestScanKilled(unittest.TestCase):
    def test_killed_scan_resumes_to_the_uninterrupted_rows(self):
        from BladeInspect.measurement.scan import scan_to_dir
        from BladeInspect.rig.simrig_device import SimRigDevice
        from BladeInspect.rig.serial_rig import SerialRig
        nominal = demo_nominal()
        tmp = tempfile.mkdtemp(prefix="bi-kill-scan-")
        self.addCleanup(shutil.rmtree, tmp, True)
        # The reference: the same simulated rig served on a pty, scanned whole in process.
        with SimRigDevice(sim_rig(nominal)) as device:
            rig = SerialRig(device.port_url, timeout_s=5)
            try:
                scan_to_dir(os.path.join(tmp, "reference"), rig, n_sections=3, seed=SEED)
            finally:
                rig.close()
            total = device.passes
        out = os.path.join(tmp, "killed")
        procs = Processes(self)
        port = start_simrig(procs, os.path.join(tmp, "simrig.log"))
        log = os.path.join(tmp, "scan.log")
        run = procs.start([CLI, "scan", "--rig", "serial:" + port, "--out", out,
                           "--sections", "3", "--seed", str(SEED)], log)

        def inside_second_section():
            record = record_of(out)
            return (record is not None and len(record["sections"]) == 1
                    and journal_passes(out) >= 2)
        kill_when(run, inside_second_section, "a pass inside the 2nd section", log)
        record = record_of(out)
        self.assertFalse(record["complete"])
        kept = record["checkpoint"]["journal_passes"] + journal_passes(out)
        with SimRigDevice(sim_rig(nominal)) as device:
            log = os.path.join(tmp, "resume.log")
            finish(procs.start([CLI, "scan", "--rig", "serial:" + device.port_url, "--out",
                                out, "--sections", "3", "--seed", str(SEED), "--resume"],
                               log), log)
            served = device.passes
        self.assertEqual(served, total - kept)
        self.assertIsNone(first_difference(read_lines(os.path.join(out, "points.csv")),
                                           read_lines(os.path.join(tmp, "reference",
                                                                   "points.csv"))))
        self.assertTrue(record_of(out)["complete"])
        self.assertFalse(os.path.exists(os.path.join(out, JOURNAL_FILE)))
        self.assertEqual(len(read_points(os.path.join(out, "points.csv")).xyz),
                         record_of(out)["points"])


class TestJournal(unittest.TestCase):
    """The journal on its own: what a kill can leave of its last pass, and a resumed scan that
    asks for other passes than those journaled."""

    def setUp(self):
        tmp = tempfile.mkdtemp(prefix="bi-journal-")
        self.addCleanup(shutil.rmtree, tmp, True)
        self.path = os.path.join(tmp, JOURNAL_FILE)
        self.rng = np.random.default_rng(4)
        self.paths = [section_path(self.rng, k, y) for k, y in ((40, 10.0), (25, 20.0),
                                                                  (33, 30.0))]

    def journaled_run(self, n):
        """n passes through a journaled fake rig; returns the readings."""
        from BladeInspect.measurement.journal import JournaledRig
        rig = JournaledRig(FakeSimulatedRig(seed=3), self.path)
        return [rig.scan_path(p, 15.0 * i) for i, p in enumerate(self.paths[:n])]

    def resumed(self, committed):
        from BladeInspect.measurement.journal import JournaledRig
        inner = FakeSimulatedRig(seed=3)
        inner.set_pass_index = lambda i: setattr(inner, "pass_index", i)
        rig = JournaledRig(inner, self.path, keep=True)
        return rig, rig.resume(committed), inner

    def test_replay_gives_back_the_very_readings_then_the_rig_takes_over(self):
        original = self.journaled_run(3)
        with open(self.path, "rb") as fh:
            whole = fh.read()
        # Cut inside the last pass, inside its last line (no newline): a kill mid-write.
        cut = whole.rindex(b"end 2") - 7
        with open(self.path, "wb") as fh:
            fh.write(whole[:cut])
        rig, n_replayed, inner = self.resumed(0)
        self.assertEqual(n_replayed, 2)
        self.assertEqual(os.path.getsize(self.path), whole.index(b"end 1\n") + 6)
        for i, p in enumerate(self.paths):
            got = rig.scan_path(p, 15.0 * i)
            np.testing.assert_array_equal(got.reading_mm, original[i].reading_mm)
            np.testing.assert_array_equal(got.snr, original[i].snr)
        # Two passes replayed, the third measured: the rig was asked once, with pass index 2.
        self.assertEqual(inner.pass_index, 3)
        self.assertEqual(rig.passes, 3)
        self.assertEqual(len(read_journal(self.path)[0]), 3)

    def test_passes_a_checkpoint_holds_are_not_replayed(self):
        self.journaled_run(3)
        rig, n_replayed, inner = self.resumed(2)
        self.assertEqual(n_replayed, 1)
        rig.scan_path(self.paths[2], 30.0)
        self.assertEqual(inner.pass_index, 0)     # replayed, not measured

    def test_another_path_than_journaled_is_refused(self):
        self.journaled_run(2)
        rig, _, _ = self.resumed(0)
        with self.assertRaisesRegex(InputError, "pass 0 was measured along another path"):
            rig.scan_path(self.paths[0] + 0.001, 0.0)

    def test_damage_before_the_last_pass_is_an_error(self):
        self.journaled_run(3)
        with open(self.path, "rb") as fh:
            data = fh.read()
        with open(self.path, "wb") as fh:
            fh.write(data.replace(b"end 0\n", b"end 0 x\n"))
        with self.assertRaisesRegex(InputError, "damaged at byte"):
            read_journal(self.path)


if __name__ == "__main__":
    unittest.main()
