"""Translation of the workbench's user-visible texts, as FreeCAD's workbenches do it: command
texts are marked with QT_TRANSLATE_NOOP in the command's context (FreeCAD translates them when
it builds the menus); every other text (task panels, dialogs, progress) is translated where it
is shown, with translate(CONTEXT, text). tests/test_gui_strings.py checks that no literal
reaches a widget untranslated."""
import FreeCAD

QT_TRANSLATE_NOOP = FreeCAD.Qt.QT_TRANSLATE_NOOP
translate = FreeCAD.Qt.translate
CONTEXT = "BladeInspect"
