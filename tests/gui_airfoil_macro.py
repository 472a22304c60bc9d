"""Driven by tests/test_gui_airfoil.py inside a real FreeCAD GUI (under Xvfb): the fit selector,
the console lines of Register, Section analysis and Airfoil analysis, the fit-sensitivity and
airfoil task panels, the camber lines and edge circles in the 3D view, their save and reopen.
Writes $BI_GUI_OUT/checks.json and screenshots. Not a test module (needs the running GUI)."""
import os
import sys

import FreeCAD
import FreeCADGui as Gui
from PySide import QtGui

sys.path.insert(0, os.environ["BI_REPO"])
from tests.gui_harness import (OUT, active_panel, check, click_ok_and_wait,  # noqa: E402
                               clipped_headers, run_scenario, settle, start_workbench,
                               step, view_shot, window_shot)


class ConsoleLines:
    """The lines the commands send through FreeCADGui.doCommand (what the console shows)."""

    def __enter__(self):
        self.lines, self.do_command = [], Gui.doCommand

        def recorded(line):
            self.lines.append(line)
            return self.do_command(line)
        Gui.doCommand = recorded
        return self.lines

    def __exit__(self, *exc):
        Gui.doCommand = self.do_command


def run():
    start_workbench(560)
    from BladeInspect.app import airfoil_objects, objects
    from BladeInspect.gui import commands, progress, tables, taskpanels, viewproviders
    from BladeInspect.inspection.simulate import simulate_measurement
    doc = FreeCAD.newDocument("Airfoil")
    state = {}

    @step("register with the minimax fit through the panel, as a console line")
    def _():
        blade = objects.make_demo_blade(doc)
        doc.recompute()
        ps, _, _, _ = simulate_measurement(objects.nominal_of(blade), n_points=20000, seed=5)
        meas = objects.make_measurement(doc, ps)
        Gui.runCommand("BladeInspect_Register")
        settle(0.3)
        panel = active_panel(taskpanels.RegisterPanel)
        check("register panel open", panel is not None)
        panel.fit.objective.setCurrentIndex(panel.fit.objective.findText("minimax"))
        window_shot("airfoil_task_panel_register_fit")
        with ConsoleLines() as lines:
            click_ok_and_wait()
            settle()
        calls = [line for line in lines if "BladeInspect.app.actions.register(" in line]
        check("register runs as one console line with the fit", len(calls) == 1
              and "fit='minimax'" in calls[0] and repr(meas.Name) in calls[0], lines)
        regs = objects.find_objects(doc, "BladeInspect::Registration")
        check("registration made with the minimax fit", len(regs) == 1
              and regs[0].Fit == "minimax", (progress.MESSAGES[-1:], progress.LAST_TRACEBACK))
        reg_panel = active_panel(taskpanels.RegistrationPanel)
        check("registration panel shows the fit-sensitivity table",
              reg_panel is not None and reg_panel.sensitivity is not None)
        window_shot("airfoil_task_panel_fit_sensitivity")
        if reg_panel is not None and reg_panel.sensitivity is not None:
            table = reg_panel.sensitivity.findChild(QtGui.QTableWidget)
            check("the fit-sensitivity table does not scroll sideways",
                  table.horizontalScrollBar().maximum() == 0,
                  (table.width(), table.horizontalScrollBar().maximum()))
            check("the fit-sensitivity table's headers read whole at 560 px",
                  not clipped_headers(table), clipped_headers(table))
            # a worst deviation's change is of its size; "*" when it changes side
            wrong, last = [], table.columnCount() - 1
            for r in range(table.rowCount()):
                name = table.item(r, 0)
                if name is None or "Worst deviation" not in name.text():
                    continue
                values = [float(table.item(r, c).text()) for c in range(2, last)]
                sizes = [abs(v) for v in values]
                shown = table.item(r, last).text()
                side = min(values) < 0 < max(values)
                if abs(float(shown.rstrip(" *")) - (max(sizes) - min(sizes))) > 1.5e-4 or \
                        shown.endswith("*") != side:
                    wrong.append((name.text(), values, shown))
            check("the worst deviations' change is of their size, * on a change of side",
                  not wrong, wrong)
        Gui.Control.closeDialog()
        state.update(blade=blade, reg=regs[0])

    @step("section analysis as a console line")
    def _():
        with ConsoleLines() as lines:
            table = commands.BY_NAME["BladeInspect_SectionAnalysis"].analyse(state["reg"])
        check("section analysis runs as a console line", table is not None and any(
            "BladeInspect.app.actions.section_analysis(" in line for line in lines), lines)

    @step("airfoil analysis: panel, console line, table, camber lines and edge circles")
    def _():
        Gui.Selection.clearSelection()
        Gui.runCommand("BladeInspect_Airfoil")
        settle(0.3)
        options = active_panel(taskpanels.AirfoilOptionsPanel)
        check("airfoil options panel open", options is not None)
        # tolerances that give each verdict: the max. thickness well inside its zone, the
        # area's zone away from zero; the demo scan's edge zones hold too few points, so
        # the chord, stagger and LE radius are not measured
        limits = os.path.join(OUT, "limits.csv")
        with open(limits, "w") as fh:
            fh.write("characteristic,section,lower,upper\nchord_mm,all,-0.05,0.05\n"
                     "stagger_deg,all,-0.002,0.002\nle_radius_mm,all,0.05,0.1\n"
                     "max_thickness_mm,all,-0.05,0.05\narea_mm2,all,0.5,1.0\n")
        options.characteristics.setText(limits)
        with ConsoleLines() as lines:
            click_ok_and_wait()
            settle()
        check("airfoil runs as a console line",
              any("BladeInspect.app.actions.airfoil(" in line for line in lines), lines)
        panel = active_panel(taskpanels.AirfoilPanel)
        check("airfoil table panel open", panel is not None,
              (progress.MESSAGES[-1:], progress.LAST_TRACEBACK))
        group = airfoil_objects.find_analysis(doc)
        blocks = airfoil_objects.analysis_of(group)["airfoil"]
        check("table has a row per section and characteristic", panel is not None and
              panel.table.rowCount() == len(panel.rows) > 5 * len(blocks), len(panel.rows))
        if panel is not None:
            table = panel.table
            names = [table.item(r, 0).text() for r in range(table.rowCount())]
            check("characteristics by their names and units, not their keys",
                  "Max. thickness" in names and not any("_mm" in n for n in names)
                  and table.item(names.index("Max. thickness"), 1).text() == "mm", names[:12])
            colours = {table.item(r, tables.VERDICT_COLUMN).text():
                       table.item(r, tables.VERDICT_COLUMN).background().color().name()
                       for r in range(table.rowCount()) if table.columnSpan(r, 0) == 1}
            check("verdict cells coloured", colours.get("pass") == tables.VERDICT_COLOURS[
                "pass"] and colours.get("fail") == tables.VERDICT_COLOURS["fail"], colours)
            check("the characteristics table does not scroll sideways",
                  table.horizontalScrollBar().maximum() == 0,
                  (table.width(), table.horizontalScrollBar().maximum()))
            check("the characteristics table's headers read whole at 560 px",
                  not clipped_headers(table),
                  (clipped_headers(table), table.viewport().width(),
                   [table.horizontalHeader().sectionSize(c)
                    for c in range(table.columnCount())]))
            verdict = airfoil_objects.analysis_of(group)["airfoil_verdict"]
            line = panel.verdict_label.text()
            check("the verdict line names the characteristics as the table does",
                  "Airfoil: " in line and "Section area" in line
                  and not any(k in line for k in ("area_mm2", "le_radius_mm", "chord_mm"))
                  and panel.verdict_label.toolTip() == verdict["summary"]
                  and "area_mm2" in verdict["summary"], (line, verdict["summary"]))
        window_shot("airfoil_task_panel_characteristics")
        Gui.Control.closeDialog()
        kinds = [objects.proxy_type(o) for o in group.Group]
        # (no edge circles where both edges of a measured profile are withheld)
        check("a camber line per section and profile, edge circles where drawn",
              kinds.count(airfoil_objects.CamberLine.Type) >= len(blocks)
              and 0 < kinds.count(airfoil_objects.EdgeCircles.Type)
              <= kinds.count(airfoil_objects.CamberLine.Type), kinds)
        check("each has its view provider", all(
            isinstance(o.ViewObject.Proxy, viewproviders.ViewProviderAirfoilGeometry)
            for o in group.Group))
        for obj in doc.Objects:
            if obj.ViewObject is not None and obj not in group.Group and obj != group:
                obj.ViewObject.Visibility = obj == state["blade"]
        state["blade"].ViewObject.Transparency = 75
        view_shot("airfoil_view_camber_edges")
        view = Gui.activeDocument().activeView()
        view.viewTop()
        view.fitAll()
        view_shot("airfoil_view_camber_edges_top", fit=False)
        # One section close up, along its normal: the camber lines end at the edge circles.
        label = blocks[len(blocks) // 2]["label"]
        for obj in group.Group:
            obj.ViewObject.Visibility = obj.SectionLabel == label
        section = [o for o in group.Group if o.SectionLabel == label]
        Gui.Selection.clearSelection()
        for obj in section:
            Gui.Selection.addSelection(obj)
        view.viewTop()
        Gui.SendMsgToActiveView("ViewSelection")
        Gui.Selection.clearSelection()
        view_shot("airfoil_view_section_close_up", fit=False)
        for obj in group.Group:
            obj.ViewObject.Visibility = True
        state["group"] = group

    @step("camber lines and edge circles survive save and reopen")
    def _():
        path = os.path.join(OUT, "airfoil.FCStd")
        before = {o.Name: (o.Shape.Length, o.InputSignature) for o in state["group"].Group}
        doc.saveAs(path)
        FreeCAD.closeDocument(doc.Name)
        reopened = FreeCAD.openDocument(path)
        after = {n: reopened.getObject(n) for n in before}
        check("every object reopened with its shape and signature", all(
            o is not None and abs(o.Shape.Length - before[n][0]) < 1e-9
            and o.InputSignature == before[n][1] for n, o in after.items()))
        check("reopened objects have their view providers and icons", all(
            isinstance(o.ViewObject.Proxy, viewproviders.ViewProviderAirfoilGeometry)
            and os.path.exists(o.ViewObject.Proxy.getIcon()) for o in after.values()))
        view_shot("airfoil_view_reopened")



run_scenario(run)
