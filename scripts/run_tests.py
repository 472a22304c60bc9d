"""Test driver run inside FreeCADCmd by ./run-tests: finds the modules of tests/ by path, runs
them in BLADEINSPECT_TEST_JOBS worker processes (FreeCADCmd each; default one per core, at most
two), prints a plain 'N passed, N failed, N skipped' line and exits non-zero on any failure or
error, or when no test ran.

Each worker claims the next module not yet claimed (an exclusively created file per module),
so the load balances itself whatever the modules cost; the longest modules are started first.
A worker's verbose lines are relayed as they are written; its failures are printed together at
the end, so that one traceback is never interleaved with the other worker's lines."""
import fnmatch
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TESTS = os.path.join(REPO, "tests")
MAX_JOBS = 2   # the suite's subprocess tests (CLI, GUI, killed runs) load a core of their own


class CountingResult(unittest.TextTestResult):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.passed = 0
        self.durations = {}
        self._last_stop = time.time()

    def stopTest(self, test):
        # From the previous test's end: a module's class and module set-ups count as its own.
        super().stopTest(test)
        now = time.time()
        module = test.id().rsplit(".", 2)[0]
        self.durations[module] = self.durations.get(module, 0.0) + now - self._last_stop
        self._last_stop = now

    def addSuccess(self, test):
        super().addSuccess(test)
        self.passed += 1


def test_modules(pattern):
    """The modules unittest's discovery would load from tests/, longest file first (a cheap,
    deterministic stand-in for a module's cost)."""
    names = [name for name in os.listdir(TESTS)
             if name.endswith(".py") and fnmatch.fnmatch(name, pattern)]
    names.sort(key=lambda name: (-os.path.getsize(os.path.join(TESTS, name)), name))
    return ["tests." + name[:-3] for name in names]


def claim(claims, module):
    try:
        os.close(os.open(os.path.join(claims, module), os.O_CREAT | os.O_EXCL | os.O_WRONLY))
        return True
    except FileExistsError:
        return False


def run_worker(index, claims, modules):
    """Runs every module this worker claims; writes its counts and failures to claims/."""
    # Two workers on two cores: BLAS threads of their own would only contend (core.blas_threads).
    from BladeInspect.core.blas_threads import limit_blas_threads
    limit_blas_threads()
    stream = unittest.runner._WritelnDecorator(sys.stdout)
    result = CountingResult(stream, True, 2)
    loader = unittest.TestLoader()
    result.startTestRun()
    for module in modules:
        if claim(claims, module):
            try:
                suite = loader.loadTestsFromName(module)
            except Exception:   # counted as an error, never skipped
                suite = unittest.FunctionTestCase(lambda: loader.loadTestsFromName(module),
                                                  description="import " + module)
            suite.run(result)
            sys.stdout.flush()
    result.stopTestRun()
    with open(os.path.join(claims, "errors-%d.txt" % index), "w") as fh:
        result.stream = unittest.runner._WritelnDecorator(fh)
        result.printErrors()
    summary = {"passed": result.passed, "run": result.testsRun, "skipped": len(result.skipped),
               "failed": (len(result.failures) + len(result.errors)
                          + len(result.unexpectedSuccesses)),
               "durations": result.durations}
    with open(os.path.join(claims, "summary-%d.json" % index), "w") as fh:
        json.dump(summary, fh)


def relay(logs, offsets):
    """Prints the complete lines the workers have written since the last call."""
    for index, path in enumerate(logs):
        with open(path, "rb") as fh:
            fh.seek(offsets[index])
            chunk = fh.read()
        end = chunk.rfind(b"\n") + 1
        if end:
            sys.stdout.write(chunk[:end].decode("utf-8", "replace"))
            offsets[index] += end
    sys.stdout.flush()


def run_parent(pattern):
    modules = test_modules(pattern)
    jobs = int(os.environ.get("BLADEINSPECT_TEST_JOBS") or min(MAX_JOBS, os.cpu_count() or 1))
    jobs = max(1, min(jobs, len(modules)))
    claims = tempfile.mkdtemp(prefix="bladeinspect-tests-")
    start = time.time()
    bootstrap = ("import sys, runpy; sys.path.insert(0, %r); "
                 "runpy.run_path(%r, run_name='__main__')" % (REPO, os.path.abspath(__file__)))
    workers, logs = [], []
    try:
        for index in range(jobs):
            logs.append(os.path.join(claims, "worker-%d.log" % index))
            env = dict(os.environ, BLADEINSPECT_TEST_WORKER=str(index),
                       BLADEINSPECT_TEST_CLAIMS=claims,
                       BLADEINSPECT_TEST_MODULES=json.dumps(modules))
            with open(logs[-1], "wb") as log:
                workers.append(subprocess.Popen(["freecadcmd", "-c", bootstrap], env=env,
                                                stdout=log, stderr=subprocess.STDOUT,
                                                stdin=subprocess.DEVNULL, cwd=REPO))
        offsets = [0] * jobs
        while any(worker.poll() is None for worker in workers):
            relay(logs, offsets)
            time.sleep(0.5)
        relay(logs, offsets)
        passed = failed = skipped = run = 0
        durations = {}
        for index, worker in enumerate(workers):
            summary_path = os.path.join(claims, "summary-%d.json" % index)
            if not os.path.exists(summary_path):   # the worker died: its log says how
                print("worker %d ended (exit %s) without a summary" % (index, worker.returncode))
                failed += 1
                continue
            with open(summary_path) as fh:
                summary = json.load(fh)
            with open(os.path.join(claims, "errors-%d.txt" % index)) as fh:
                sys.stdout.write(fh.read())
            passed += summary["passed"]
            failed += summary["failed"] + (worker.returncode != 0)
            skipped += summary["skipped"]
            run += summary["run"]
            durations.update(summary["durations"])
        unclaimed = [m for m in modules if not os.path.exists(os.path.join(claims, m))]
        if unclaimed:
            print("modules no worker ran: %s" % ", ".join(unclaimed))
            failed += len(unclaimed)
    finally:
        for worker in workers:
            if worker.poll() is None:
                worker.kill()
        shutil.rmtree(claims, ignore_errors=True)
    print("test time: %.1f s in %d worker(s); slowest modules (set-ups included):"
          % (time.time() - start, jobs))
    for module, seconds in sorted(durations.items(), key=lambda kv: -kv[1])[:10]:
        print("  %6.1f s  %s" % (seconds, module))
    print("%d passed, %d failed, %d skipped" % (passed, failed, skipped), flush=True)
    return 1 if failed or run == 0 else 0


def main():
    if REPO not in sys.path:
        sys.path.insert(0, REPO)
    worker = os.environ.get("BLADEINSPECT_TEST_WORKER")
    if worker is None:
        code = run_parent(os.environ.get("BLADEINSPECT_TEST_PATTERN", "test_*.py"))
    else:
        run_worker(int(worker), os.environ["BLADEINSPECT_TEST_CLAIMS"],
                   json.loads(os.environ["BLADEINSPECT_TEST_MODULES"]))
        code = 0
    sys.stdout.flush()
    os._exit(code)


if __name__ == "__main__":
    main()
