"""The layer rule, read from the source: every import of every module (at module level or
inside a function) points down core -> cad -> rig -> measurement -> inspection -> app -> gui,
never up; cli.py may import any layer but gui; FreeCADGui and Qt only in gui/; core/ imports no
FreeCAD at all, and every core module imports in a Python where FreeCAD cannot be imported.
rig/, measurement/ and inspection/ import without it too (they reach cad/ inside the functions
that need the CAD). (Init.py and InitGui.py, FreeCAD's own entry points, sit outside the
package and are not read.)

    /usr/bin/python3 tests/test_layers.py ROOT     prints the violations of the checkout ROOT
"""
import ast
import os
import subprocess
import sys
import unittest

LAYERS = ("core", "cad", "rig", "measurement", "inspection", "app", "gui")
PACKAGE = "BladeInspect"
FREECAD_MODULES = ("FreeCAD", "Part", "Mesh", "Points", "FreeCADGui", "PySide", "PySide2",
                   "PySide6", "shiboken2")
GUI_MODULES = ("FreeCADGui", "PySide", "PySide2", "PySide6", "shiboken2")
# The command line may use every layer but the GUI.
CLI_RANK = LAYERS.index("app")


def _modules(root):
    """(dotted module name, file path) of every module of the package under ``root``."""
    base = os.path.join(root, PACKAGE)
    for folder, dirs, files in os.walk(base):
        dirs[:] = sorted(d for d in dirs if not d.startswith((".", "_")))
        for name in sorted(files):
            if name.endswith(".py"):
                rel = os.path.relpath(os.path.join(folder, name), root)[:-3].split(os.sep)
                if rel[-1] == "__init__":
                    rel = rel[:-1]
                yield ".".join(rel), os.path.join(folder, name)


def _imported(module, path, tree):
    """(line, dotted name) of everything the module imports, wherever the import sits."""
    is_package = os.path.basename(path) == "__init__.py"
    here = module.split(".") if is_package else module.split(".")[:-1]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parent = here[:len(here) - (node.level - 1)]
                stem = ".".join(parent + ([node.module] if node.module else []))
            else:
                stem = node.module or ""
            if node.module:
                yield node.lineno, stem
            else:
                for alias in node.names:
                    yield node.lineno, stem + "." + alias.name


def _rank(module):
    """The module's place in LAYERS; the top-level modules (cli, the FreeCAD bootstrap) have
    their own rules and no rank."""
    parts = module.split(".")
    if len(parts) > 1 and parts[1] in LAYERS:
        return LAYERS.index(parts[1])
    return None


def layer_violations(root):
    """One line per import of the checkout at ``root`` that breaks the layer rule."""
    found = []
    for module, path in _modules(root):
        with open(path, encoding="utf-8") as fh:
            tree = ast.parse(fh.read(), path)
        rel = os.path.relpath(path, root)
        mine = _rank(module)
        top_level = module.count(".") == 1
        for line, name in _imported(module, path, tree):
            head = name.split(".")[0]
            where = "%s:%d imports %s" % (rel, line, name)
            if head in FREECAD_MODULES and mine == 0:
                found.append(where + " (core stays free of FreeCAD and Qt)")
            elif head in GUI_MODULES and mine != LAYERS.index("gui"):
                found.append(where + " (FreeCADGui and Qt only in gui/)")
            if head != PACKAGE:
                continue
            target = _rank(name)
            if target is None:
                if name.split(".")[1:2] == ["cli"] and module != PACKAGE + ".cli":
                    found.append(where + " (nothing imports the command line)")
                continue
            if module == PACKAGE + ".cli":
                if target > CLI_RANK:
                    found.append(where + " (cli.py may import any layer but gui)")
            elif top_level or mine is None:
                found.append(where + " (a top-level module imports no layer)")
            elif target > mine:
                found.append(where + " (%s is above %s)" % (LAYERS[target], LAYERS[mine]))
    return found


