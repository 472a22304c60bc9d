import unittest


class TestSkeleton(unittest.TestCase):
    def test_core_imports_without_freecad(self):
        import subprocess, sys, os
        from tests.helpers import REPO
        # The core layer must import in a Python that has no FreeCAD on its path.
        code = ("import sys; sys.path = [p for p in sys.path if 'freecad' not in p.lower()];"
                "import BladeInspect.core.errors")
        subprocess.run(["/usr/bin/python3", "-c", code], cwd=REPO, check=True)


if __name__ == "__main__":
    unittest.main()
