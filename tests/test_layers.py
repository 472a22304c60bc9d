"""The layer rule, read from the source: every import of every module (at module level or
inside a function) points down core -> cad -> rig -> measurement -> inspection -> app -> gui,
never up; cli.py may import any layer but gui; FreeCADGui and Qt only in gui/; core/ imports no
FreeCAD at all, and every core module imports in a Python where FreeCAD cannot be imported.
rig/, measurement/ and inspection/ import without it too (they reach cad/ inside the functions
that need the CAD). (Init.py and InitGui.py, FreeCAD's own entry points, sit outside the
package and are not read.)

Within each package no import circle (import_circles: modules of one package importing each
other round a loop, at module level or inside functions; a package's __init__ importing its own
submodules is not one), and no module uses another's private name (private_name_uses:
``from X import _name`` or ``X._name`` on an imported module of the package; dunder names and
a package's private submodules imported within that package excepted).

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


def _parent(module):
    return module.rsplit(".", 1)[0]


def _bindings(module, path, tree, known):
    """(line, module imported, names taken from it, {local name: module} bound by the import)
    of every import of the package's own modules: a name imported from a package that is
    itself a module (``from . import sections``) is that module, imported."""
    is_package = os.path.basename(path) == "__init__.py"
    here = module.split(".") if is_package else module.split(".")[:-1]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name in known:
                    bound = {alias.asname: alias.name} if alias.asname else {}
                    yield node.lineno, alias.name, [], bound
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                stem = ".".join(here[:len(here) - (node.level - 1)]
                                + ([node.module] if node.module else []))
            else:
                stem = node.module or ""
            names = []
            for alias in node.names:
                sub = stem + "." + alias.name
                if sub in known:
                    yield node.lineno, sub, [], {alias.asname or alias.name: sub}
                else:
                    names.append(alias.name)
            if names and stem in known:
                yield node.lineno, stem, names, {}


def _parsed(root):
    """{module: (path, tree)} of the package under ``root``."""
    out = {}
    for module, path in _modules(root):
        with open(path, encoding="utf-8") as fh:
            out[module] = (path, ast.parse(fh.read(), path))
    return out


def _strongly_connected(graph):
    """The strongly connected components of ``graph`` ({node: set of nodes}), Tarjan's."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def import_circles(root):
    """One entry per import circle within a package of the checkout at ``root``: the modules
    round it, then each import that closes it (path:line imports module). An import of a
    deeper module counts as one of the sibling that holds it (importing it runs that
    package's __init__); a package's __init__ importing its own submodules, or a submodule its
    package, is no edge."""
    parsed = _parsed(root)
    known = set(parsed)
    graph, lines = {}, {}
    for module, (path, tree) in parsed.items():
        package = _parent(module)
        for line, target, _, _ in _bindings(module, path, tree, known):
            if not target.startswith(package + "."):
                continue
            sibling = ".".join(target.split(".")[:package.count(".") + 2])
            if sibling == module:
                continue
            graph.setdefault(module, set()).add(sibling)
            lines.setdefault((module, sibling), []).append(
                "%s:%d imports %s" % (os.path.relpath(path, root), line, target))
    found = []
    for component in _strongly_connected(graph):
        if len(component) < 2:
            continue
        members = set(component)
        where = ["  " + text for a in component for b in sorted(graph.get(a, ()))
                 if b in members for text in lines[(a, b)]]
        found.append("import circle in %s: %s\n%s"
                     % (_parent(component[0]),
                        ", ".join(m.rsplit(".", 1)[1] for m in component), "\n".join(where)))
    return found