def function_level_imports(root):
    """How many imports of the package's own modules sit inside functions."""
    count = 0
    for module, path in _modules(root):
        with open(path, encoding="utf-8") as fh:
            tree = ast.parse(fh.read(), path)
        for func in ast.walk(tree):
            if isinstance(func, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for node in ast.walk(func):
                    if isinstance(node, ast.ImportFrom) and (
                            node.level or (node.module or "").startswith(PACKAGE)):
                        count += 1
    return count


# The layers between cad/ and app/ import without FreeCAD (cad/ is imported where a function
# needs the CAD): their lazy imports of cad/ say so.
WITHOUT_FREECAD = ("core", "rig", "measurement", "inspection")

# Run in a fresh interpreter: refuses every FreeCAD module, then imports every module of the
# layers named.
_IMPORT_WITHOUT_FREECAD = r"""
import importlib, importlib.abc, pkgutil, sys
BLOCKED = BLOCKED_MODULES
class Refuse(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ImportError("FreeCAD is not available here: " + name)
sys.meta_path.insert(0, Refuse())
names = []
for layer in sys.argv[1:]:
    package = importlib.import_module("BladeInspect." + layer)
    for m in sorted(pkgutil.iter_modules(package.__path__), key=lambda m: m.name):
        importlib.import_module("BladeInspect.%s.%s" % (layer, m.name))
        names.append("%s.%s" % (layer, m.name))
print(" ".join(names))
"""


class TestLayers(unittest.TestCase):
    def setUp(self):
        from tests.helpers import REPO
        self.root = REPO

    def test_no_import_points_up(self):
        self.assertEqual(layer_violations(self.root), [])

    def test_the_scan_reads_function_level_imports(self):
        """The scan sees an upward import hidden inside a function (independent truth: a
        module written here with one)."""
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            for pkg in ("core", "app", "inspection"):
                os.makedirs(os.path.join(tmp, PACKAGE, pkg))
                open(os.path.join(tmp, PACKAGE, pkg, "__init__.py"), "w").close()
            open(os.path.join(tmp, PACKAGE, "__init__.py"), "w").close()
            with open(os.path.join(tmp, PACKAGE, "inspection", "late.py"), "w") as fh:
                fh.write("import os\n\ndef f():\n    from ..app import objects\n"
                         "    from BladeInspect.core import errors\n")
            with open(os.path.join(tmp, PACKAGE, "core", "gui_peek.py"), "w") as fh:
                fh.write("def g():\n    import FreeCAD\n")
            found = layer_violations(tmp)
        self.assertEqual(len(found), 2, found)
        self.assertIn("inspection/late.py:4 imports BladeInspect.app", found[1])
        self.assertIn("core/gui_peek.py:2 imports FreeCAD", found[0])

    def test_every_module_below_cad_and_app_imports_without_freecad(self):
        proc = subprocess.run(["/usr/bin/python3", "-c",
                               _IMPORT_WITHOUT_FREECAD.replace("BLOCKED_MODULES",
                                                               repr(FREECAD_MODULES))]
                              + list(WITHOUT_FREECAD),
                              cwd=self.root, capture_output=True, text=True)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        # modules and sub-packages (core/airfoil/: its __init__ imports its modules)
        on_disk = ["%s.%s" % (layer, name) for layer in WITHOUT_FREECAD
                   for name in sorted(
                       n[:-3] if n.endswith(".py") else n
                       for n in os.listdir(os.path.join(self.root, PACKAGE, layer))
                       if (n.endswith(".py") and n != "__init__.py") or os.path.isfile(
                           os.path.join(self.root, PACKAGE, layer, n, "__init__.py")))]
        self.assertEqual(proc.stdout.split(), on_disk)


if __name__ == "__main__":
    root = sys.argv[1] if len(sys.argv) > 1 else "."
    violations = layer_violations(root)
    for v in violations:
        print(v)
    print("%d violation(s); %d imports of the package inside functions"
          % (len(violations), function_level_imports(root)))
    sys.exit(1 if violations else 0)
