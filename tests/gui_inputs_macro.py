"""Driven by tests/test_gui_inputs.py inside a real FreeCAD GUI (under Xvfb), the Combo View
at its default width: the input panels as a user meets them. Register names the CAD and the
points it will use, preselected from the selection, and uses them with a second CAD in the
document; OK with bad section heights, a missing or unreadable characteristics file or a
missing rig calibration keeps the panel open with the text and a red error line; Browse fills a
file name; no input panel's label or field is clipped; the preferences page is grouped with a
tooltip on every field; the Help menu opens the user guide. Writes $BI_GUI_OUT/checks.json and
screenshots. Not a test module (needs the running GUI)."""
import os
import sys

import FreeCAD
import FreeCADGui as Gui
from PySide import QtCore, QtGui

sys.path.insert(0, os.environ["BI_REPO"])
from tests.gui_harness import mouse_click as click  # noqa: E402
from tests.gui_harness import (OUT, ReportWatch, active_panel, check,  # noqa: E402
                               click_ok_and_wait, click_task_button, run_scenario, settle,
                               start_workbench, step, wait_until, window_shot)

# FreeCAD's default Combo View width.
COMBO_WIDTH = 230
RESULT_WAIT_S = 5



def open_panel(command, kind):
    Gui.Control.closeDialog()    # what an earlier step left open
    settle(0.1)
    Gui.runCommand(command)
    settle(0.3)
    return active_panel(kind)


def cancel_panel():
    click_task_button(QtGui.QDialogButtonBox.Cancel)
    settle(0.3)


def dock_shot(name):
    """The dock that holds the task view, alone, as the user guide shows a panel."""
    settle(0.3)
    for dock in Gui.getMainWindow().findChildren(QtGui.QDockWidget):
        if dock.isVisible() and dock.findChild(QtGui.QDialogButtonBox) is not None:
            dock.grab().save(os.path.join(OUT, name + ".png"))
            return


def visible_right_edge(widget):
    """The screen x of the right edge of the task view's visible area (the viewport of the
    scroll area the widget sits in), or None when it sits in none."""
    parent = widget.parentWidget()
    while parent is not None and not isinstance(parent, QtGui.QAbstractScrollArea):
        parent = parent.parentWidget()
    if parent is None:
        return None
    viewport = parent.viewport()
    return viewport.mapToGlobal(QtCore.QPoint(viewport.width(), 0)).x()


def clipped(form):
    """[(kind, text, width needed, width had)] of the form's visible labels and fields that do
    not show whole: a label's text (a word-wrapped one: its height for its width), a field
    narrower than its minimum size (a spin box's or combo box's text then clips), a line
    edit's text, a check box's text, and any widget that runs past the right edge of the task
    view's visible area (a sideways scroll)."""
    found = []
    edge = visible_right_edge(form)
    for widget in form.findChildren(QtGui.QWidget):
        try:
            if not widget.isVisible() or widget.width() <= 0:
                continue
            right = widget.mapToGlobal(QtCore.QPoint(widget.width(), 0)).x()
        except RuntimeError:    # a child Qt deleted meanwhile (a combo box's popup parts)
            continue
        metrics = widget.fontMetrics()
        if edge is not None and right > edge + 1:
            found.append(("past the edge", type(widget).__name__, right, edge))
        if isinstance(widget, QtGui.QLabel) and widget.text():
            if widget.wordWrap():
                need = widget.heightForWidth(widget.width())
                if widget.height() < need:
                    found.append(("label height", widget.text(), need, widget.height()))
            else:
                need = max(metrics.horizontalAdvance(line) for line in widget.text().split("\n"))
                if widget.contentsRect().width() < need:
                    found.append(("label", widget.text(), need, widget.width()))
        elif isinstance(widget, (QtGui.QAbstractSpinBox, QtGui.QComboBox, QtGui.QCheckBox,
                                 QtGui.QPushButton)):
            need = widget.minimumSizeHint().width()
            if isinstance(widget, (QtGui.QAbstractSpinBox, QtGui.QCheckBox, QtGui.QPushButton)):
                need = widget.sizeHint().width()
            if widget.width() < need:
                text = widget.text() if hasattr(widget, "text") else widget.currentText()
                found.append((type(widget).__name__, text, need, widget.width()))
        elif isinstance(widget, QtGui.QLineEdit) and type(widget.parentWidget()).__name__ \
                not in ("QAbstractSpinBox", "QSpinBox", "QDoubleSpinBox", "QComboBox"):
            # a line edit of a spin box or combo box is measured with its owner
            need = metrics.horizontalAdvance(widget.text()) + 12
            if widget.text() and not os.path.isabs(widget.text()) and widget.width() < need:
                found.append(("line edit", widget.text(), need, widget.width()))
    return found


