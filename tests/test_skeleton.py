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

    def test_every_test_module_runs_all_its_tests_directly(self):
        # A class defined below `unittest.main()` is never run by `python tests/test_x.py`.
        import ast, glob, os
        from tests.helpers import REPO
        for path in sorted(glob.glob(os.path.join(REPO, "tests", "test_*.py"))):
            with open(path) as fh:
                body = ast.parse(fh.read()).body
            last = body[-1]
            with self.subTest(module=os.path.basename(path)):
                self.assertIsInstance(last, ast.If)
                self.assertEqual(ast.unparse(last.test), "__name__ == '__main__'")
                self.assertFalse(any(isinstance(node, ast.If) and ast.unparse(node.test) ==
                                     "__name__ == '__main__'" for node in body[:-1]))


if __name__ == "__main__":
    unittest.main()
