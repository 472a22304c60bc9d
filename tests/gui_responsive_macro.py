"""Driven by tests/test_gui_responsive.py inside a real FreeCAD GUI (under Xvfb): Inspect and
Airfoil analysis clicked through while a 100 ms QTimer records how late the event loop answers
in each stage; Inspect cancelled during its report by a mouse click on the status bar's real
Cancel button, then resumed from the Inspect panel to the same result as an uninterrupted run,
with no temporary folder left behind; the deviation map's out-of-tolerance points in their own
colour and size. Writes $BI_GUI_OUT/checks.json (with the lateness per stage under "steps")
and screenshots. Not a test module (needs the running GUI)."""
import glob
import json
import os
import sys
import tempfile
import time

import FreeCAD
import FreeCADGui as Gui
from PySide import QtCore, QtGui

sys.path.insert(0, os.environ["BI_REPO"])
from tests.gui_harness import mouse_click  # noqa: E402
from tests.gui_harness import (OUT, STEPS, ReportWatch, active_panel, check,  # noqa: E402
                               click_ok_and_wait, click_task_button, run_scenario,
                               settle, start_workbench,
                               step, view_shot, wait_until, window_shot)

TICK_MS = 100
# The event loop may answer this late at most while a job runs (the bound).
MAX_LATE_S = 1.0
CANCEL_WITHIN_S = 1.0


class Lateness:
    """A QTimer every TICK_MS recording, per stage (the status bar's message while a job runs),
    the worst lateness of its ticks: how long the event loop could not answer. A wait that
    spans the job's end counts up to that end; what follows it (the document's recompute, the
    result panel) is kept apart under AFTER."""
    AFTER = "after the job: recompute and result panel (not a stage)"

    def __init__(self):
        from BladeInspect.gui import progress
        self.progress = progress
        self.worst = {}
        self.timer = QtCore.QTimer()
        self.timer.setInterval(TICK_MS)
        self.timer.timeout.connect(self.tick)
        self.last = None
        self.stage = None
        self.ended = None
        self.close = progress.StatusProgress.close

        def close(bar):
            self.ended = time.perf_counter()
            return self.close(bar)
        progress.StatusProgress.close = close

    def note(self, stage, late):
        self.worst[stage] = max(self.worst.get(stage, 0.0), late)

    def tick(self):
        now = time.perf_counter()
        if self.last is not None and self.stage is not None:
            end = now
            if self.ended is not None and self.last < self.ended < now:
                end = self.ended
                self.note(self.AFTER, now - self.ended)
            self.note(self.stage, end - self.last - TICK_MS / 1000.0)
        self.ended = None
        self.last = now
        busy = self.progress.busy()
        message = Gui.getMainWindow().statusBar().currentMessage()
        self.stage = (message.split(": ", 1)[-1][:60] or "-") if busy else None

    def __enter__(self):
        self.timer.start()
        return self

    def __exit__(self, *exc):
        self.timer.stop()
        self.progress.StatusProgress.close = self.close

    def max(self):
        return max([v for k, v in self.worst.items() if k != self.AFTER] or [0.0])


def cancel_button():
    for button in Gui.getMainWindow().statusBar().findChildren(QtGui.QPushButton):
        if button.isVisible() and button.text() == "Cancel":
            return button
    return None



def temp_folders():
    return set(glob.glob(os.path.join(tempfile.gettempdir(), "bladeinspect-inspections-*")))


def result_of(registration):
    with open(os.path.join(registration.InspectionFolder, "result.json")) as fh:
        data = json.load(fh)
    return {"verdict": data["verdict"]["summary"], "n_points": data.get("n_points"),
            "pose": [round(v, 9) for row in data["measured_to_cad"] for v in row]}


def inspections(doc):
    return [o for o in doc.Objects if "InspectionFolder" in o.PropertiesList]