def error_lines(panel):
    return [label.text() for label in panel.form.findChildren(QtGui.QLabel, "error")
            if label.isVisible()]


def run():
    start_workbench(COMBO_WIDTH)
    from BladeInspect.app import objects
    from BladeInspect.cad.demo_blade import BladeParams
    from BladeInspect.gui import commands, loop_commands, progress, taskpanels
    from BladeInspect.inspection.simulate import simulate_measurement
    doc = FreeCAD.newDocument("Inputs")
    state = {}

    @step("register: the selected CAD and points are named and used")
    def _():
        blade = objects.make_demo_blade(doc, name="Blade")
        doc.recompute()
        ps, _, _, _ = simulate_measurement(objects.nominal_of(blade), n_points=8000, seed=5)
        meas = objects.make_measurement(doc, ps, name="Scan")
        # a second CAD, newer: a blade of other twist and camber the scan does not fit
        other = objects.make_demo_blade(doc, BladeParams(twist_deg=-15.0, camber_root=0.02,
                                                         camber_tip=0.02), name="OtherBlade")
        other.Label = "Other blade"
        doc.recompute()
        for obj in (meas, other):
            obj.ViewObject.Visibility = False
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(blade)
        Gui.Selection.addSelection(meas)
        panel = open_panel("BladeInspect_Register", taskpanels.RegisterPanel)
        check("register: input panel open", panel is not None)
        check("register: the panel names the selected CAD and points",
              panel.nominal.currentText() == blade.Label
              and panel.measurement.currentText() == meas.Label
              and panel.nominal.count() == 2,
              (panel.nominal.currentText(), panel.measurement.currentText()))
        check("register: 'Allow mismatch' offered, with a tooltip",
              not panel.allow_mismatch.isChecked() and panel.allow_mismatch.toolTip())
        check("register: nothing clipped at %d px" % COMBO_WIDTH, not clipped(panel.form),
              clipped(panel.form))
        dock_shot("inputs_register_panel")
        window_shot("inputs_register_window")
        Gui.Selection.clearSelection()   # what the panel shows is what it uses
        with ReportWatch() as watch:
            click_ok_and_wait()
            wait_until(lambda: active_panel(taskpanels.RegistrationPanel) is not None,
                       RESULT_WAIT_S)
        regs = objects.find_objects(doc, objects.Registration.Type)
        check("register: the registration uses the CAD the panel named",
              len(regs) == 1 and regs[0].Nominal == blade and regs[0].Measurement == meas,
              (progress.MESSAGES[-1:], watch.new_text[-800:]))
        check("register: no traceback in the Report view", not watch.problems(),
              watch.problems())
        state.update(blade=blade, other=other, meas=meas, reg=regs[0] if regs else None)
        Gui.Control.closeDialog()
        settle(0.3)

    @step("register: a mismatch error names the GUI's box, not a command-line option")
    def _():
        # a small scan of the other blade, registered to the first: it does not fit
        ps, _, _, _ = simulate_measurement(objects.nominal_of(state["other"]), n_points=1500,
                                           seed=6)
        small = objects.make_measurement(doc, ps, name="OtherScan")
        small.ViewObject.Visibility = False
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(small)
        panel = open_panel("BladeInspect_Register", taskpanels.RegisterPanel)
        check("register: the newly selected points are preselected",
              panel.measurement.currentText() == small.Label, panel.measurement.currentText())
        panel.nominal.setCurrentIndex(panel.nominal.findText(state["blade"].Label))
        before = len(progress.MESSAGES)
        click_ok_and_wait()
        text = " ".join(m[1] for m in progress.MESSAGES[before:])
        check("register: the mismatch error names 'Allow mismatch', not --allow-mismatch",
              "Allow mismatch" in text and "--allow-mismatch" not in text, text)
        check("register: the error names the CAD it was registered to",
              "does not fit %s" % state["blade"].Label in text, text)
        Gui.Control.closeDialog()
        settle(0.3)

    @step("inspect: bad heights and a missing rig file keep the panel open")
    def _():
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(state["blade"])
        panel = open_panel("BladeInspect_Inspect", loop_commands.InspectPanel)
        check("inspect: input panel open", panel is not None)
        check("inspect: nothing clipped at %d px" % COMBO_WIDTH, not clipped(panel.form),
              clipped(panel.form))
        objects_before = [o.Name for o in doc.Objects]
        for text in ("50,abc", "120"):
            panel.heights.setText(text)
            click_task_button(QtGui.QDialogButtonBox.Ok)
            settle(0.5)
            still = active_panel(loop_commands.InspectPanel)
            check("inspect: OK with heights %r keeps the panel open, the text kept" % text,
                  still is panel and panel.heights.text() == text and not progress.busy(),
                  still)
            check("inspect: heights %r: a red error line under the field" % text,
                  len(error_lines(panel)) == 1 and "Section heights" in error_lines(panel)[0],
                  error_lines(panel))
            if text == "120":
                dock_shot("inputs_error_heights")
        panel.heights.setText("50")
        missing = os.path.join(OUT, "no-such", "RIG.json")
        panel.rig_file.setText(missing)
        click_task_button(QtGui.QDialogButtonBox.Ok)
        settle(0.5)
        check("inspect: a missing rig file keeps the panel open with an error line",
              active_panel(loop_commands.InspectPanel) is panel
              and panel.rig_file.text() == missing
              and any("not found" in line for line in error_lines(panel)),
              error_lines(panel))
        rig = os.path.join(OUT, "RIG.json")
        with open(rig, "w") as fh:
            fh.write("{}")
        asked = []
        commands.ask_open_file = lambda title, filters: asked.append(title) or rig
        click(panel.rig_file.browse_button)
        settle(0.2)
        check("inspect: Browse asks for the rig file and fills the field",
              asked and panel.rig_file.text() == rig and not error_lines(panel),
              (asked, panel.rig_file.text(), error_lines(panel)))
        check("inspect: nothing was added", [o.Name for o in doc.Objects] == objects_before)
        cancel_panel()

    @step("airfoil: a missing or unreadable characteristics file keeps the panel open")
    def _():
        Gui.Selection.clearSelection()
        panel = open_panel("BladeInspect_Airfoil", taskpanels.AirfoilOptionsPanel)
        check("airfoil: input panel open, the registration named",
              panel is not None and panel.registration.currentText() == state["reg"].Label,
              panel.registration.currentText() if panel else None)
        check("airfoil: nothing clipped at %d px" % COMBO_WIDTH, not clipped(panel.form),
              clipped(panel.form))
        bad = os.path.join(OUT, "bad.csv")
        with open(bad, "w") as fh:
            fh.write("name,value\nchord,1\n")
        for path, words in ((os.path.join(OUT, "missing.csv"), "no such"),
                            (bad, "header")):
            panel.characteristics.setText(path)
            click_task_button(QtGui.QDialogButtonBox.Ok)
            settle(0.5)
            check("airfoil: OK with %s keeps the panel open, the text kept"
                  % os.path.basename(path),
                  active_panel(taskpanels.AirfoilOptionsPanel) is panel
                  and panel.characteristics.text() == path and not progress.busy())
            check("airfoil: %s: a red error line saying why" % os.path.basename(path),
                  any(words in line for line in error_lines(panel)), error_lines(panel))
            if words == "no such":
                dock_shot("inputs_error_characteristics")
        good = os.path.join(OUT, "limits.csv")
        with open(good, "w") as fh:
            fh.write("characteristic,section,lower,upper\nmax_thickness_mm,all,-0.05,0.05\n")
        commands.ask_open_file = lambda title, filters: good
        click(panel.characteristics.browse_button)
        settle(0.2)
        check("airfoil: Browse fills the characteristics file and clears the error",
              panel.characteristics.text() == good and not error_lines(panel),
              error_lines(panel))
        cancel_panel()

    @step("the other input panels read whole at the default width")
    def _():
        for command, kind in (("BladeInspect_DemoBlade", taskpanels.DemoBladePanel),
                              ("BladeInspect_ConnectRig", taskpanels.ConnectRigPanel),
                              ("BladeInspect_Calibrate", loop_commands.CalibratePanel),
                              ("BladeInspect_Simulate", loop_commands.SimulatePanel)):
            panel = open_panel(command, kind)
            check("%s: panel open" % command, panel is not None)
            if panel is None:
                continue
            check("%s: nothing clipped at %d px" % (command, COMBO_WIDTH),
                  not clipped(panel.form), clipped(panel.form))
            if kind in (taskpanels.DemoBladePanel, taskpanels.ConnectRigPanel):
                check("%s: a tooltip on every field" % command,
                      all(w.toolTip() for w in panel.errors if w is not panel.form),
                      [type(w).__name__ for w in panel.errors if not w.toolTip()])
            if kind is taskpanels.DemoBladePanel:
                dock_shot("inputs_demo_blade_panel")
            cancel_panel()

    @step("a command without a panel names what it uses")
    def _():
        Gui.Control.closeDialog()
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(state["reg"])
        with ReportWatch() as watch:
            Gui.runCommand("BladeInspect_DeviationMap")
            wait_until(lambda: not progress.busy(), 60)
            settle(0.3)
        check("deviation map: the Report view names the registration it uses",
              "Deviation map uses %s" % state["reg"].Label in watch.new_text
              and not watch.problems(), (watch.new_text[-600:], watch.problems()))

    @step("preferences: grouped, symbols written, a tooltip on every field")
    def _():
        seen = {}

        def look():
            dialog = QtGui.QApplication.activeModalWidget()
            try:
                groups = [g.title() for g in dialog.findChildren(QtGui.QGroupBox)
                          if g.isVisible()]
                boxes = {w.objectName(): w for w in dialog.findChildren(QtGui.QAbstractSpinBox)
                         if w.isVisible()}
                seen["groups"] = groups
                seen["rate"] = boxes["PointsPerSecond"].text() if "PointsPerSecond" in boxes \
                    else None
                seen["untipped"] = [n for n, w in boxes.items() if n and not w.toolTip()]
                seen["labels"] = [w.text() for w in dialog.findChildren(QtGui.QLabel)
                                  if w.isVisible()]
                seen["fields"] = sorted(n for n in boxes if n)
                path = os.path.join(OUT, "inputs_preferences.png")
                dialog.grab().save(path)
            finally:
                dialog.reject()
        QtCore.QTimer.singleShot(1500, look)
        Gui.showPreferences("BladeInspect")
        settle(0.3)
        from BladeInspect.app import settings
        check("preferences: group boxes by topic",
              {"Sensor", "Scan strategy", "Tolerance and colour map"}
              <= set(seen.get("groups", ())), seen.get("groups"))
        check("preferences: every setting shown, each with a tooltip",
              seen.get("fields") == sorted(settings.SETTINGS) and not seen.get("untipped"),
              (seen.get("fields"), seen.get("untipped")))
        labels = " ".join(seen.get("labels", ()))
        check("preferences: \u00b1\u03b4 and \u03b5 written as symbols",
              "\u00b1\u03b4" in labels and "\u03b5" in labels and "+-" not in labels
              and "epsilon" not in labels, labels)
        check("preferences: the rate reads 9000 points/s", seen.get("rate") == "9000 points/s",
              seen.get("rate"))

    @step("help: the Help menu opens the user guide")
    def _():
        actions = [a for menu in Gui.getMainWindow().menuBar().actions()
                   if menu.menu() is not None
                   for a in menu.menu().actions() if a.text() == "BladeInspect user guide"]
        help_menus = [m.text() for m in Gui.getMainWindow().menuBar().actions()
                      if m.menu() is not None and any(
                          a.text() == "BladeInspect user guide" for a in m.menu().actions())]
        check("help: an entry in the Help menu", any("Help" in t for t in help_menus),
              help_menus)
        opened = []
        commands.open_in_browser = opened.append
        if actions:
            actions[0].trigger()
            settle(0.2)
        check("help: it opens docs/user-guide.md",
              len(opened) == 1 and opened[0].endswith(os.path.join("docs", "user-guide.md"))
              and os.path.exists(opened[0]), opened)


run_scenario(run)
