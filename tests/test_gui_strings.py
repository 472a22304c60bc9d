"""Every user-visible text of the workbench passes through Qt's translation (issue 14 item 8):
an ast scan of BladeInspect/gui (and InitGui.py) for string literals that reach a widget, a
dialog, the status bar, the console or a progress report without translate() or
QT_TRANSLATE_NOOP around them, and for command and panel texts that are not marked. Runs
without FreeCAD (it reads the source)."""
import ast
import os
import re
import unittest

from tests.helpers import REPO

GUI_DIR = os.path.join(REPO, "BladeInspect", "gui")
# Calls whose string arguments the user reads.
SINKS = {"setWindowTitle", "setToolTip", "setText", "setPlaceholderText", "addRow", "addItems",
         "addItem", "QLabel", "QPushButton", "QGroupBox", "QMessageBox", "QTableWidgetItem",
         "setHorizontalHeaderLabels", "showMessage", "PrintMessage", "PrintWarning",
         "PrintError", "report_error", "show_result", "run", "run_action", "getOpenFileName",
         "getSaveFileName", "getExistingDirectory", "ask_open_file", "ask_directory",
         "ask_save_file", "TablePanel", "_show_table", "add_row", "p", "legend_node",
         "InputError"}
# Of these, only some arguments are shown (run_action's second is the action's name).
SHOWN_ARGUMENTS = {"run_action": (0,)}
TRANSLATORS = {"translate", "QT_TRANSLATE_NOOP"}
# Class attributes that are shown: the command's menu text and tooltip, a panel's title.
SHOWN_ATTRIBUTES = {"menu", "tip", "title", "dialog_title", "MenuText", "ToolTip"}
# A literal with no word in it once format fields and the product's name are taken out
# (e.g. "BladeInspect: %s\n", "%.4f mm") has nothing to translate.
FORMAT = re.compile(r"%[-+ #0]*\d*(?:\.\d+)?[a-zA-Z%]|\{[^}]*\}")
UNITS = {"mm", "um", "deg", "arcsec"}
FILE_NAME = re.compile(r"\b\w+\.(?:json|csv|FCStd|html|pdf|png)\b")


def _name(func):
    return func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)


def _has_words(text):
    rest = FILE_NAME.sub(" ", FORMAT.sub(" ", text)).replace("BladeInspect", " ")
    return any(w not in UNITS for w in re.findall(r"[A-Za-z]{2,}", rest))


def _untranslated(node):
    """String constants with words under ``node`` that no translator call encloses."""
    if isinstance(node, ast.Call) and _name(node.func) in TRANSLATORS:
        return []
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node] if _has_words(node.value) else []
    if isinstance(node, (ast.Call, ast.Subscript)):
        # A call or an index inside the argument (os.path.basename(path), summary["out_dir"])
        # computes a value; a call's own sinks are visited as calls of their own.
        return []
    found = []
    for child in ast.iter_child_nodes(node):
        found += _untranslated(child)
    return found


def _modules():
    paths = [os.path.join(GUI_DIR, f) for f in sorted(os.listdir(GUI_DIR)) if f.endswith(".py")]
    return paths + [os.path.join(REPO, "InitGui.py")]


def untranslated_texts(source, path="<source>"):
    """[(path, line, text)] of the user-visible literals of ``source`` left untranslated."""
    tree = ast.parse(source)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and _name(node.func) in SINKS:
            shown = SHOWN_ARGUMENTS.get(_name(node.func))
            args = [a for i, a in enumerate(node.args) if shown is None or i in shown]
            if shown is None:
                args += [k.value for k in node.keywords]
            for arg in args:
                found += [(path, c.lineno, c.value) for c in _untranslated(arg)]
        elif isinstance(node, ast.ClassDef):
            for stmt in node.body:
                if isinstance(stmt, ast.Assign) and any(
                        getattr(t, "id", None) in SHOWN_ATTRIBUTES for t in stmt.targets):
                    found += [(path, c.lineno, c.value) for c in _untranslated(stmt.value)]
    return found


class GuiStringsAreTranslated(unittest.TestCase):
    def test_every_user_visible_literal_goes_through_translate(self):
        found = []
        for path in _modules():
            with open(path) as fh:
                found += untranslated_texts(fh.read(), os.path.relpath(path, REPO))
        self.assertEqual(found, [], "\n".join("%s:%d: %r" % f for f in found))

    def test_the_scan_finds_what_it_must(self):
        # The scan itself, on sources with known answers: it must not pass by finding nothing.
        bad = ('box.setToolTip("Stop the scan")\n'
               'layout.addRow("Seed", spin)\n'
               'progress.run("Register", job)\n'
               'p(0.5, "cutting sections")\n'
               'class C:\n    menu = "Report..."\n')
        self.assertEqual(sorted(t for _, _, t in untranslated_texts(bad)),
                         sorted(["Stop the scan", "Seed", "Register", "cutting sections",
                                 "Report..."]))
        good = ('box.setToolTip(translate("BladeInspect", "Stop the scan"))\n'
                'layout.addRow(translate("BladeInspect", label), spin)\n'
                'box.setSuffix(" mm")\n'
                'FreeCAD.Console.PrintWarning("BladeInspect: %s\\n" % warning)\n'
                'class C:\n    menu = QT_TRANSLATE_NOOP("C", "Report...")\n')
        self.assertEqual(untranslated_texts(good), [])


if __name__ == "__main__":
    unittest.main()
