"""A crash under ./bladeinspect is never silent: the Python process is killed by a signal in the
middle of a run, and the wrapper prints one line naming the command, the FreeCAD and Python
versions and the log, exits non-zero, and leaves no result in --out."""
import os
import re
import shutil
import signal
import threading
import subprocess
import sys
import tempfile
import time
import unittest

from tests.helpers import REPO, cli_process, process_state

BLADEINSPECT = os.path.join(REPO, "bladeinspect")
RESULT_FILES = ("result.json", "deviations.csv", "report.html", "report.pdf", "inspection.FCStd")


def _alive(pid):
    """True while ``pid`` runs (a zombie waiting to be reaped counts as ended)."""
    return process_state(pid) not in (None, "Z")


def _kill_if_alive(pid):
    try:
        os.kill(pid, signal.SIGKILL)
    except OSError:
        pass


def _start_simulate(out, tmp):
    """./bladeinspect simulate into ``out``, its log and status files in ``tmp``; stderr piped
    (its progress lines say when the run is inside a stage)."""
    return subprocess.Popen(
        [BLADEINSPECT, "simulate", "--out", out, "--points", "20000", "--seed", "3"],
        cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        env=dict(os.environ, TMPDIR=tmp))


class CrashIsNeverSilent(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="bladeinspect-crash-")
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def _kill_mid_run(self, sig):
        out = os.path.join(self.tmp, "out-%d" % sig)
        wrapper = _start_simulate(out, self.tmp)
        lines = []
        killed = None
        try:
            for line in wrapper.stderr:
                lines.append(line)
                # A progress line: FreeCAD is up and the run is inside a stage.
                if killed is None and re.match(r"\[\s*\d+%\]", line):
                    killed = cli_process(wrapper.pid)
                    self.assertIsNotNone(killed, "no Python child under the wrapper")
                    os.kill(killed, sig)
                    # A child that hangs after its SIGSEGV is the wrapper's to end (10 s,
                    # AHungCrashIsEnded); this timer only keeps a broken wrapper from hanging
                    # the suite: the test then fails on the wrapper's "killed by signal KILL".
                    self.forced = threading.Timer(60.0, _kill_if_alive, (killed,))
                    self.forced.start()
            rc = wrapper.wait(timeout=120)
        finally:
            if getattr(self, "forced", None) is not None:
                self.forced.cancel()
            if wrapper.poll() is None:
                wrapper.kill()
        self.assertIsNotNone(killed, "the run printed no progress: %s" % "".join(lines))
        return out, rc, lines

    def _check(self, sig, how):
        out, rc, lines = self._kill_mid_run(sig)
        self.assertNotEqual(rc, 0)
        last = lines[-1].rstrip("\n")
        self.assertRegex(last, r"^bladeinspect: crashed: 'simulate' %s \(FreeCAD \d+\.\d+(\.\d+)?,"
                         r" Python %d\.%d\.\d+\); no result in .*; log: (\S+)$"
                         % (how, sys.version_info[0], sys.version_info[1]))
        log = last.rsplit("log: ", 1)[1]
        self.assertTrue(os.path.isfile(log), log)
        for name in RESULT_FILES:
            self.assertFalse(os.path.exists(os.path.join(out, name)), name)
        beside = [n for n in os.listdir(os.path.dirname(out)) if n.startswith(".bladeinspect-")]
        self.assertEqual(beside, [], "a private output folder was left beside --out")
        return log

    def test_killing_the_wrapper_ends_the_run(self):
        # ./bladeinspect is what a user or a supervisor kills: its Python child must end with it,
        # SIGKILL included, as it would if the wrapper had exec'd it; SIGTERM is passed on.
        for sig in (signal.SIGKILL, signal.SIGTERM):
            out = os.path.join(self.tmp, "wrapper-%d" % sig)
            wrapper = _start_simulate(out, self.tmp)
            child = None
            try:
                for line in wrapper.stderr:
                    if re.match(r"\[\s*\d+%\]", line):
                        child = cli_process(wrapper.pid)
                        wrapper.send_signal(sig)
                        break
                rest = wrapper.stderr.read()
                rc = wrapper.wait(timeout=60)
            finally:
                if wrapper.poll() is None:
                    wrapper.kill()
            self.assertIsNotNone(child)
            self.assertNotEqual(rc, 0)
            deadline = time.monotonic() + 10
            while _alive(child) and time.monotonic() < deadline:
                time.sleep(0.05)
            self.assertFalse(_alive(child), "the CLI's Python outlived its wrapper (signal %d)"
                             % sig)
            if sig == signal.SIGTERM:
                self.assertRegex(rest.strip().splitlines()[-1],
                                 r"^bladeinspect: crashed: 'simulate' was killed by signal TERM")
            self.assertFalse(os.path.exists(os.path.join(out, "result.json")))

    def test_sigkill(self):
        self._check(signal.SIGKILL, "was killed by signal KILL")

    def test_segfault_turned_into_an_exit_status(self):
        # FreeCAD's own handler turns SIGSEGV into a bare exit status; either way the wrapper
        # reports it, and the log holds the Python stack written by faulthandler.
        log = self._check(signal.SIGSEGV, r"(was killed by signal SEGV|ended with exit status "
                                          r"\d+ without finishing|hung after its fatal error and was ended by the "
                                          r"wrapper 10 s later)")
        with open(log) as fh:
            self.assertIn("Fatal Python error", fh.read())


