"""Driven by tests/test_gui_loop.py inside a real FreeCAD GUI (under Xvfb): the closed-loop
commands (Inspect, Calibrate, Add CMM file, Simulation test bed) on the demo blade with the
simulated rig. Every check compares with something the pipeline did not compute: OpenCASCADE's
own distances to the blade, the section planes from the blade's bounding box, the simulator's
truth. Writes $BI_GUI_OUT/checks.json and exits. Not a test module (needs the running GUI)."""
import json
import os
import sys
import time

import numpy as np

import FreeCAD
import FreeCADGui as Gui
from PySide import QtCore, QtGui

sys.path.insert(0, os.environ["BI_REPO"])
from tests.gui_harness import (OUT, active_panel, check, click_ok_and_wait,  # noqa: E402
                               run_scenario, settle, start_workbench, step, view_shot, window_shot)

HEIGHTS = (20.0, 50.0, 80.0)


def occ_distances(shape, points):
    """OpenCASCADE's own distance from each point to the shape (independent of the pipeline's
    B-spline distance)."""
    import Part
    return np.array([shape.distToShape(Part.Vertex(FreeCAD.Vector(*p)))[0] for p in points])


def corner_error(estimated, truth, corners):
    """Largest displacement of the bounding-box corners between two 4x4 poses."""
    h = np.column_stack([corners, np.ones(len(corners))])
    return float(np.max(np.linalg.norm((h @ estimated.T - h @ truth.T)[:, :3], axis=1)))


