"""Paths of the workbench's icons and .ui files, found from the package's own location (the
workbench's entry files are executed without __file__)."""
import os

MODULE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ICON_DIR = os.path.join(MODULE_DIR, "resources", "icons")
# BladeInspect.ts (scripts/update-translations) and the translators' BladeInspect_<lang>.qm
TRANSLATIONS_DIR = os.path.join(MODULE_DIR, "resources", "translations")


def icon_path(name):
    """The SVG of a command or object, by its name (e.g. "BladeInspect_Scan")."""
    return os.path.join(ICON_DIR, name + ".svg")
