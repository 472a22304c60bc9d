"""Driven by tests/test_gui_click.py inside a real FreeCAD GUI (under Xvfb): Register, Airfoil
analysis and Inspect as a user runs them, by a mouse click on the task panel's OK button. After
each, the result panel must be the task view's open dialog with its verdict, and the Report view
must have gained no traceback nor the task view's "Active task dialog found". Writes
$BI_GUI_OUT/checks.json and a screenshot of each result panel. Not a test module (needs the
running GUI)."""
import os
import sys

import FreeCAD
import FreeCADGui as Gui
from PySide import QtGui

sys.path.insert(0, os.environ["BI_REPO"])
from tests.gui_harness import (OUT, ReportWatch, active_panel, check,  # noqa: E402
                               click_ok_and_wait, click_task_button, run_scenario, settle,
                               start_workbench, step, task_button, wait_until,
                               window_shot)

RESULT_WAIT_S = 5


def open_input_panel(command, kind):
    """Run the toolbar command; its input panel, or None."""
    Gui.runCommand(command)
    settle(0.3)
    return active_panel(kind)


def click_ok_expecting(name, kind, shot):
    """Click OK on the open input panel; check the result panel of class ``kind`` is the task
    view's active dialog and the Report view stayed clean; its screenshot ``shot``. Returns the
    result panel or None."""
    from BladeInspect.gui import progress
    with ReportWatch() as watch:
        click_ok_and_wait()
        wait_until(lambda: active_panel(kind) is not None, RESULT_WAIT_S)
    panel = active_panel(kind)
    check(name + ": the result panel is open after OK",
          panel is not None and Gui.Control.activeDialog(),
          (progress.MESSAGES[-1:], watch.new_text[-1500:]))
    check(name + ": no traceback or 'Active task dialog found' in the Report view",
          not watch.problems(), watch.problems())
    if panel is not None:
        window_shot(shot)
        task_view_shot(shot + "_panel")
    return panel


def task_view_shot(name):
    """The dock that holds the task view, alone: the result panel as the user guide shows it."""
    window = Gui.getMainWindow()
    for dock in window.findChildren(QtGui.QDockWidget):
        if dock.isVisible() and dock.findChild(QtGui.QDialogButtonBox) is not None:
            dock.grab().save(os.path.join(OUT, name + ".png"))
            return


def close_result():
    """Close the result panel with its Close button; any other dialog as the macro can."""
    if task_button(QtGui.QDialogButtonBox.Close) is not None:
        click_task_button(QtGui.QDialogButtonBox.Close)
    else:
        Gui.Control.closeDialog()
    settle(0.3)


def run():
    start_workbench(560)
    from BladeInspect.app import objects
    from BladeInspect.gui import loop_commands, taskpanels
    from BladeInspect.inspection.simulate import simulate_measurement
    doc = FreeCAD.newDocument("Clicks")
    state = {}

    @step("register: OK shows the registration panel")
    def _():
        blade = objects.make_demo_blade(doc)
        doc.recompute()
        ps, _, _, _ = simulate_measurement(objects.nominal_of(blade), n_points=20000, seed=5)
        objects.make_measurement(doc, ps)
        doc.recompute()
        state["blade"] = blade
        check("register: input panel open",
              open_input_panel("BladeInspect_Register", taskpanels.RegisterPanel) is not None)
        panel = click_ok_expecting("register", taskpanels.RegistrationPanel,
                                   "click_register_result")
        check("register: the panel names the registration and shows its pose",
              panel is not None and panel.form.windowTitle().startswith("Registration: ")
              and "Translation" in panel.text.toPlainText(),
              panel.text.toPlainText()[:400] if panel is not None else None)
        close_result()
        check("register: Close closes the result panel", not Gui.Control.activeDialog())

    @step("airfoil analysis: OK shows the characteristics panel")
    def _():
        options = open_input_panel("BladeInspect_Airfoil", taskpanels.AirfoilOptionsPanel)
        check("airfoil: input panel open", options is not None)
        limits = os.path.join(OUT, "limits.csv")
        with open(limits, "w") as fh:
            fh.write("characteristic,section,lower,upper\nmax_thickness_mm,all,-0.05,0.05\n"
                     "area_mm2,all,0.5,1.0\n")
        options.characteristics.setText(limits)
        panel = click_ok_expecting("airfoil", taskpanels.AirfoilPanel, "click_airfoil_result")
        check("airfoil: the panel shows its table and the airfoil verdict",
              panel is not None and panel.table.rowCount() > 5
              and panel.verdict_label.text().startswith("Airfoil: "),
              panel.verdict_label.text() if panel is not None else None)
        close_result()

    @step("inspect: OK shows Table 2 with the verdict")
    def _():
        for obj in doc.Objects:
            if obj != state["blade"] and obj.ViewObject is not None:
                obj.ViewObject.Visibility = False
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(state["blade"])
        panel = open_input_panel("BladeInspect_Inspect", loop_commands.InspectPanel)
        check("inspect: input panel open", panel is not None)
        check("inspect: the panel names the selected CAD it will inspect against",
              panel is not None and panel.nominal.currentText() == state["blade"].Label
              and panel.nominal.currentData() == state["blade"].Name,
              None if panel is None else panel.nominal.currentText())
        panel.heights.setText("50")
        panel.airfoil.setChecked(False)
        result = click_ok_expecting("inspect", taskpanels.TablePanel, "click_inspect_result")
        labels = [w.text() for w in result.form.findChildren(QtGui.QLabel)] if result else []
        check("inspect: the panel shows Table 2 and the part's verdict",
              result is not None and result.form.windowTitle().startswith("Inspection")
              and result.table.rowCount() == 1
              and any(word in " ".join(labels) for word in ("PASS", "FAIL", "NOT PROVEN")),
              labels)
        close_result()


run_scenario(run)
