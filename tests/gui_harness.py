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


def task_button(which=QtGui.QDialogButtonBox.Ok):
    """The visible button ``which`` of the task view's button box (FreeCAD 0.20's Combo View,
    1.0's Tasks), or None."""
    for box in Gui.getMainWindow().findChildren(QtGui.QDialogButtonBox):
        button = box.button(which)
        if button is not None and button.isVisible():
            return button
    return None


def mouse_click(widget):
    """A left mouse press and release at the widget's centre, as a user's click
    (QTest.mouseClick's events; FreeCAD's PySide has no QtTest)."""
    centre = QtCore.QPointF(widget.rect().center())
    for kind, buttons in ((QtCore.QEvent.MouseButtonPress, QtCore.Qt.LeftButton),
                          (QtCore.QEvent.MouseButtonRelease, QtCore.Qt.NoButton)):
        QtGui.QApplication.sendEvent(widget, QtGui.QMouseEvent(
            kind, centre, QtCore.Qt.LeftButton, buttons, QtCore.Qt.NoModifier))


def click_task_button(which=QtGui.QDialogButtonBox.Ok):
    """Click the task panel's button as a user does: a left mouse press and release at its
    centre (QTest.mouseClick's events; FreeCAD's PySide has no QtTest), so FreeCAD's task view
    calls the panel's accept() or reject() the way it does for a user."""
    button = task_button(which)
    if button is None:
        raise AssertionError("the task view shows no %r button" % which)
    mouse_click(button)


def wait_until(condition, timeout_s):
    """Run the event loop until condition() holds or timeout_s passed; condition()'s value."""
    end = time.time() + timeout_s
    while not condition() and time.time() < end:
        QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)
        time.sleep(0.02)
    return condition()


def click_ok_and_wait(timeout_s=600):
    """Click the task panel's OK, then run the event loop until the command's work is done
    (no job running, no event left to start one)."""
    from BladeInspect.gui import progress
    click_task_button(QtGui.QDialogButtonBox.Ok)
    settle(0.3)
    wait_until(lambda: not progress.busy(), timeout_s)
    settle(0.3)


def report_view_text():
    """The text of the Report view (FreeCAD's console messages, errors and tracebacks)."""
    texts = [w.toPlainText() for w in Gui.getMainWindow().findChildren(QtGui.QTextEdit)
             if "report" in w.objectName().lower()]
    return "\n".join(texts)


class ReportWatch:
    """What the Report view gained, and the Python exceptions nobody caught (a Qt slot's go to
    sys.excepthook), while the block ran: ``new_text``, ``exceptions``."""

    def __enter__(self):
        self.before = report_view_text()
        self.exceptions = []
        self.hook = sys.excepthook

        def hook(kind, value, tb):
            self.exceptions.append("".join(traceback.format_exception(kind, value, tb)))
            self.hook(kind, value, tb)
        sys.excepthook = hook
        return self

    def __exit__(self, *exc):
        sys.excepthook = self.hook
        after = report_view_text()
        self.new_text = after[len(self.before):] if after.startswith(self.before) else after

    def problems(self):
        """The lines a user must not see after a working command: a traceback, the task
        view's refusal or a shape the 3D view cannot draw, with every uncaught exception."""
        bad = [line for line in self.new_text.splitlines()
               if "Traceback" in line or "Active task dialog found" in line
               or "Cannot compute Inventor representation" in line
               or "Error" in line.split(":")[0]]
        return bad + self.exceptions


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
