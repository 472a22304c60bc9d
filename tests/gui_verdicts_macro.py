"""Driven by tests/test_gui_verdicts.py inside a real FreeCAD GUI (under Xvfb), the Combo View
at about 300 px: one inspection of the demo blade at three planned heights, clicked through
Inspect's OK, then Section analysis, Report, the registration's panel and Airfoil analysis
(its OK clicked) on the same inspection. Every panel must name the same sections (the planned
heights) and give the verdict the inspection gave, first and large, with U and TUR per
section, "±" never "+-"; a value the airfoil stage withheld shows as not measured with its
reason and is judged neither pass nor fail. Writes $BI_GUI_OUT/checks.json and screenshots
of each result panel. Not a test module (needs the running GUI)."""
import json
import os
import sys

import FreeCAD
import FreeCADGui as Gui
from PySide import QtGui

sys.path.insert(0, os.environ["BI_REPO"])
from tests.gui_harness import (OUT, ReportWatch, active_panel, check,  # noqa: E402
                               click_ok_and_wait, clipped_headers, run_scenario, settle,
                               start_workbench, step, wait_until)

HEIGHTS = (25.0, 75.0)
NAMES = ["25 %", "75 %"]
WORDS = {"pass": "PASS", "not proven": "NOT PROVEN", "fail": "FAIL"}
COMBO_WIDTH = 300
RESULT_WAIT_S = 5


def open_input_panel(command, kind):
    Gui.runCommand(command)
    settle(0.3)
    return active_panel(kind)


def panel_shot(name):
    """The dock that holds the task view, alone, at the Combo View's width."""
    settle(0.3)
    window = Gui.getMainWindow()
    for dock in window.findChildren(QtGui.QDockWidget):
        if dock.isVisible() and dock.findChild(QtGui.QDialogButtonBox) is not None:
            dock.grab().save(os.path.join(OUT, name + ".png"))
            return dock.width()
    return None


def shown_texts(panel):
    """Every text the panel shows: its labels, text views and table cells and headers."""
    texts = [w.text() for w in panel.form.findChildren(QtGui.QLabel)]
    texts += [w.toPlainText() for w in panel.form.findChildren(QtGui.QTextBrowser)]
    for table in panel.form.findChildren(QtGui.QTableWidget):
        for c in range(table.columnCount()):
            item = table.horizontalHeaderItem(c)
            texts.append(item.text() if item is not None else "")
        texts += [table.item(r, c).text() for r in range(table.rowCount())
                  for c in range(table.columnCount()) if table.item(r, c) is not None]
    return texts


def check_banner(name, panel, word):
    """The verdict on top: the panel's first widget, the word alone, larger than the body."""
    banner = getattr(panel, "verdict_banner", None) if panel is not None else None
    layout = panel.form.layout() if panel is not None else None
    first = layout.itemAt(0).widget() if layout is not None and layout.count() else None
    check(name + ": the verdict is the panel's first line, its word alone",
          banner is not None and first is banner and banner.text() == word,
          (banner.text() if banner is not None else None, word))
    if banner is None:
        return
    body = panel.form.font().pointSizeF()
    check(name + ": the verdict is larger than the body text",
          banner.font().pointSizeF() >= 1.5 * body and banner.font().bold(),
          (banner.font().pointSizeF(), body))
    details = getattr(banner, "details", None)
    detail_text = details.text() if details is not None else ""
    check(name + ": no temporary path or weight model in the verdict's lines",
          not any(s in banner.text() + detail_text for s in ("/tmp", "bladeinspect-", "1/(")),
          (banner.text(), detail_text))


def check_fits(name, panel):
    """The panel no wider than the Combo View: the task view does not scroll sideways (a
    table inside it may)."""
    widget = panel.form if panel is not None else None
    while widget is not None and not isinstance(widget, QtGui.QScrollArea):
        widget = widget.parentWidget()
    bar = widget.horizontalScrollBar() if widget is not None else None
    check(name + ": the panel fits the Combo View's width",
          bar is not None and bar.maximum() == 0,
          (bar.maximum() if bar is not None else None,
           panel.form.width() if panel is not None else None))


def check_no_ascii_plus_minus(name, panel):
    bad = [t for t in shown_texts(panel) if "+-" in t] if panel is not None else ["no panel"]
    check(name + ": '\u00b1', never '+-'", not bad, bad[:3])
    check_fits(name, panel)


def section_column(panel):
    table = panel.table
    return [table.item(r, 0).text() for r in range(table.rowCount())]


def column_of(table, header):
    for c in range(table.columnCount()):
        if table.horizontalHeaderItem(c).text() == header:
            return c
    return None


