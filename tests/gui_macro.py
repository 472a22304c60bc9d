"""Driven by tests/test_gui.py inside a real FreeCAD GUI (under Xvfb): activates the workbench,
runs its commands, checks objects, colours and panels, saves screenshots, writes a JSON of
its checks to $BI_GUI_OUT/checks.json and exits. Not a test module itself (FreeCAD's GUI must
be running), hence no test_ prefix."""
import json
import os
import sys

import numpy as np

import FreeCAD
import FreeCADGui as Gui
from PySide import QtCore, QtGui

sys.path.insert(0, os.environ["BI_REPO"])
from tests.gui_harness import (OUT, active_panel, check, click_ok_and_wait,  # noqa: E402
                               run_scenario, settle, start_workbench, step, view_shot,
                               window_shot)


def colours_of(obj):
    return np.array(obj.Color)[:, :3]


def run():
    start_workbench(430)
    from BladeInspect.app import objects
    from BladeInspect.gui import commands, progress, viewproviders
    names = [c for c in Gui.listCommands() if c.startswith("BladeInspect_")]
    check("all commands registered", set(commands.MENU) <= set(names), names)
    check("workbench active", Gui.activeWorkbench().name() == "BladeInspectWorkbench",
          Gui.activeWorkbench().name())
    check("scan greyed out without a rig", not commands.BY_NAME["BladeInspect_Scan"].IsActive())
    check("register greyed out without inputs",
          not commands.BY_NAME["BladeInspect_Register"].IsActive())
    doc = FreeCAD.newDocument("Inspection")
    state = {}

    @step("demo blade through its task panel")
    def _():
        Gui.runCommand("BladeInspect_DemoBlade")
        settle(0.5)
        panel = _active_panel()
        check("demo blade task panel open", panel is not None)
        window_shot("task_panel_demo_blade")
        panel.boxes["span"].setValue(60.0)
        # The console (and a recorded macro) sees the lines the command runs: doCommand's.
        console = []
        do_command = Gui.doCommand

        def recorded(line):
            console.append(line)
            return do_command(line)
        Gui.doCommand = recorded
        try:
            click_ok_and_wait()
            settle()
        finally:
            Gui.doCommand = do_command
        blade = objects.find_objects(doc, "BladeInspect::DemoBlade")
        check("demo blade made", len(blade) == 1)
        made = [line for line in console if "objects.make_demo_blade(" in line]
        check("demo blade made through doCommand, shown in the console",
              len(made) == 1 and "span=60.0" in made[0], console)
        import __main__
        check("the console's obj is the demo blade", getattr(__main__, "obj", None) == blade[0])
        check("demo blade has the panel's span",
              abs(blade[0].Shape.BoundBox.ZLength - 60.0) < 1e-6, blade[0].Shape.BoundBox)
        state["blade"] = blade[0]
        check("register still greyed out: a blade but no points",
              not commands.BY_NAME["BladeInspect_Register"].IsActive())
        view_shot("demo_blade")

    @step("load CAD error is a message, not a traceback, and adds nothing")
    def _():
        before = len(doc.Objects)
        commands.ask_open_file = lambda *a: os.path.join(OUT, "missing.step")
        Gui.runCommand("BladeInspect_LoadCad")
        settle()
        check("missing CAD reported", progress.MESSAGES and "no such CAD file"
              in progress.MESSAGES[-1][1], progress.MESSAGES[-1:])
        check("missing CAD adds no object", len(doc.Objects) == before)

    @step("cancel leaves the document as it was")
    def _():
        before = [o.Name for o in doc.Objects]

        def job(p):
            with objects.building(doc, "cancelled"):
                objects.make_measurement(doc, _FakePoints(np.random.rand(20, 3)))
                bars = Gui.getMainWindow().statusBar().findChildren(QtGui.QPushButton)
                [b for b in bars if b.text() == "Cancel"][-1].click()
                p(0.5, "working")
        value = progress.run("Cancel test", job)
        check("cancelled job returns nothing", value is None)
        check("cancel reported", progress.MESSAGES[-1] == ("Cancel test", "cancelled"))
        check("cancel leaves no objects", [o.Name for o in doc.Objects] == before)
        settle()
        check("no progress widgets left", not Gui.getMainWindow().statusBar().findChildren(
            QtGui.QProgressBar, "BladeInspectProgress"))

    @step("import simulated points, register, deviation map")
    def _():
        from BladeInspect.core.pointio import write_points_csv
        from BladeInspect.core import transforms as tf
        from BladeInspect.inspection.simulate import simulate_measurement
        blade = state["blade"]
        nominal = objects.nominal_of(blade)
        ps, truth, info, _ = simulate_measurement(nominal, n_points=2000, seed=3,
                                                  section_heights=())
        path = os.path.join(OUT, "simulated.csv")
        write_points_csv(path, ps.xyz, {"snr": ps.snr})
        commands.ask_open_file = lambda *a: path
        Gui.runCommand("BladeInspect_ImportPoints")
        meas = objects.find_objects(doc, "BladeInspect::Measurement")
        check("points imported", len(meas) == 1 and meas[0].NPoints == len(ps.xyz),
              progress.MESSAGES[-1:])
        meas = meas[0]
        check("register active with blade and points",
              commands.BY_NAME["BladeInspect_Register"].IsActive())
        Gui.Selection.clearSelection()

        def click_cancel():
            buttons = Gui.getMainWindow().statusBar().findChildren(QtGui.QPushButton)
            [b for b in buttons if b.text() == "Cancel"][-1].click()
        QtCore.QTimer.singleShot(0, click_cancel)   # fires at the job's first progress report
        cancelled = commands.BY_NAME["BladeInspect_Register"].register(meas, blade)
        check("registration cancelled by its Cancel button", cancelled is None and
              progress.MESSAGES[-1] == ("Register", "cancelled"), progress.MESSAGES[-1:])
        check("cancelled registration leaves no object",
              not objects.find_objects(doc, "BladeInspect::Registration"))
        Gui.runCommand("BladeInspect_Register")
        settle(0.3)
        from BladeInspect.gui import taskpanels
        register_panel = active_panel(taskpanels.RegisterPanel)
        check("register opens its panel with the fit selector", register_panel is not None
              and register_panel.fit.objective.currentText() == "least-squares")
        check("the fit selector offers the ICP weights, the default first",
              register_panel is not None and
              [register_panel.fit.icp_weights.itemText(k) for k in
               range(register_panel.fit.icp_weights.count())] == ["default", "snr", "sensor"]
              and register_panel.fit.values()["weights"] is None)
        window_shot("task_panel_register")
        click_ok_and_wait()
        regs = objects.find_objects(doc, "BladeInspect::Registration")
        check("registration made", len(regs) == 1, progress.MESSAGES[-1:])
        reg = regs[0]
        error = tf.corner_displacement(objects.matrix_array(reg.MeasuredToCad), truth,
                                       nominal.bbox_corners)
        check("registered pose matches the simulation's truth", error < 0.005, error)
        check("uncertainty stated and consistent", 0 < reg.PoseUncertaintyMm < 0.005
              and error < 5 * reg.PoseUncertaintyMm + 1e-4, (error, reg.PoseUncertaintyMm))
        check("rms near the injected noise",
              abs(reg.RmsMm - info["noise_rms_injected_mm"]) < 0.001,
              (reg.RmsMm, info["noise_rms_injected_mm"]))
        window_shot("task_panel_registration")
        Gui.Control.closeDialog()
        Gui.runCommand("BladeInspect_DeviationMap")
        maps = objects.find_objects(doc, "BladeInspect::DeviationMap")
        check("deviation map of every point", len(maps) == 1 and maps[0].NPoints == reg.NPoints
              and len(maps[0].Color) == reg.NPoints, progress.MESSAGES[-1:])
        blade.ViewObject.Transparency = 60
        view_shot("deviation_map_simulated")
        state["reg"], state["nominal"] = reg, nominal

    @step("section analysis of the registration")
    def _():
        reg = state["reg"]
        table = commands.BY_NAME["BladeInspect_SectionAnalysis"].analyse(reg)
        check("section analysis made", table is not None and len(table.sections) > 0,
              progress.MESSAGES[-1:])
        if table is not None:
            commands.SectionAnalysis.show(table)
            window_shot("task_panel_sections")
            Gui.Control.closeDialog()

    @step("report of the registration")
    def _():
        reg, nominal = state["reg"], state["nominal"]
        import tempfile
        from BladeInspect.core import transforms as tf
        from BladeInspect.inspection import pipeline
        out = os.path.join(OUT, "report")
        # The report is of the stored Registration: registering again would be a second,
        # possibly different answer; and it leaves nothing in the temporary folder.
        registrations = []
        register = pipeline.register
        pipeline.register = lambda *a, **k: registrations.append(a) or register(*a, **k)
        private_tmp = os.path.join(OUT, "report-tmp")
        os.makedirs(private_tmp, exist_ok=True)
        tempdir, tempfile.tempdir = tempfile.tempdir, private_tmp
        try:
            summary = commands.BY_NAME["BladeInspect_Report"].report(reg, out)
        finally:
            pipeline.register = register
            tempfile.tempdir = tempdir
        check("report does not register again", not registrations, len(registrations))
        check("report leaves no temporary files", os.listdir(private_tmp) == [],
              os.listdir(private_tmp))
        check("report written", summary is not None and
              os.path.exists(os.path.join(out, "result.json")),
              (progress.MESSAGES[-1:], progress.LAST_TRACEBACK[0]))
        if summary is not None:
            with open(os.path.join(out, "result.json")) as fh:
                T = np.array(json.load(fh)["measured_to_cad"])
            check("report's pose is the document's", tf.corner_displacement(
                T, objects.matrix_array(reg.MeasuredToCad), nominal.bbox_corners) < 1e-4)
            from BladeInspect.app import registration_fit
            with open(os.path.join(out, "result.json")) as fh:
                weights = json.load(fh).get("weights")
            with open(os.path.join(out, "report.html"), encoding="utf-8") as fh:
                html = fh.read()
            # Points without angle_deg have no beam: the paper's SNR weights, by default.
            check("report names the ICP weights the registration used",
                  weights == registration_fit.weights_record(reg) and weights["model"] == "snr"
                  and "ICP weights: snr" in html, weights)
            doc_path = os.path.join(out, "inspection.FCStd")
            check("report's document written", os.path.exists(doc_path))
            saved = FreeCAD.openDocument(doc_path, hidden=True)
            try:
                files = [getattr(o, "SourceFile", "") for o in saved.Objects]
                check("report's document points at no temporary file",
                      not any(f and (f.startswith(private_tmp) or
                                     os.path.basename(os.path.dirname(f)).startswith(
                                         "bladeinspect-report-")) for f in files), files)
            finally:
                FreeCAD.closeDocument(saved.Name)
            FreeCAD.setActiveDocument(reg.Document.Name)
            Gui.setActiveDocument(reg.Document.Name)

    @step("clear the imported measurement's objects")
    def _():
        for obj in list(doc.Objects):
            if objects.proxy_type(obj) in ("BladeInspect::Measurement",
                                           "BladeInspect::Registration",
                                           "BladeInspect::DeviationMap") or \
                    obj.Name.startswith("SectionProfiles"):
                doc.removeObject(obj.Name)

    @step("simulated rig: connect, scan, reconstruct, register, deviation map, sections")
    def _():
        blade = state["blade"]
        Gui.Selection.clearSelection()
        commands.BY_NAME["BladeInspect_ConnectRig"].connect("sim", 0)
        check("rig connected", commands.RIG.connected, progress.MESSAGES[-1:])
        check("scan active with a rig", commands.BY_NAME["BladeInspect_Scan"].IsActive())
        Gui.runCommand("BladeInspect_Scan")
        settle(0.3)
        panel = _active_panel()
        # Two sections at a coarse point spacing keep the simulated scan to tens of seconds.
        panel.sections.setValue(2)
        panel.point_spacing.setValue(0.5)
        window_shot("task_panel_scan")
        click_ok_and_wait()
        scans = objects.find_objects(doc, "BladeInspect::Measurement")
        check("scan made a measurement", len(scans) == 1, progress.MESSAGES[-1:])
        meas = scans[0]
        check("scan measurement has SNR", len(meas.SNR) == meas.NPoints > 100, meas.NPoints)
        recon = commands.BY_NAME["BladeInspect_Reconstruct"].reconstruct(meas)
        check("reconstruction made", recon is not None and recon.NCurves > 0,
              progress.MESSAGES[-1:])
        reg = commands.BY_NAME["BladeInspect_Register"].register(meas, blade)
        check("registration made", reg is not None, progress.MESSAGES[-1:])
        check("registration rms small", reg.RmsMm < 0.02, reg.RmsMm)
        from BladeInspect.core import transforms as tf
        scan_json = os.path.join(os.path.dirname(meas.SourceFile), "scan.json")
        with open(scan_json) as fh:
            truth = np.array(json.load(fh)["table_to_cad"])
        error = tf.corner_displacement(objects.matrix_array(reg.MeasuredToCad), truth,
                                       objects.nominal_of(blade).bbox_corners)
        check("scan registered onto the rig's true fixture pose", error < 0.02,
              "pose error %.4f mm, stated 1 sigma %.4f mm" % (error, reg.PoseUncertaintyMm))
        check("registration uncertainty stated", 0 < reg.PoseUncertaintyMm < 0.05,
              reg.PoseUncertaintyMm)
        # The rig's readings carry angle_deg: their beam is known, so the sensor weights.
        check("scan registered with the sensor model's weights",
              reg.WeightsUsed.startswith("sensor,"), reg.WeightsUsed)
        commands.Register.show(reg)
        window_shot("task_panel_registration_scan")
        Gui.Control.closeDialog()
        dmap = commands.BY_NAME["BladeInspect_DeviationMap"].make(reg)
        check("deviation map of every point", dmap.NPoints == reg.NPoints)
        state["real_map"] = dmap.Name
        view_shot("deviation_map_scan")
        rows = commands.BY_NAME["BladeInspect_SectionAnalysis"].analyse(reg)
        check("section analysis rows", rows is not None, progress.MESSAGES[-1:])
        if rows:
            commands.SectionAnalysis.show(rows)
            window_shot("task_panel_sections_scan")
            Gui.Control.closeDialog()

    @step("deviation map of a known result, legend, save and reopen")
    def _():
        blade = state["blade"]
        from BladeInspect.core.colourmap import classed_colours
        result = _known_result(blade.Shape)
        reg = objects.make_registration(doc, result, name="KnownRegistration")
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(reg)
        check("deviation map command active", commands.BY_NAME["BladeInspect_DeviationMap"]
              .IsActive())
        Gui.runCommand("BladeInspect_DeviationMap")
        settle()
        dmap = [o for o in objects.find_objects(doc, "BladeInspect::DeviationMap")
                if o.Registration == reg][0]
        limit = dmap.Limit
        check("colours follow deviations", np.allclose(
            colours_of(dmap), classed_colours(result.deviation, limit), atol=1e-6))
        vobj = dmap.ViewObject
        check("display mode Color", vobj.DisplayMode == "Color", vobj.DisplayMode)
        check("legend in the scene", vobj.Proxy.legend is not None)
        for other in doc.Objects:
            if other not in (dmap, blade) and other.ViewObject is not None:
                other.ViewObject.Visibility = False
        blade.ViewObject.Visibility = True
        blade.ViewObject.Transparency = 70
        Gui.Selection.clearSelection()
        view_shot("deviation_map_known")
        path = os.path.join(OUT, "inspection.FCStd")
        doc.saveAs(path)
        name = dmap.Name
        FreeCAD.closeDocument(doc.Name)
        settle()
        doc2 = FreeCAD.openDocument(path)
        settle(0.5)
        dmap2 = doc2.getObject(name)
        check("reopened colours intact", np.allclose(
            colours_of(dmap2), classed_colours(result.deviation, limit), atol=0.5 / 255 + 1e-9))
        check("reopened display mode Color", dmap2.ViewObject.DisplayMode == "Color")
        check("reopened view provider and legend", isinstance(
            dmap2.ViewObject.Proxy, viewproviders.ViewProviderDeviationMap)
            and dmap2.ViewObject.Proxy.legend is not None)
        reg2 = doc2.getObject("KnownRegistration")
        check("reopened pose intact", np.allclose(
            objects.matrix_array(reg2.MeasuredToCad), result.measured_to_cad, atol=1e-12))
        view_shot("deviation_map_reopened")
        Gui.ActiveDocument.setEdit(reg2.Name)
        settle(0.3)
        check("registration panel on double-click", _active_panel() is not None)
        window_shot("task_panel_registration_known")
        Gui.Control.closeDialog()

    @step("preferences page reads and writes the parameters")
    def _():
        from BladeInspect.app import settings
        from BladeInspect.gui.preferences import PreferencesPage
        page = PreferencesPage()
        page.widgets["ToleranceMm"].setValue(0.05)
        page.widgets["Sides"].setValue(1)
        page.saveSettings()
        group = FreeCAD.ParamGet(settings.PARAM_PATH)
        check("tolerance saved", abs(group.GetFloat("ToleranceMm") - 0.05) < 1e-12)
        check("sides saved", group.GetInt("Sides") == 1)
        check("colour limit falls back to tolerance", abs(settings.colour_limit() - 0.05) < 1e-12)
        seen = {}

        def look_and_close():
            dialog = QtGui.QApplication.activeModalWidget()
            if dialog is None:
                return
            seen["title"] = dialog.windowTitle()
            seen["ours"] = bool(dialog.findChildren(QtGui.QDoubleSpinBox, "ToleranceMm"))
            dialog.grab().save(os.path.join(OUT, "preferences.png"))
            dialog.reject()
        QtCore.QTimer.singleShot(1500, look_and_close)
        Gui.runCommand("BladeInspect_Preferences")   # modal: returns when the timer closes it
        settle(0.2)
        check("preferences dialog shows the BladeInspect page", seen.get("ours"), seen)

    check("no tracebacks reached the user", not any(
        "Traceback" in text for _, text in progress.MESSAGES), progress.MESSAGES)