class AHungCrashIsEnded(unittest.TestCase):
    """FreeCAD's SIGSEGV handler has been seen to hang in a futex after faulthandler wrote the
    Python stack; the wrapper must end such a child rather than hang with it. The hang is made
    here by stopping the child (SIGSTOP: alive, doing nothing) and writing the line faulthandler
    writes into the wrapper's log, as the real crash does."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="bladeinspect-hung-")
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def test_a_child_alive_after_its_logged_crash_is_killed_and_reported(self):
        out = os.path.join(self.tmp, "out")
        wrapper = _start_simulate(out, self.tmp)
        child = None
        stopped_at = None
        lines = []
        try:
            for line in wrapper.stderr:
                lines.append(line)
                if child is None and re.match(r"\[\s*\d+%\]", line):
                    child = cli_process(wrapper.pid)
                    self.assertIsNotNone(child, "no Python child under the wrapper")
                    os.kill(child, signal.SIGSTOP)
                    logs = [n for n in os.listdir(self.tmp)
                            if n.startswith("bladeinspect-") and n.endswith(".log")]
                    self.assertEqual(len(logs), 1, logs)
                    with open(os.path.join(self.tmp, logs[0]), "a") as fh:
                        fh.write("Fatal Python error: Segmentation fault\n")
                    stopped_at = time.monotonic()
                    # Without the wrapper's watchdog the stopped child would hold stderr open
                    # for ever: this ends it so that the test fails instead of hanging.
                    backstop = threading.Timer(45.0, _kill_if_alive, (child,))
                    backstop.start()
                    self.addCleanup(backstop.cancel)
            rc = wrapper.wait(timeout=60)
            waited = time.monotonic() - (stopped_at or 0.0)
        finally:
            if child is not None:
                _kill_if_alive(child)
            if wrapper.poll() is None:
                wrapper.kill()
        self.assertIsNotNone(child, "the run printed no progress: %s" % "".join(lines))
        self.assertFalse(_alive(child), "the hung child outlived its wrapper")
        self.assertNotEqual(rc, 0)
        # The grace is 10 s (the wrapper's crash_grace_s), polled each second.
        self.assertGreaterEqual(waited, 9.0)
        self.assertLess(waited, 40.0)
        self.assertRegex(lines[-1].rstrip("\n"),
                         r"^bladeinspect: crashed: 'simulate' hung after its fatal error and was"
                         r" ended by the wrapper 10 s later \(FreeCAD [^)]*\); no result in .*;"
                         r" log: \S+$")
        self.assertFalse(os.path.exists(os.path.join(out, "result.json")))
        beside = [n for n in os.listdir(self.tmp) if n.startswith(".bladeinspect-")]
        self.assertEqual(beside, [], "a private output folder was left beside --out")


class HelpAndUsageAreNoCrash(unittest.TestCase):
    """argparse ends --help and a usage error with SystemExit: the run finished, it did not
    crash (the wrapper once said 'crashed' after every --help)."""

    def test_help_and_a_usage_error(self):
        for args, status, words in ((["report", "--help"], 0, "usage:"),
                                    (["report", "--no-such-option"], 2, "required")):
            done = subprocess.run([BLADEINSPECT] + args, capture_output=True, text=True,
                                  timeout=120)
            self.assertEqual(done.returncode, status, done.stderr)
            self.assertIn(words, done.stdout + done.stderr)
            self.assertNotIn("crashed", done.stdout + done.stderr)


if __name__ == "__main__":
    unittest.main()