def _private(name):
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def private_name_uses(root):
    """One line per use of another module's private name in the checkout at ``root``:
    ``from X import _name`` of a module X of the package, or ``m._name`` where m names an
    imported module of the package (dunder names excepted; a private submodule imported from
    within its own package is the package's own)."""
    parsed = _parsed(root)
    known = set(parsed)
    found = []
    for module, (path, tree) in parsed.items():
        rel = os.path.relpath(path, root)
        bound = {}
        for line, target, names, binding in _bindings(module, path, tree, known):
            for name in names:
                if _private(name):
                    found.append("%s:%d imports %s from %s" % (rel, line, name, target))
            for local, sub in binding.items():
                bound[local] = sub
                last = sub.rsplit(".", 1)[1]
                if _private(last) and not (module + ".").startswith(_parent(sub) + "."):
                    found.append("%s:%d imports the private module %s" % (rel, line, sub))
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                    and node.value.id in bound and _private(node.attr) \
                    and bound[node.value.id] != module:
                found.append("%s:%d uses %s.%s" % (rel, node.lineno, bound[node.value.id],
                                                   node.attr))
    # by file and line (the scan meets them in the syntax tree's order)
    return sorted(found, key=lambda text: (text.split(":")[0], int(text.split(":")[1].split()[0])))


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

    def test_no_import_circle_within_a_package(self):
        found = import_circles(self.root)
        self.assertEqual(len(found), 0, "\n" + "\n".join(found))

    def test_no_private_name_of_another_module(self):
        found = private_name_uses(self.root)
        self.assertEqual(len(found), 0, "\n" + "\n".join(found))

    def _tree(self, tmp, files):
        """A package BladeInspect under ``tmp`` with ``files`` ({relative path: text}), every
        folder a package."""
        for rel, text in files.items():
            path = os.path.join(tmp, PACKAGE, rel)
            folder = os.path.dirname(path)
            while not os.path.exists(folder):
                os.makedirs(folder)
            with open(path, "w") as fh:
                fh.write(text)
        for folder, _, names in os.walk(os.path.join(tmp, PACKAGE)):
            if "__init__.py" not in names:
                open(os.path.join(folder, "__init__.py"), "w").close()

    def test_the_scan_finds_a_circle(self):
        """A circle through a function-level import is found and named with its lines; an
        __init__ importing its submodules, which import each other one way, is no circle
        (independent truth: modules written here)."""
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            self._tree(tmp, {
                "inspection/a.py": "from . import b\n",
                "inspection/b.py": "import os\n\ndef f():\n    from .c import g\n",
                "inspection/c.py": "from BladeInspect.inspection import a\n\ng = 1\n",
                "core/kernel/__init__.py": "from .edges import edge\nfrom . import profile\n",
                "core/kernel/edges.py": "from . import profile\nfrom .. import kernel\n"
                                        "edge = 1\n",
                "core/kernel/profile.py": "import numpy\n",
                "core/user.py": "from .kernel import edges\n"})
            found = import_circles(tmp)
        self.assertEqual(len(found), 1, found)
        self.assertTrue(found[0].startswith("import circle in BladeInspect.inspection: a, b, c"),
                        found[0])
        for line in ("inspection/a.py:1 imports BladeInspect.inspection.b",
                     "inspection/b.py:4 imports BladeInspect.inspection.c",
                     "inspection/c.py:1 imports BladeInspect.inspection.a"):
            self.assertIn(line, found[0])

    def test_the_scan_finds_private_names(self):
        """``from X import _name`` and ``module._name`` on an imported module of the package
        are found, function-level too; dunder names, a package's private submodule imported
        within it and names of other libraries are not (independent truth: modules written
        here)."""
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            self._tree(tmp, {
                "core/shapes.py": "_HIDDEN = 1\nSHOWN = 2\n",
                "core/kernel/__init__.py": "from . import _impl\nfrom ._impl import run\n",
                "core/kernel/_impl.py": "def run():\n    return 1\n",
                "inspection/user.py": "from ..core.shapes import _HIDDEN, SHOWN\n"
                                      "from ..core import shapes as sh\n"
                                      "from os import _exit\n\n"
                                      "def f():\n    from ..core import kernel\n"
                                      "    return sh._HIDDEN + sh.__name__ + kernel._impl.run()\n",
                "inspection/clean.py": "from ..core import shapes\nfrom ..core.kernel import run"
                                       "\n\nx = shapes.SHOWN + run() + len(shapes.__file__)\n"})
            found = private_name_uses(tmp)
        self.assertEqual(found, [
            "BladeInspect/inspection/user.py:1 imports _HIDDEN from BladeInspect.core.shapes",
            "BladeInspect/inspection/user.py:7 uses BladeInspect.core.shapes._HIDDEN",
            "BladeInspect/inspection/user.py:7 uses BladeInspect.core.kernel._impl"])

    def test_a_clean_tree_passes_both_scans(self):
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            self._tree(tmp, {
                "core/values.py": "SCALE = 2\n",
                "core/kernel/__init__.py": "from .edges import edge\n",
                "core/kernel/edges.py": "from ..values import SCALE\nedge = SCALE\n",
                "inspection/stage.py": "from . import verdicts\nfrom ..core import kernel\n",
                "inspection/verdicts.py": "def f():\n    from ..core.values import SCALE\n"
                                          "    return SCALE\n"})
            self.assertEqual(import_circles(tmp), [])
            self.assertEqual(private_name_uses(tmp), [])

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
    circles = import_circles(root)
    private = private_name_uses(root)
    for v in violations + circles + private:
        print(v)
    print("%d violation(s); %d import circle(s); %d private name use(s) across modules; "
          "%d imports of the package inside functions"
          % (len(violations), len(circles), len(private), function_level_imports(root)))
    sys.exit(1 if violations or circles or private else 0)