def check_section_table(name, panel, verdict, exact=False):
    """Table 2's sections named by the planned heights, each with its verdict, U and TUR
    (the verdict's own numbers), readable at the Combo View's width (headers whole, numbers
    whole; a horizontal scroll bar, never a cut)."""
    check(name + ": the sections are the planned heights", panel is not None
          and section_column(panel) == NAMES, panel and section_column(panel))
    if panel is None:
        return
    table = panel.table
    cols = {h: column_of(table, h) for h in ("Verdict", "\u00b1U\nmm", "TUR")}
    check(name + ": verdict, U and TUR columns", None not in cols.values(), cols)
    if None in cols.values():
        return
    rows = [(table.item(r, cols["Verdict"]).text(), table.item(r, cols["\u00b1U\nmm"]).text(),
             table.item(r, cols["TUR"]).text()) for r in range(table.rowCount())]
    expected = [(s.get("verdict"), "%.4f" % s["U_mm"], "%.1f" % s["tur"])
                for s in verdict["sections"]]
    check(name + ": each section's verdict as judged, with its U and TUR",
          [r[0] for r in rows] == [e[0] for e in expected]
          and all(float(r[1]) > 0 and float(r[2]) > 0 for r in rows), (rows, expected))
    if exact:
        check(name + ": U and TUR as result.json's", rows == expected, (rows, expected))
    check(name + ": the headers read whole", not clipped_headers(table),
          clipped_headers(table))
    metrics = table.fontMetrics()
    cut = [(r, c, table.item(r, c).text()) for r in range(table.rowCount())
           for c in range(table.columnCount())
           if metrics.horizontalAdvance(table.item(r, c).text())
           > table.horizontalHeader().sectionSize(c)]
    check(name + ": no cell is cut (the table scrolls sideways instead)", not cut, cut[:4])
    return rows


def close_panel():
    Gui.Control.closeDialog()
    settle(0.3)


