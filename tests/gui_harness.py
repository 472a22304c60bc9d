"""What the GUI macros (tests/gui_macro.py, tests/gui_loop_macro.py) share inside the running
FreeCAD GUI: recorded checks and timed steps, screenshots, and the run that writes
$BI_GUI_OUT/checks.json and exits. Not a test module (needs the running GUI)."""
import gc
import json
import os
import sys
import time
import traceback

import FreeCADGui as Gui
from PySide import QtCore, QtGui

OUT = os.environ["BI_GUI_OUT"]
REPO = os.environ["BI_REPO"]
CHECKS = []
STEPS = {}


def check(name, ok, detail=""):
    CHECKS.append({"name": name, "ok": bool(ok), "detail": str(detail)[:2000]})


def step(name):
    """Run a scenario step, recording its time and any exception (an ImportError of the
    project's own modules included) as a failed check."""
    def wrap(fn):
        t0 = time.time()
        try:
            fn()
            STEPS[name] = {"status": "ran", "seconds": round(time.time() - t0, 2)}
        except Exception:
            STEPS[name] = {"status": "error", "seconds": round(time.time() - t0, 2)}
            check(name + ": no exception", False, traceback.format_exc())
        return fn
    return wrap


def settle(seconds=0.2):
    end = time.time() + seconds
    while time.time() < end:
        QtGui.QApplication.processEvents()
        time.sleep(0.02)


def view_shot(name, fit=True):
    view = Gui.activeDocument().activeView()
    if fit:
        view.viewIsometric()
        view.fitAll()
    settle()
    path = os.path.join(OUT, name + ".png")
    view.saveImage(path, 1000, 750, "Current")
    return path


def window_shot(name):
    """The main window with its task panel. QWidget.grab() leaves the OpenGL 3D view blank, so
    the view is rendered with saveImage and painted into its place."""
    settle(0.3)
    window = Gui.getMainWindow()
    shot = window.grab()
    mdi = window.centralWidget()
    sub = mdi.activeSubWindow() if hasattr(mdi, "activeSubWindow") else None
    if sub is not None and Gui.activeDocument() is not None:
        target = sub.widget()
        origin = target.mapTo(window, QtCore.QPoint(0, 0))
        view_png = os.path.join(OUT, name + "-view.tmp.png")
        Gui.activeDocument().activeView().saveImage(view_png, target.width(), target.height(),
                                                    "Current")
        painter = QtGui.QPainter(shot)
        painter.drawImage(origin, QtGui.QImage(view_png))
        painter.end()
        os.remove(view_png)
    path = os.path.join(OUT, name + ".png")
    shot.save(path)
    return path


def clipped_headers(table):
    """[(column, header text, width its longest line needs, the section's width)] of the
    header labels narrower than their text: the text's advance in the header's font plus the
    style's header margin on both sides (what QHeaderView's own size hint adds), line by
    line. Empty when every header reads whole."""
    header = table.horizontalHeader()
    metrics = header.fontMetrics()
    margin = header.style().pixelMetric(QtGui.QStyle.PM_HeaderMargin, None, header)
    clipped = []
    for c in range(table.columnCount()):
        item = table.horizontalHeaderItem(c)
        text = item.text() if item is not None else ""
        need = max(metrics.horizontalAdvance(line) for line in text.split("\n")) + 2 * margin
        if header.sectionSize(c) < need:
            clipped.append((c, text, need, header.sectionSize(c)))
    return clipped


def active_panel(kinds):
    """The visible task panel of one of these classes, or None."""
    for obj in gc.get_objects():
        if isinstance(obj, kinds) and obj.form.isVisible():
            return obj
    return None


def start_workbench(combo_width):
    """The main window sized for the screenshots (the Combo View ``combo_width`` wide) and the
    workbench active; the repository importable; progress dialogs off (they would wait for a
    click; their messages are checked instead)."""
    sys.path.insert(0, REPO)
    window = Gui.getMainWindow()
    window.resize(1280, 1000)
    # FreeCAD 0.20 has one "Combo View" dock; 1.0 splits it into tabbed "Model" and "Tasks"
    # docks of other names: size every visible dock on the left
    left = [d for d in window.findChildren(QtGui.QDockWidget)
            if d.isVisible() and window.dockWidgetArea(d) == QtCore.Qt.LeftDockWidgetArea]
    if left:
        window.resizeDocks(left, [combo_width] * len(left), QtCore.Qt.Horizontal)
    Gui.activateWorkbench("BladeInspectWorkbench")
    from BladeInspect.gui import progress
    progress.SHOW_DIALOGS = False


def run_scenario(run):
    """Run the scenario once the GUI is up, write the checks and steps, and exit."""
    def main():
        try:
            run()
        except Exception:
            check("scenario ran", False, traceback.format_exc())
        with open(os.path.join(OUT, "checks.json"), "w") as fh:
            json.dump({"checks": CHECKS, "steps": STEPS}, fh, indent=1)
        os._exit(0)
    QtCore.QTimer.singleShot(300, main)
