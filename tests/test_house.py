"""The house's sizes, read from the source: no module of the package over MAX_MODULE_LINES
lines, and no function of the pipeline (inspection/) or the command line (cli.py) taking more
than MAX_PARAMETERS parameters (self and cls not counted, *args and **kwargs one each): a run's
options travel as inspection.run_options.RunOptions, not as keyword lists.

    /usr/bin/python3 tests/test_house.py ROOT     prints what breaks them in the checkout ROOT
"""
import ast
import os
import sys
import tempfile
import unittest

PACKAGE = "BladeInspect"
MAX_MODULE_LINES = 800
MAX_PARAMETERS = 8
# Where the parameter rule holds, relative to the package.
PARAMETER_SCOPES = ("inspection" + os.sep, "cli.py")


def _sources(root):
    base = os.path.join(root, PACKAGE)
    for folder, dirs, files in os.walk(base):
        dirs[:] = sorted(d for d in dirs if not d.startswith((".", "_")))
        for name in sorted(files):
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                yield os.path.relpath(path, base), path


def long_modules(root):
    """'path: N lines' of every module over MAX_MODULE_LINES."""
    found = []
    for rel, path in _sources(root):
        with open(path, encoding="utf-8") as fh:
            n = sum(1 for _ in fh)
        if n > MAX_MODULE_LINES:
            found.append("%s: %d lines" % (rel, n))
    return found


def parameter_count(node):
    a = node.args
    names = [x.arg for x in a.posonlyargs + a.args]
    n = len(names) + len(a.kwonlyargs) + (a.vararg is not None) + (a.kwarg is not None)
    return n - (1 if names and names[0] in ("self", "cls") else 0)


def long_signatures(root):
    """'path:line name() takes N parameters' of every function in PARAMETER_SCOPES over
    MAX_PARAMETERS."""
    found = []
    for rel, path in _sources(root):
        if not rel.startswith(PARAMETER_SCOPES):
            continue
        with open(path, encoding="utf-8") as fh:
            tree = ast.parse(fh.read(), path)
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = parameter_count(node)
                if n > MAX_PARAMETERS:
                    found.append("%s:%d %s() takes %d parameters"
                                 % (rel, node.lineno, node.name, n))
    return found


class TestHouse(unittest.TestCase):
    def setUp(self):
        from tests.helpers import REPO
        self.root = REPO

    def test_no_module_over_the_limit(self):
        found = long_modules(self.root)
        self.assertEqual(found, [], "\n" + "\n".join(found))

    def test_no_long_signature_in_the_pipeline_or_the_command_line(self):
        found = long_signatures(self.root)
        self.assertEqual(found, [], "\n" + "\n".join(found))

    def test_the_scans_find_what_they_look_for(self):
        """On a tree written here (independent truth): a 801-line module, a 9-parameter
        function in inspection/ and in cli.py are found; a method's self, a 9-parameter
        function outside the scopes and an 8-parameter one with *args/**kwargs are not."""
        with tempfile.TemporaryDirectory() as tmp:
            pkg = os.path.join(tmp, PACKAGE)
            os.makedirs(os.path.join(pkg, "inspection"))
            os.makedirs(os.path.join(pkg, "core"))
            nine = "def f(a, b, c, d, e, f, g, h, i):\n    pass\n"
            files = {
                "inspection/long.py": "x = 1\n" * 801,
                "inspection/many.py": nine + "class C:\n    def m(self, a, b, c, d, e, f, g, "
                                             "h):\n        pass\n"
                                             "def k(a, b, c, d, e, f, *args, **kw):\n"
                                             "    pass\n",
                "cli.py": "def main(a, b, c, d, e, f, g, h, *, i=0):\n    pass\n",
                "core/free.py": nine,
            }
            for rel, text in files.items():
                with open(os.path.join(pkg, rel), "w") as fh:
                    fh.write(text)
            self.assertEqual(long_modules(tmp), ["inspection/long.py: 801 lines"])
            self.assertEqual(sorted(long_signatures(tmp)),
                             ["cli.py:1 main() takes 9 parameters",
                              "inspection/many.py:1 f() takes 9 parameters"])


if __name__ == "__main__":
    root = sys.argv[1] if len(sys.argv) > 1 else "."
    found = long_modules(root) + long_signatures(root)
    for line in found:
        print(line)
    print("%d module(s) over %d lines; %d function(s) over %d parameters in inspection/ and "
          "cli.py" % (len(long_modules(root)), MAX_MODULE_LINES, len(long_signatures(root)),
                      MAX_PARAMETERS))
    sys.exit(1 if found else 0)
