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
    print("test time: %.1f s" % (time.time() - start))
    print("%d passed, %d failed, %d skipped" % (result.passed, failed, len(result.skipped)),
          flush=True)
    os._exit(1 if failed or result.testsRun == 0 else 0)


if __name__ == "__main__":
    main()