def _active_panel():
    from BladeInspect.gui import taskpanels
    return active_panel((taskpanels.FormPanel, taskpanels.RegistrationPanel))


class _FakePoints:
    def __init__(self, xyz):
        self.xyz, self.snr, self.columns = xyz, None, {}
        self.n_rows_skipped, self.source = 0, "fake"


def _known_result(shape):
    """Points on the blade's faces moved along their normals by a known deviation field
    (a smooth wave over the span, both signs, beyond the colour limit at its peaks)."""
    from BladeInspect.core.stats import deviation_statistics
    from BladeInspect.inspection.result import RegistrationResult
    pts, nrm = [], []
    for face in shape.Faces:
        if "Plane" in type(face.Surface).__name__:
            continue   # hub and tip caps: trimmed planes, their parameter box is not the face
        u0, u1, v0, v1 = face.ParameterRange
        for u in np.linspace(u0, u1, 70):
            for v in np.linspace(v0, v1, 40):
                p = face.valueAt(u, v)
                n = face.normalAt(u, v)
                pts.append((p.x, p.y, p.z))
                nrm.append((n.x, n.y, n.z))
    pts, nrm = np.array(pts), np.array(nrm)
    span = max(pts[:, 2].max() - pts[:, 2].min(), 1.0)
    dev = 0.06 * np.sin(2 * np.pi * pts[:, 2] / span) * np.cos(np.pi * pts[:, 0] / span)
    points = pts + dev[:, None] * nrm
    n = len(points)
    return RegistrationResult(
        measured_to_cad=np.eye(4), points_cad=points, deviation=dev,
        inlier=np.ones(n, bool), closest=pts, normal=nrm, face=np.zeros(n, int),
        snr=None, columns={}, n_rows_skipped=0, rms_mm=float(np.sqrt(np.mean(dev ** 2))),
        pose_covariance=np.eye(6) * 1e-8, center=pts.mean(axis=0), pose_uncertainty_mm=1e-4,
        deviation_stats=deviation_statistics(dev), coarse={}, warnings=[])


run_scenario(run)