def open_inspect(blade):
    from BladeInspect.gui import loop_commands
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(blade)
    Gui.runCommand("BladeInspect_Inspect")
    settle(0.3)
    panel = active_panel(loop_commands.InspectPanel)
    if panel is not None:
        panel.heights.setText("50")
    return panel


def run():
    start_workbench(560)
    from BladeInspect.app import objects
    from BladeInspect.gui import progress, taskpanels
    # The session's temporary folders in a private one: other FreeCAD sessions on this machine
    # make theirs in the system's.
    tempfile.tempdir = os.path.join(OUT, "tmp")
    os.makedirs(tempfile.tempdir)
    doc = FreeCAD.newDocument("Responsive")
    blade = objects.make_demo_blade(doc)
    doc.recompute()
    state = {"before": temp_folders()}

    @step("inspect: the event loop answers in every stage")
    def _():
        check("inspect: input panel open", open_inspect(blade) is not None)
        with Lateness() as lateness, ReportWatch() as watch:
            click_ok_and_wait()
        STEPS["lateness inspect"] = {k: round(v, 3) for k, v in lateness.worst.items()}
        check("inspect: the event loop is never late by more than %g s" % MAX_LATE_S,
              lateness.max() <= MAX_LATE_S, STEPS["lateness inspect"])
        check("inspect: an inspection was made", len(inspections(doc)) == 1,
              (progress.MESSAGES[-1:], watch.new_text[-800:]))
        state["uninterrupted"] = result_of(inspections(doc)[0])
        Gui.Control.closeDialog()
        settle()

    @step("inspect: Cancel during the report answers within a second, resume finishes it")
    def _():
        open_inspect(blade)
        clicked = {}

        def watch_stage():
            # The click is due half a second into the report stage; the answer is timed from
            # then, so a GUI that cannot click until the stage ends is timed as it is.
            message = Gui.getMainWindow().statusBar().currentMessage()
            if "due" not in clicked and "writing the report" in message:
                clicked["due"] = time.perf_counter() + 0.5
            if "due" in clicked and "clicked" not in clicked \
                    and time.perf_counter() >= clicked["due"]:
                button = cancel_button()
                if button is not None:
                    clicked["clicked"] = time.perf_counter()
                    mouse_click(button)
        poll = QtCore.QTimer()
        poll.setInterval(50)
        poll.timeout.connect(watch_stage)
        poll.start()
        click_task_button(QtGui.QDialogButtonBox.Ok)
        wait_until(lambda: "clicked" in clicked, 600)
        wait_until(lambda: not progress.busy(), 60)
        stopped = time.perf_counter()
        poll.stop()
        settle(0.3)
        answer = stopped - clicked.get("due", stopped)
        STEPS["cancel answered s"] = round(answer, 3)
        check("cancel: the click during the report stops the job within %g s" % CANCEL_WITHIN_S,
              "clicked" in clicked and answer <= CANCEL_WITHIN_S, answer)
        check("cancel: the inspection was not added", len(inspections(doc)) == 1)
        said = [m for m in progress.MESSAGES if "Inspect" in m[0]][-1:]
        check("cancel: the message offers the resume from the Inspect panel",
              said and "Resume" in said[0][1] and "--resume" not in said[0][1], said)
        panel = open_inspect(blade)
        resume = getattr(panel, "resume", None)
        check("resume: the Inspect panel offers the interrupted inspection, checked",
              resume is not None and resume.isVisible() and resume.isChecked(),
              resume and resume.text())
        window_shot("responsive_resume_panel")
        with Lateness() as lateness:
            click_ok_and_wait()
        STEPS["lateness resume"] = {k: round(v, 3) for k, v in lateness.worst.items()}
        check("resume: an inspection was made", len(inspections(doc)) == 2,
              progress.MESSAGES[-2:])
        panel = active_panel(taskpanels.TablePanel)
        labels = [w.text() for w in panel.form.findChildren(QtGui.QLabel)] if panel else []
        check("resume: the result panel says the inspection was resumed",
              any("Resumed from the interrupted inspection" in t for t in labels), labels)
        if len(inspections(doc)) == 2:
            resumed = result_of(inspections(doc)[1])
            check("resume: the same verdict, points and pose as the uninterrupted run",
                  resumed == state["uninterrupted"], (resumed, state["uninterrupted"]))
        window_shot("responsive_resumed_inspection")
        Gui.Control.closeDialog()
        settle()
        left = temp_folders() - state["before"]
        check("resume: the two inspections' folders and no other are left", len(left) == 2,
              sorted(left))

    @step("cancel before anything is measured: its temporary folder goes")
    def _():
        before = temp_folders()
        open_inspect(blade)
        clicked = {}

        def at_once():
            button = cancel_button()
            if button is not None and "clicked" not in clicked:
                clicked["clicked"] = True
                mouse_click(button)
        poll = QtCore.QTimer()
        poll.setInterval(20)
        poll.timeout.connect(at_once)
        poll.start()
        click_ok_and_wait()
        poll.stop()
        check("cancel at once: no new temporary folder", temp_folders() - before == set(),
              sorted(temp_folders() - before))

    @step("airfoil analysis: the event loop answers")
    def _():
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(inspections(doc)[0])
        Gui.runCommand("BladeInspect_Airfoil")
        settle(0.3)
        check("airfoil: input panel open",
              active_panel(taskpanels.AirfoilOptionsPanel) is not None)
        with Lateness() as lateness:
            click_ok_and_wait()
        STEPS["lateness airfoil"] = {k: round(v, 3) for k, v in lateness.worst.items()}
        check("airfoil: the event loop is never late by more than %g s" % MAX_LATE_S,
              lateness.max() <= MAX_LATE_S, STEPS["lateness airfoil"])
        Gui.Control.closeDialog()
        settle()

    @step("deviation map: out-of-tolerance points in their own colour and size")
    def _():
        from pivy import coin
        from BladeInspect.core import colourmap
        for obj in doc.Objects:
            if obj.ViewObject is not None:
                obj.ViewObject.Visibility = False
        limit = 0.008
        dmap = objects.make_deviation_map(doc, inspections(doc)[0], limit, name="TightMap")
        doc.recompute()
        dev = list(dmap.Deviation)
        above = [i for i, d in enumerate(dev) if d > limit]
        below = [i for i, d in enumerate(dev) if d < -limit]
        colours = [tuple(round(v, 3) for v in c[:3]) for c in dmap.Color]
        check("map: points beyond +tol have the above colour, beyond -tol the below colour",
              above and below
              and all(colours[i] == tuple(round(v, 3) for v in colourmap.ABOVE_COLOUR)
                      for i in above)
              and all(colours[i] == tuple(round(v, 3) for v in colourmap.BELOW_COLOUR)
                      for i in below), (len(above), len(below)))
        node = getattr(dmap.ViewObject.Proxy, "outliers", None)
        style = node and [node.getChild(i) for i in range(node.getNumChildren())
                          if isinstance(node.getChild(i), coin.SoDrawStyle)]
        coords = node and [node.getChild(i) for i in range(node.getNumChildren())
                           if isinstance(node.getChild(i), coin.SoCoordinate3)]
        check("map: the out-of-tolerance points are drawn again, larger than the others",
              style and coords and style[0].pointSize.getValue() > dmap.ViewObject.PointSize
              and coords[0].point.getNum() == len(above) + len(below),
              (style and style[0].pointSize.getValue(), coords and coords[0].point.getNum()))
        check("map: the legend counts both classes",
              list(dmap.OutOfTolerance) == [len(below), len(above)],
              list(getattr(dmap, "OutOfTolerance", [])))
        dmap.ViewObject.Visibility = True
        settle()
        view_shot("responsive_out_of_tolerance_map")
        window_shot("responsive_out_of_tolerance_window")


run_scenario(run)
