import unittest


class TestSkeleton(unittest.TestCase):
    def test_core_imports_without_freecad(self):
        """Every module of the numerics layer imports in a Python that has no FreeCAD on its
        path, and none of them brings FreeCAD in."""
        import subprocess
        from tests.helpers import REPO
        code = ("import sys, pkgutil, importlib; "
                "sys.path = [p for p in sys.path if 'freecad' not in p.lower()]; "
                "import BladeInspect.core as core; "
                "names = [m.name for m in pkgutil.iter_modules(core.__path__)]; "
                "[importlib.import_module('BladeInspect.core.' + n) for n in names]; "
                "bad = [m for m in ('FreeCAD', 'Part', 'FreeCADGui') if m in sys.modules]; "
                "assert not bad, bad; assert len(names) >= 10, names; print(len(names))")
        proc = subprocess.run(["/usr/bin/python3", "-c", code], cwd=REPO, capture_output=True,
                              text=True)
        self.assertEqual(proc.returncode, 0, proc.stderr)


if __name__ == "__main__":
    unittest.main()
