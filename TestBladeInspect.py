"""BladeInspect's tests for FreeCAD's Test workbench and `freecadcmd -t TestBladeInspect`.

The tests live in tests/ and are found by path: FreeCAD puts every addon's folder on sys.path,
so a bare `import tests` could pick up another addon's package."""
import os
import unittest

REPO = os.path.dirname(os.path.abspath(__file__))


def load_tests(loader, standard_tests, pattern):
    suite = loader.discover(os.path.join(REPO, "tests"), pattern=pattern or "test_*.py",
                            top_level_dir=REPO)
    standard_tests.addTests(suite)
    return standard_tests
