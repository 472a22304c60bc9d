"""Run by bench/bench_gui_demo.py inside the real FreeCAD GUI: the demo from the toolbar's
functions (demo blade, then Inspect with the default sections) timed, written to
$BI_BENCH_OUT/gui_demo.json. Not a test module."""
import json
import os
import time
import traceback

import FreeCAD
import FreeCADGui as Gui

OUT = os.environ["BI_BENCH_OUT"]
result = {}
try:
    Gui.activateWorkbench("BladeInspectWorkbench")
    from BladeInspect.app import objects
    from BladeInspect.gui import loop_commands
    t0 = time.time()
    doc = FreeCAD.newDocument("GuiDemo")
    blade = objects.make_demo_blade(doc)
    doc.recompute()
    summary = loop_commands.Inspect().inspect(blade, [10.0, 30.0, 50.0, 70.0, 90.0], 0.04, 0)
    result["gui_demo_s"] = time.time() - t0
    result["ok"] = summary is not None
    if summary is not None:
        result["rms_mm"] = summary["result"].rms_mm
except Exception:
    result["error"] = traceback.format_exc()
with open(os.path.join(OUT, "gui_demo.json"), "w") as fh:
    json.dump(result, fh)
os._exit(0)
