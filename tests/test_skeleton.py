import unittest


class TestSkeleton(unittest.TestCase):
    def test_core_imports_without_freecad(self):
        import subprocess, sys, os
        from tests.helpers import REPO
        # The core layer must import in a Python that has no FreeCAD on its path.
        code = ("import sys; sys.path = [p for p in sys.path if 'freecad' not in p.lower()];"
                "import BladeInspect.core.errors")
        subprocess.run(["/usr/bin/python3", "-c", code], cwd=REPO, check=True)

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
