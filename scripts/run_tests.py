"""Test driver run inside FreeCADCmd by ./run-tests: discovers tests/ by path, prints a
plain 'N passed, N failed, N skipped' line and exits non-zero on any failure or error."""
import os
import sys
import time
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class CountingResult(unittest.TextTestResult):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.passed = 0
        self.durations = {}

    def startTest(self, test):
        self._started = time.time()
        super().startTest(test)

    def stopTest(self, test):
        super().stopTest(test)
        module = test.id().rsplit(".", 2)[0]
        self.durations[module] = self.durations.get(module, 0.0) + time.time() - self._started

    def addSuccess(self, test):
        super().addSuccess(test)
        self.passed += 1


def main():
    if REPO not in sys.path:
        sys.path.insert(0, REPO)
    pattern = os.environ.get("BLADEINSPECT_TEST_PATTERN", "test_*.py")
    suite = unittest.TestLoader().discover(os.path.join(REPO, "tests"), pattern=pattern,
                                           top_level_dir=REPO)
    runner = unittest.TextTestRunner(stream=sys.stdout, verbosity=2, resultclass=CountingResult)
    start = time.time()
    result = runner.run(suite)
    failed = len(result.failures) + len(result.errors) + len(result.unexpectedSuccesses)
    print("test time: %.1f s; slowest modules (test bodies, class set-ups not counted):"
          % (time.time() - start))
    for module, seconds in sorted(result.durations.items(), key=lambda kv: -kv[1])[:8]:
        print("  %6.1f s  %s" % (seconds, module))
    print("%d passed, %d failed, %d skipped" % (result.passed, failed, len(result.skipped)),
          flush=True)
    os._exit(1 if failed or result.testsRun == 0 else 0)


if __name__ == "__main__":
    main()
