"""Long work in the GUI: a progress bar and a Cancel button in the status bar, Qt events
processed between the pipeline's progress reports, and every user error shown as a FreeCAD
message (and a non-modal dialog) rather than a traceback.

The work runs in the GUI thread: FreeCAD documents and OpenCASCADE are not thread-safe, and the
pipeline reports progress often enough for the window to stay responsive."""
import traceback

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from ..core.errors import Cancelled, InputError
from .i18n import translate

# Messages shown to the user, newest last: (title, text). Tests read them; dialogs can be off.
MESSAGES = []
LAST_TRACEBACK = [None]
SHOW_DIALOGS = True
_busy = []
_open_boxes = []


def busy():
    """True while a long job runs: commands grey out so none starts inside another."""
    return bool(_busy)


def show_modeless(box):
    """Show a message box without blocking; it is kept referenced until closed (else Python
    collects it and it vanishes)."""
    box.setModal(False)
    box.finished.connect(lambda *_: _open_boxes.remove(box))
    _open_boxes.append(box)
    box.show()


def report_error(title, text):
    MESSAGES.append((title, text))
    FreeCAD.Console.PrintError("BladeInspect: %s: %s\n" % (title, text))
    if SHOW_DIALOGS and FreeCAD.GuiUp:
        box = QtGui.QMessageBox(QtGui.QMessageBox.Warning,
                                translate("BladeInspect", "BladeInspect: %s") % title, text,
                                QtGui.QMessageBox.Ok, FreeCADGui.getMainWindow())
        show_modeless(box)


class StatusProgress:
    """progress(fraction, message) for the pipeline, shown in the main window's status bar."""

    def __init__(self, title):
        self.title = title
        self.cancelled = False
        self.status = FreeCADGui.getMainWindow().statusBar()
        self.bar = QtGui.QProgressBar()
        self.bar.setObjectName("BladeInspectProgress")
        self.bar.setRange(0, 1000)
        self.bar.setMaximumWidth(220)
        self.button = QtGui.QPushButton(translate("BladeInspect", "Cancel"))
        self.button.setToolTip(translate(
            "BladeInspect", "Stop %s; the document keeps what it had before") % title)
        self.button.clicked.connect(self.cancel)
        self.status.addPermanentWidget(self.bar)
        self.status.addPermanentWidget(self.button)
        self.messages = []
        self.show(0.0, translate("BladeInspect", "starting"))

    def cancel(self):
        self.cancelled = True

    def show(self, fraction, message):
        self.bar.setValue(int(round(1000 * min(max(fraction, 0.0), 1.0))))
        self.messages.append((fraction, message))
        self.status.showMessage("%s: %s" % (self.title, message))
        QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)

    def __call__(self, fraction, message):
        self.show(fraction, message)
        if self.cancelled:
            raise Cancelled("%s cancelled" % self.title)

    def close(self):
        self.status.removeWidget(self.bar)
        self.status.removeWidget(self.button)
        self.bar.setParent(None)
        self.button.setParent(None)


def run(title, job):
    """job(progress) with status-bar progress and cancel; returns its value, or None when it was
    cancelled or failed (the failure already reported to the user)."""
    progress = StatusProgress(title)
    _busy.append(title)
    try:
        value = job(progress)
        progress.status.showMessage(translate("BladeInspect", "%s: done") % title, 5000)
        return value
    except Cancelled:
        FreeCAD.Console.PrintWarning(
            translate("BladeInspect", "BladeInspect: %s cancelled") % title + "\n")
        MESSAGES.append((title, "cancelled"))
        progress.status.showMessage(translate("BladeInspect", "%s: cancelled") % title, 5000)
    except InputError as exc:
        report_error(title, str(exc))
    except Exception as exc:
        # A bug, not bad input: one line to the user, the traceback to the log for a report.
        LAST_TRACEBACK[0] = traceback.format_exc()
        FreeCAD.Console.PrintLog(LAST_TRACEBACK[0])
        report_error(title, translate("BladeInspect", "internal error: %s: %s (details in the "
                                                     "report view's log)")
                     % (type(exc).__name__, exc))
    finally:
        _busy.remove(title)
        progress.close()
    return None
