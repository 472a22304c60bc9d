"""Long work in the GUI: a progress bar and a Cancel button in the status bar, Qt events
processed between the pipeline's progress reports, and every user error shown as a FreeCAD
message (and a non-modal dialog) rather than a traceback.

The work runs in the GUI thread, since FreeCAD documents, Coin and OpenCASCADE are not
thread-safe; its long pure computations (the report's pages, the airfoil characteristics'
draws, the final fit: numpy, scipy and matplotlib only) go to a worker thread through
core.background while this module's waiter keeps the event loop turning, so the window
redraws and Cancel answers within a fraction of a second in every stage."""
import threading
import time
import traceback

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from ..core import background
from ..core.errors import Cancelled, InputError
from .i18n import translate

# Messages shown to the user, newest last: (title, text). Tests read them; dialogs can be off.
MESSAGES = []
LAST_TRACEBACK = [None]
SHOW_DIALOGS = True
_busy = []
_open_boxes = []
# How long a cancelled worker is given to reach its next check before the job is dropped, s.
CANCEL_GRACE_S = 0.3
# The event loop's turn in a long loop of the GUI thread comes after this long, s.
PUMP_S = 0.05


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


def report_note(title, text):
    """A message the user should read that is not an error (what a cancel left, how to go on)."""
    _report(title, text, FreeCAD.Console.PrintWarning, QtGui.QMessageBox.Information)


def report_error(title, text):
    _report(title, text, FreeCAD.Console.PrintError, QtGui.QMessageBox.Warning)


def _report(title, text, console, icon):
    MESSAGES.append((title, text))
    console("BladeInspect: %s: %s\n" % (title, text))
    if SHOW_DIALOGS and FreeCAD.GuiUp:
        box = QtGui.QMessageBox(icon, translate("BladeInspect", "BladeInspect: %s") % title,
                                text, QtGui.QMessageBox.Ok, FreeCADGui.getMainWindow())
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
        self.gui_thread = threading.current_thread()
        self._pending = None    # the latest report from a worker thread, shown by wait_for
        self._pumped = time.perf_counter()
        self.show(0.0, translate("BladeInspect", "starting"))

    def cancel(self):
        self.cancelled = True

    def pump(self):
        """core.background's pump: the event loop turned if it waited PUMP_S, and a cancel
        raised, from the long loops that stay in the GUI thread."""
        if threading.current_thread() is not self.gui_thread:
            return
        now = time.perf_counter()
        if now - self._pumped >= PUMP_S:
            self._pumped = now
            QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 20)
        if self.cancelled:
            raise Cancelled("%s cancelled" % self.title)

    def wait_for(self, thread, stop):
        """core.background's waiter: the event loop turns (the worker's reports shown) until
        ``thread`` ends; on Cancel the worker is told to stop and the job ends at once."""
        while thread.is_alive():
            QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)
            pending, self._pending = self._pending, None
            if pending is not None:
                self.show(*pending)
            if self.cancelled:
                stop.set()
                thread.join(CANCEL_GRACE_S)
                raise Cancelled("%s cancelled" % self.title)
            thread.join(0.02)

    def show(self, fraction, message):
        self.bar.setValue(int(round(1000 * min(max(fraction, 0.0), 1.0))))
        self.messages.append((fraction, message))
        self.status.showMessage("%s: %s" % (self.title, message))
        QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)
        self._pumped = time.perf_counter()

    def __call__(self, fraction, message):
        if threading.current_thread() is self.gui_thread:
            self.show(fraction, message)
        else:
            self._pending = (fraction, message)   # Qt widgets belong to the GUI thread
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
    previous_waiter = background.set_waiter(progress.wait_for)
    previous_pump = background.set_pump(progress.pump)
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
        background.set_waiter(previous_waiter)
        background.set_pump(previous_pump)
        _busy.remove(title)
        progress.close()
    return None