def run():
    start_workbench(COMBO_WIDTH)
    from BladeInspect.app import objects
    from BladeInspect.gui import commands, loop_commands, taskpanels
    doc = FreeCAD.newDocument("Verdicts")
    state = {}

    @step("inspect: the verdict first, the planned sections with U and TUR")
    def _():
        blade = state["blade"] = objects.make_demo_blade(doc)
        doc.recompute()
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(blade)
        panel = open_input_panel("BladeInspect_Inspect", loop_commands.InspectPanel)
        check("inspect: input panel open", panel is not None)
        panel.heights.setText(", ".join("%g" % h for h in HEIGHTS))
        panel.airfoil.setChecked(False)
        with ReportWatch() as watch:
            click_ok_and_wait()
            wait_until(lambda: active_panel(taskpanels.TablePanel) is not None, RESULT_WAIT_S)
        result = active_panel(taskpanels.TablePanel)
        check("inspect: Table 2 open after OK, no traceback", result is not None
              and not watch.problems(), watch.problems())
        reg = doc.getObject("Inspection")
        check("inspect: the registration records its heights", reg is not None
              and list(reg.InspectionHeights) == list(HEIGHTS))
        if result is None or reg is None:
            return
        with open(os.path.join(reg.InspectionFolder, "result.json")) as fh:
            verdict = json.load(fh)["verdict"]
        state.update(reg=reg, verdict=verdict, word=WORDS[verdict["verdict"]])
        check_banner("inspect", result, state["word"])
        state["inspect_rows"] = check_section_table("inspect", result, verdict, exact=True)
        check_no_ascii_plus_minus("inspect", result)
        state["dock_width"] = panel_shot("verdicts_inspect_table2")

    @step("section analysis: the same sections and verdict")
    def _():
        reg = state["reg"]
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(reg)
        close_panel()
        with ReportWatch() as watch:
            Gui.runCommand("BladeInspect_SectionAnalysis")
            wait_until(lambda: active_panel(taskpanels.TablePanel) is not None, 120)
        panel = active_panel(taskpanels.TablePanel)
        check("section analysis: panel open, no traceback",
              panel is not None and not watch.problems(), watch.problems())
        if panel is None:
            return
        check_banner("section analysis", panel, state["word"])
        rows = check_section_table("section analysis", panel, state["verdict"], exact=True)
        check("section analysis: each section's verdict as Inspect's",
              rows is not None and [r[0] for r in rows] == [r[0] for r in
                                                            state["inspect_rows"] or ()],
              (rows, state["inspect_rows"]))
        check_no_ascii_plus_minus("section analysis", panel)
        panel_shot("verdicts_section_analysis")
        close_panel()

    @step("report: the same sections and verdict in result.json")
    def _():
        reg = state["reg"]
        out = os.path.join(OUT, "report")
        commands.ask_directory = lambda title: out
        commands.open_in_browser = lambda path: None
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(reg)
        from BladeInspect.gui import progress
        with ReportWatch() as watch:
            Gui.runCommand("BladeInspect_Report")
            settle(0.5)
            wait_until(lambda: not progress.busy() and os.path.exists(
                os.path.join(out, "result.json")), 300)
        check("report: written, no traceback", os.path.exists(os.path.join(out, "result.json"))
              and not watch.problems(), watch.problems())
        if not os.path.exists(os.path.join(out, "result.json")):
            return
        with open(os.path.join(out, "result.json")) as fh:
            written = json.load(fh)
        sections = written["sections"]
        sections = sections.get("sections", sections) if isinstance(sections, dict) else sections
        check("report: the sections are the planned heights",
              [s["height_pct"] for s in sections] == list(HEIGHTS),
              [s["height_pct"] for s in sections])
        check("report: the inspection's verdict",
              written["verdict"]["verdict"] == state["verdict"]["verdict"]
              and [s.get("verdict") for s in written["verdict"]["sections"]]
              == [s.get("verdict") for s in state["verdict"]["sections"]],
              (written["verdict"]["summary"], state["verdict"]["summary"]))

    @step("registration panel: the verdict under its fit first")
    def _():
        reg = state["reg"]
        close_panel()
        Gui.ActiveDocument.setEdit(reg.Name)
        settle(0.5)
        panel = active_panel(taskpanels.RegistrationPanel)
        check("registration: panel open", panel is not None)
        check_banner("registration", panel, state["word"])
        panel_shot("verdicts_registration")
        if Gui.ActiveDocument.getInEdit():
            Gui.ActiveDocument.resetEdit()
        close_panel()

    def airfoil_of(registration, shot):
        """Airfoil analysis of ``registration``, its OK clicked; the result panel and the
        analysis, or (None, None)."""
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(registration)
        close_panel()
        options = open_input_panel("BladeInspect_Airfoil", taskpanels.AirfoilOptionsPanel)
        check(shot + ": input panel open", options is not None)
        limits = os.path.join(OUT, "limits.csv")
        with open(limits, "w") as fh:
            fh.write("characteristic,section,lower,upper\nchord_mm,all,-0.05,0.05\n"
                     "le_radius_mm,all,-0.03,0.03\nte_radius_mm,all,-0.03,0.03\n"
                     "max_thickness_mm,all,-0.05,0.05\n")
        options.characteristics.setText(limits)
        with ReportWatch() as watch:
            click_ok_and_wait()
            wait_until(lambda: active_panel(taskpanels.AirfoilPanel) is not None,
                       RESULT_WAIT_S)
        panel = active_panel(taskpanels.AirfoilPanel)
        check(shot + ": panel open after OK, no traceback",
              panel is not None and not watch.problems(), watch.problems())
        if panel is None:
            return None, None
        from BladeInspect.app import airfoil_objects
        analysis = airfoil_objects.analysis_of(airfoil_objects.find_analysis(doc))
        word = WORDS.get(analysis["airfoil_verdict"]["verdict"], "NOT JUDGED")
        check_banner(shot, panel, word)
        check_no_ascii_plus_minus(shot, panel)
        # what the stage withheld (null, its reason) is judged neither pass nor fail
        withheld = [row for row in panel.rows if len(row) > 2 and row[9]]
        judged = [(row[0], row[8]) for row in withheld if row[8] in ("pass", "fail")]
        check(shot + ": a withheld value is judged neither pass nor fail", not judged, judged)
        table = panel.table
        shown = [(table.item(r, 3).text(), table.item(r, 3).toolTip())
                 for r in range(table.rowCount()) if len(panel.rows[r]) > 2
                 and panel.rows[r][9]]
        check(shot + ": withheld values read 'not measured', the reason in the tooltip",
              all(t == "not measured" and "needed" in tip for t, tip in shown), shown[:3])
        panel_shot(shot)
        return panel, withheld

    @step("airfoil analysis of the inspection: its planned sections")
    def _():
        panel, _ = airfoil_of(state["reg"], "verdicts_airfoil")
        if panel is None:
            return
        groups = [row[0] for row in panel.rows if len(row) == 2]
        check("airfoil: one group per planned section, named by its height",
              len(groups) == len(NAMES) and all(g.startswith("Section %s: " % n)
                                                for g, n in zip(groups, NAMES)), groups)
        close_panel()

    @step("airfoil analysis of a 20k-point scan: sparse edges withheld, not judged")
    def _():
        from BladeInspect.app import actions
        from BladeInspect.inspection.simulate import simulate_measurement
        blade = state["blade"]
        ps, _, _, _ = simulate_measurement(objects.nominal_of(blade), n_points=20000, seed=5)
        measurement = objects.make_measurement(doc, ps)
        doc.recompute()
        reg = actions.register(doc.Name, measurement.Name, blade.Name, 5)
        panel, withheld = airfoil_of(reg, "verdicts_airfoil_withheld")
        check("airfoil (20k points): the sparse edges' values are withheld", withheld,
              panel and panel.verdict_label.text())
        close_panel()

    check("the Combo View is about %d px wide" % COMBO_WIDTH,
          state.get("dock_width") and abs(state["dock_width"] - COMBO_WIDTH) <= 40,
          state.get("dock_width"))


run_scenario(run)