def run():
    start_workbench(640)   # wide enough for Table 2's columns in the screenshots
    window = Gui.getMainWindow()
    from BladeInspect.app import objects
    from BladeInspect.gui import commands, loop_commands, progress, taskpanels
    cmd = loop_commands.BY_NAME
    names = set(c for c in Gui.listCommands() if c.startswith("BladeInspect_"))
    check("loop commands registered", set(loop_commands.NAMES) <= names, sorted(names))
    toolbars = {t.windowTitle(): [a.text() for a in t.actions()]
                for t in window.findChildren(QtGui.QToolBar)}
    check("loop toolbar holds the four commands",
          [c.menu for c in loop_commands.COMMANDS] == toolbars.get("BladeInspect loop"),
          toolbars.get("BladeInspect loop"))
    icons = [Gui.getCommandInfo(n)["pixmap"] for n in loop_commands.NAMES] \
        if hasattr(Gui, "getCommandInfo") else \
        [c.GetResources()["Pixmap"] for c in loop_commands.COMMANDS]
    check("every loop command has its own SVG icon",
          all(os.path.isfile(p) and p.endswith(n + ".svg")
              for p, n in zip(icons, loop_commands.NAMES)), icons)
    doc = FreeCAD.newDocument("Loop")
    check("inspect greyed out without a nominal", not cmd["BladeInspect_Inspect"].IsActive())
    check("add CMM greyed out without a registration", not cmd["BladeInspect_AddCmm"].IsActive())
    check("simulate and calibrate need no input",
          cmd["BladeInspect_Simulate"].IsActive() and cmd["BladeInspect_Calibrate"].IsActive())
    state = {}

    @step("simulation test bed on the demo blade")
    def _():
        Gui.runCommand("BladeInspect_Simulate")
        settle(0.3)
        panel = active_panel(loop_commands.SimulatePanel)
        check("simulate task panel open", panel is not None)
        window_shot("loop_task_panel_simulate")
        panel.points.setValue(3000)
        panel.seed.setValue(5)
        click_ok_and_wait()
        settle()
        blade = objects.find_objects(doc, objects.DemoBlade.Type)
        check("simulate built the demo blade (none in the document)", len(blade) == 1)
        state["blade"] = blade[0]
        reg = doc.getObject("SimulatedRegistration")
        meas = doc.getObject("SimulatedScan")
        dmap = objects.find_objects(doc, objects.DeviationMap.Type)
        check("simulation objects made", reg is not None and meas is not None and len(dmap) == 1,
              [o.Name for o in doc.Objects])
        check("pose error within 3x its bound", 0 < reg.PoseErrorOverBound < 3.0,
              reg.PoseErrorOverBound)
        check("pose error vs bound shown", loop_commands.RESULTS and
              "x its bound" in loop_commands.RESULTS[-1][1], loop_commands.RESULTS[-1:])
        # The measured points moved by the found pose lie on the blade by OCC's distance:
        # within the injected error (uniform +-6 um) plus what the pose error adds.
        xyz = np.asarray(meas.Coordinates).reshape(-1, 3)[::60][:50]
        pose = objects.matrix_array(reg.MeasuredToCad)
        on_cad = xyz @ pose[:3, :3].T + pose[:3, 3]
        d = occ_distances(blade[0].Shape, on_cad)
        check("simulated points land on the blade (OCC distance)", np.max(d) < 0.01,
              "max %.5f mm" % np.max(d))
        check("deviation map has a colour per point",
              len(dmap[0].Color) == dmap[0].NPoints == len(meas.Coordinates) // 3)
        for obj in (reg, meas) + tuple(dmap):
            if obj.ViewObject is not None:
                obj.ViewObject.Visibility = False
        Gui.Control.closeDialog()

    @step("inspect rejects bad heights with a message and adds nothing")
    def _():
        before = [o.Name for o in doc.Objects]
        value = cmd["BladeInspect_Inspect"].start("10, 130", 0.04, 0)
        check("bad height reported", value is None and "outside 0-100" in
              progress.MESSAGES[-1][1], progress.MESSAGES[-1:])
        check("bad height adds nothing", [o.Name for o in doc.Objects] == before)

    @step("inspect's simulated rig has the preferences' sensor, as Connect rig's")
    def _():
        from BladeInspect.app import settings
        from BladeInspect.gui.session import RIG
        RIG.disconnect()
        saved = settings.value("StandoffMm")
        settings.store("StandoffMm", 41.5)
        try:
            with loop_commands.inspection_rig(state["blade"], 0) as rig:
                standoff = rig.sensor.standoff
            connected = commands.BY_NAME["BladeInspect_ConnectRig"].connect("sim", 0)
            connected_standoff = connected.sensor.standoff if connected is not None else None
        finally:
            settings.store("StandoffMm", saved)
            RIG.disconnect()
        check("inspect's simulated rig reads the standoff preference", standoff == 41.5, standoff)
        check("connect rig reads the same", connected_standoff == 41.5, connected_standoff)

    @step("inspect cancelled leaves the document as it was")
    def _():
        before = [o.Name for o in doc.Objects]

        def click_cancel():
            buttons = Gui.getMainWindow().statusBar().findChildren(QtGui.QPushButton)
            [b for b in buttons if b.text() == "Cancel"][-1].click()
        QtCore.QTimer.singleShot(0, click_cancel)
        value = cmd["BladeInspect_Inspect"].inspect(state["blade"], HEIGHTS, 0.04, 0)
        check("inspect cancelled", value is None and
              progress.MESSAGES[-1] == ("Inspect", "cancelled"), progress.MESSAGES[-1:])
        check("cancelled inspect adds nothing", [o.Name for o in doc.Objects] == before,
              [o.Name for o in doc.Objects])

    @step("inspect the demo blade: planned paths drawn first, then the loop")
    def _():
        blade = state["blade"]
        Gui.Selection.clearSelection()
        check("inspect active with a nominal", cmd["BladeInspect_Inspect"].IsActive())
        Gui.runCommand("BladeInspect_Inspect")
        settle(0.3)
        panel = active_panel(loop_commands.InspectPanel)
        check("inspect task panel open", panel is not None)
        panel.heights.setText(", ".join("%g" % h for h in HEIGHTS))
        panel.seed.setValue(2)
        window_shot("loop_task_panel_inspect")
        seen = []

        def on_plan(plan, obj):
            # Before any planned path runs: only the blade and the drawn paths are new.
            seen.append({"names": [o.Name for o in doc.Objects],
                         "vertices": np.array([(v.X, v.Y, v.Z) for v in obj.Shape.Vertexes]),
                         "n_points": plan.n_points, "heights": list(obj.HeightsPct)})
            if len(seen) == 1:
                for o in doc.Objects:
                    if o.ViewObject is not None:
                        o.ViewObject.Visibility = o.Name in (blade.Name, obj.Name)
                blade.ViewObject.Transparency = 60
                view_shot("loop_planned_paths")
                window_shot("loop_planned_paths_window")
                blade.ViewObject.Transparency = 0
        loop_commands.PLAN_LISTENERS.append(on_plan)
        # CPU seconds, not wall: the loop runs in this process, and a suite sharing two cores
        # with another once made an unchanged 70 s run take 119 s of wall time.
        t0, cpu0 = time.time(), time.process_time()
        try:
            click_ok_and_wait()
        finally:
            loop_commands.PLAN_LISTENERS.remove(on_plan)
        state["inspect_cpu_s"] = time.process_time() - cpu0
        state["inspect_wall_s"] = time.time() - t0
        settle()
        check("plan drawn before the planned scan", len(seen) >= 1 and
              "Inspection" not in seen[0]["names"], [s["names"] for s in seen])
        reg = doc.getObject("Inspection")
        check("inspection registration made", reg is not None, progress.MESSAGES[-1:])
        first = seen[0]
        check("drawn plan has the requested heights", first["heights"] == list(HEIGHTS),
              first["heights"])
        # Section planes from the blade's own extent along its span (Z for the demo blade).
        bb = blade.Shape.BoundBox
        planes = bb.ZMin + np.array(HEIGHTS) / 100.0 * bb.ZLength
        verts = first["vertices"]
        off_plane = np.min(np.abs(verts[:, 2:3] - planes[None, :]), axis=1)
        check("every drawn vertex lies on a nominal section plane", np.max(off_plane) < 0.01,
              "max %.5f mm over %d vertices" % (np.max(off_plane), len(verts)))
        near = np.abs(verts[:, 2:3] - planes[None, :]) < 0.01
        check("every section plane has drawn paths", near.any(axis=0).all(), near.sum(axis=0))
        sample = verts[np.random.default_rng(0).choice(len(verts), 40, replace=False)]
        d = occ_distances(blade.Shape, sample)
        check("drawn vertices lie on the blade (OCC distance)", np.max(d) < 0.01,
              "max %.5f mm" % np.max(d))
        check("drawn vertices cover the plan", len(verts) <= first["n_points"] and
              len(verts) > 0.9 * first["n_points"], (len(verts), first["n_points"]))
        if reg is None:
            return
        state["reg"] = reg
        meas = reg.Measurement
        dmap = [o for o in objects.find_objects(doc, objects.DeviationMap.Type)
                if o.Registration == reg]
        check("inspection objects: points, deviation map, profiles, plan",
              meas is not None and len(dmap) == 1 and doc.getObject("PlannedPaths") is not None
              and any(o.Name.startswith("SectionProfiles") for o in doc.Objects),
              [o.Name for o in doc.Objects])
        n = len(reg.Deviation)
        check("measurement rows match the registration", meas.NPoints == n, (meas.NPoints, n))
        check("planned rows start after the blind ones", 0 < reg.FirstPlannedRow < n,
              reg.FirstPlannedRow)
        # Pose against the simulator's truth (scan.json of the run), its bound from the object.
        record = json.load(open(os.path.join(reg.InspectionFolder, "scan.json")))
        truth = np.asarray(record["table_to_cad"], dtype=float)
        corners = np.array([[x, y, z] for x in (bb.XMin, bb.XMax) for y in (bb.YMin, bb.YMax)
                            for z in (bb.ZMin, bb.ZMax)])
        err = corner_error(objects.matrix_array(reg.MeasuredToCad), truth, corners)
        check("inspection pose within 3x its bound of the simulator's truth",
              err < 3 * reg.PoseUncertaintyMm,
              "error %.2f um, bound %.2f um" % (1e3 * err, 1e3 * reg.PoseUncertaintyMm))
        # Planned points measured in the table frame, moved by the pose, lie on the blade.
        xyz = np.asarray(meas.Coordinates).reshape(-1, 3)[reg.FirstPlannedRow:][::97][:40]
        pose = objects.matrix_array(reg.MeasuredToCad)
        d = occ_distances(blade.Shape, xyz @ pose[:3, :3].T + pose[:3, 3])
        check("planned readings land on the blade (OCC distance)", np.max(d) < 0.02,
              "max %.5f mm" % np.max(d))
        panel = active_panel(taskpanels.TablePanel)
        check("Table 2 shown with one row per section",
              panel is not None and panel.table.rowCount() == len(HEIGHTS),
              panel and panel.table.rowCount())
        # The airfoil characteristics are the inspect command's default: result.json holds a
        # block per section, the document an Airfoil group with the same blocks, and Table 2's
        # panel opens them.
        from BladeInspect.app import airfoil_objects
        with open(os.path.join(reg.InspectionFolder, "result.json")) as fh:
            written = json.load(fh)
        group = airfoil_objects.find_analysis(doc)
        check("inspect adds the airfoil characteristics, as the command does",
              len(written.get("airfoil", [])) == len(HEIGHTS) and group is not None
              and airfoil_objects.analysis_of(group)["airfoil"] == written["airfoil"],
              [b.get("label") for b in written.get("airfoil", [])])
        check("the note names the ICP weights result.json records",
              panel is not None and "ICP weights: %s," % written["weights"]["model"]
              in panel.form.findChildren(QtGui.QLabel)[0].text(), written.get("weights"))
        check("the note shows result.json's warnings (the planning notes among them)",
              panel is not None and all(w in panel.form.findChildren(QtGui.QLabel)[0].text()
                                        for w in written["warnings"]), written["warnings"])
        for o in doc.Objects:
            if o.ViewObject is not None:
                o.ViewObject.Visibility = o == dmap[0]
        window_shot("loop_inspection_table")
        check("Table 2 and the fit-sensitivity table do not scroll sideways at 640 px",
              panel is not None and all(t.horizontalScrollBar().maximum() == 0
                                        for t in panel.form.findChildren(QtGui.QTableWidget)),
              panel and [(t.width(), t.horizontalScrollBar().maximum())
                         for t in panel.form.findChildren(QtGui.QTableWidget)])
        view_shot("loop_inspection_map")
        button = getattr(panel, "airfoil_button", None)
        if button is not None:
            button.click()   # replaces the panel: the button is gone after this
            settle(0.3)
        airfoil_panel = active_panel(taskpanels.AirfoilPanel)
        check("Table 2's button opens the airfoil characteristics",
              airfoil_panel is not None and airfoil_panel.table.rowCount() > 0,
              "button" if button is not None else "no button")
        window_shot("loop_inspection_airfoil")
        check("the airfoil characteristics do not scroll sideways at 640 px",
              airfoil_panel is not None
              and airfoil_panel.table.horizontalScrollBar().maximum() == 0,
              airfoil_panel and airfoil_panel.table.horizontalScrollBar().maximum())
        Gui.Control.closeDialog()

    @step("inspect cancelled once its paths are drawn leaves the document as it was")
    def _():
        before = [o.Name for o in doc.Objects]
        plan_obj = doc.getObject("PlannedPaths")

        def vertices(shape):
            return np.array([(v.X, v.Y, v.Z) for v in shape.Vertexes])
        plan_vertices = vertices(plan_obj.Shape) if plan_obj is not None else None
        drawn = []

        def cancel_at_plan(plan, obj):
            drawn.append(obj.Name)
            buttons = Gui.getMainWindow().statusBar().findChildren(QtGui.QPushButton)
            [b for b in buttons if b.text() == "Cancel"][-1].click()
        loop_commands.PLAN_LISTENERS.append(cancel_at_plan)
        try:
            value = cmd["BladeInspect_Inspect"].inspect(state["blade"], (40.0,), 0.04, 3)
        finally:
            loop_commands.PLAN_LISTENERS.remove(cancel_at_plan)
        check("second inspect drew its own paths, then was cancelled",
              value is None and drawn and drawn[0] != "PlannedPaths" and
              ("Inspect", "cancelled") in progress.MESSAGES[-2:], (drawn, progress.MESSAGES[-2:]))
        check("cancelled inspect removes its drawn paths",
              [o.Name for o in doc.Objects] == before, [o.Name for o in doc.Objects])
        check("the first inspection's paths are untouched", plan_vertices is not None and
              np.array_equal(vertices(plan_obj.Shape), plan_vertices))

    @step("inspect with the connected rig")
    def _():
        from BladeInspect.gui.session import RIG
        from BladeInspect.measurement.scan import open_rig
        blade = state["blade"]
        RIG.connect(open_rig("sim", objects.nominal_of(blade), seed=4), "sim")
        try:
            summary = cmd["BladeInspect_Inspect"].inspect(blade, (35.0, 65.0), 0.04, 4)
            check("inspect ran on the connected rig", summary is not None,
                  progress.MESSAGES[-1:])
            check("the connected rig was used, and left open for the next command",
                  summary is not None and RIG.connected and RIG.rig.elapsed_s > 0)
            if summary is None:
                return
            reg = summary["objects"]["registration"]
            record = json.load(open(os.path.join(reg.InspectionFolder, "scan.json")))
            bb = blade.Shape.BoundBox
            corners = np.array([[x, y, z] for x in (bb.XMin, bb.XMax)
                                for y in (bb.YMin, bb.YMax) for z in (bb.ZMin, bb.ZMax)])
            err = corner_error(objects.matrix_array(reg.MeasuredToCad),
                               np.asarray(record["table_to_cad"], dtype=float), corners)
            check("connected-rig pose within 3x its bound of the simulator's truth",
                  err < 3 * reg.PoseUncertaintyMm,
                  "error %.2f um, bound %.2f um" % (1e3 * err, 1e3 * reg.PoseUncertaintyMm))
            check("two planned sections in Table 2", len(summary["sections"].sections) == 2)
        finally:
            RIG.disconnect()
            Gui.Control.closeDialog()

    @step("add a CMM file to the inspection")
    def _():
        reg = state.get("reg")
        if reg is None:
            check("add CMM: needs the inspection", False)
            return
        check("add CMM active with a registration", cmd["BladeInspect_AddCmm"].IsActive())
        blade = state["blade"]
        bb = blade.Shape.BoundBox
        # Points cut from the blade at each inspected plane, moved 20 um across the profile
        # within the plane; what each should read is OpenCASCADE's distance to the blade.
        rows, per_plane, expected = [], [], []
        for h in HEIGHTS:
            z = bb.ZMin + h / 100.0 * bb.ZLength
            pts = np.array([(p.x, p.y, p.z) for wire in blade.Shape.slice(
                FreeCAD.Vector(0, 0, 1), z) for p in wire.discretize(Distance=1.0)])
            tangent = np.gradient(pts, axis=0)
            across = np.column_stack([tangent[:, 1], -tangent[:, 0], np.zeros(len(pts))])
            moved = pts + 0.02 * across / np.linalg.norm(across, axis=1)[:, None]
            d = occ_distances(blade.Shape, moved)
            per_plane.append(len(moved))
            expected.append((np.max(d), np.sqrt(np.mean(d ** 2))))
            rows += ["%.6f,%.6f,%.6f" % tuple(p) for p in moved]
        path = os.path.join(OUT, "cmm.csv")
        with open(path, "w") as fh:
            fh.write("x,y,z\n" + "\n".join(rows) + "\n")
        commands.ask_open_file = lambda *a: path
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(reg)
        Gui.runCommand("BladeInspect_AddCmm")
        settle()
        panel = active_panel(taskpanels.TablePanel)
        header = [panel.table.horizontalHeaderItem(c).text()
                  for c in range(panel.table.columnCount())] if panel else []
        check("CMM columns shown beside the optical ones", "CMM RMS" in header, header)
        if "CMM RMS" not in header:
            return
        col = {name: header.index(name) for name in header}
        counts = [int(panel.table.item(r, col["CMM points"]).text())
                  for r in range(panel.table.rowCount())]
        check("each CMM point assigned to its own section", counts == per_plane,
              (counts, per_plane))
        shown = [(float(panel.table.item(r, col["CMM max"]).text()),
                  float(panel.table.item(r, col["CMM RMS"]).text()))
                 for r in range(panel.table.rowCount())]
        check("CMM max |dev| and RMS per section agree with OCC's distances within 1 um",
              np.allclose(shown, expected, atol=0.001), (shown, expected))
        check("CMM file recorded on the inspection", reg.CmmFile == path, reg.CmmFile)
        window_shot("loop_cmm_table")
        Gui.Control.closeDialog()

    @step("calibrate the simulated rig")
    def _():
        rig_json = os.path.join(OUT, "RIG.json")
        loop_commands.ask_save_file = lambda *a: rig_json
        Gui.runCommand("BladeInspect_Calibrate")
        settle(0.3)
        panel = active_panel(loop_commands.CalibratePanel)
        check("calibrate task panel open", panel is not None)
        panel.offset.setValue(0.2)
        panel.tilt.setValue(0.1)
        panel_seed, panel_diameter = panel.seed.value(), panel.diameter.value()
        window_shot("loop_task_panel_calibrate")
        click_ok_and_wait()
        settle()
        check("RIG.json written", os.path.isfile(rig_json))
        check("calibration result shown", loop_commands.RESULTS and
              "Rotary axis through" in loop_commands.RESULTS[-1][1],
              loop_commands.RESULTS[-1:])
        written = json.load(open(rig_json))
        check("the inspect panel offers the new RIG.json",
              loop_commands.LAST_RIG_FILE[0] == rig_json, written)
        # The simulator's true axis for the panel's seed and injected errors.
        from BladeInspect.measurement.calibration import simulated_calibration_rig
        rig, truth = simulated_calibration_rig(panel_diameter, seed=panel_seed,
                                               axis_offset_mm=0.2, axis_tilt_deg=0.1)
        rig.close()
        p, d = np.array(written["axis_point"]), np.array(written["axis_direction"])
        off = (p - truth.axis_point) - np.dot(p - truth.axis_point,
                                              truth.axis_direction) * truth.axis_direction
        angle = np.degrees(np.arccos(min(1.0, abs(float(np.dot(d, truth.axis_direction))))))
        check("RIG.json axis within 2 um and 0.001 deg of the simulator's",
              np.linalg.norm(off) < 0.002 and angle < 0.001,
              "%.3f um, %.5f deg" % (1e3 * np.linalg.norm(off), angle))

    check("inspect took under 90 CPU-s in the GUI", state.get("inspect_cpu_s", 1e9) < 90,
          "%.1f CPU-s (%.1f s wall)" % (state.get("inspect_cpu_s", -1),
                                        state.get("inspect_wall_s", -1)))


run_scenario(run)
