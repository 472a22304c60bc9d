"""Run by bench/bench_gui_demo.py inside the real FreeCAD GUI: the demo from the toolbar's
functions (demo blade, then Inspect with the default sections) timed, written to
$BI_GUI_OUT/gui_demo.json. With $BI_DEMO_SHOTS set, after the timing it also opens what a
user looks at next (the Inspect panel, the inspection's tables, the registration, the
deviation map, the report) and saves a screenshot of each into $BI_GUI_OUT. Not a test
module."""
import json
import os
import sys
import time
import traceback

import FreeCAD
import FreeCADGui as Gui

OUT = os.environ["BI_GUI_OUT"]
HEIGHTS = [10.0, 30.0, 50.0, 70.0, 90.0]
result = {}


def screenshots(summary, blade):
    """The demo's panels and views as a user sees them, for people to look at."""
    sys.path.insert(0, os.environ["BI_REPO"])
    from tests.gui_harness import settle, start_workbench, view_shot, window_shot
    from BladeInspect.gui import commands, loop_commands
    start_workbench(640)
    shots = []
    Gui.runCommand("BladeInspect_Inspect")
    settle(0.3)
    shots.append(window_shot("demo_inspect_panel"))
    Gui.Control.closeDialog()
    panel = loop_commands.Inspect.show(summary)
    shots.append(window_shot("demo_inspection_tables"))
    button = getattr(panel, "airfoil_button", None)
    result["airfoil_button"] = button is not None
    if button is not None:
        button.click()
        shots.append(window_shot("demo_airfoil"))
    Gui.Control.closeDialog()
    registration = summary["objects"]["registration"]
    commands.Register.show(registration)
    shots.append(window_shot("demo_registration"))
    Gui.Control.closeDialog()
    blade.ViewObject.Transparency = 60
    shots.append(view_shot("demo_deviation_map"))
    report = commands.BY_NAME["BladeInspect_Report"].report(registration,
                                                           os.path.join(OUT, "report"))
    result["report_files"] = None if report is None else report["files"]
    result["shots"] = [os.path.basename(p) for p in shots]


try:
    Gui.activateWorkbench("BladeInspectWorkbench")
    from BladeInspect.app import objects
    from BladeInspect.gui import loop_commands
    t0 = time.time()
    doc = FreeCAD.newDocument("GuiDemo")
    blade = objects.make_demo_blade(doc)
    doc.recompute()
    summary = loop_commands.Inspect().inspect(blade, HEIGHTS, 0.04, 0)
    result["gui_demo_s"] = time.time() - t0
    result["ok"] = summary is not None
    if summary is not None:
        result["rms_mm"] = summary["result"].rms_mm
        if os.environ.get("BI_DEMO_SHOTS"):
            screenshots(summary, blade)
except Exception:
    result["error"] = traceback.format_exc()
with open(os.path.join(OUT, "gui_demo.json"), "w") as fh:
    json.dump(result, fh)
os._exit(0)
