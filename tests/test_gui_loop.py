"""The closed-loop commands in a real FreeCAD GUI under Xvfb: tests/gui_loop_macro.py runs the
simulation test bed, Inspect (planned paths drawn before they run), Add CMM file and Calibrate
on the demo blade with the simulated rig and writes its checks as JSON, asserted here.
Screenshots are copied to /tmp/bladeinspect-screens for people to look at."""
import os
import shutil
import unittest

from tests.helpers import GuiMacroChecks


@unittest.skipUnless(shutil.which("xvfb-run") and shutil.which("freecad"),
                     "xvfb-run or freecad missing: the GUI cannot be started headless")
class TestLoopCommandsGui(GuiMacroChecks, unittest.TestCase):
    MACRO = "gui_loop_macro.py"
    TIMEOUT_S = 240   # about a minute on two busy cores
    MIN_CHECKS = 32
    LOG_NAME = "loop.log"
    CHECKS_NAME = "loop_checks.json"

    def test_every_step_ran(self):
        self.assertIsNotNone(self.report)
        for name, info in self.report["steps"].items():
            print("  gui loop step %-70s %s" % (name, info))
            self.assertEqual(info["status"], "ran", (name, info))
        self.assertEqual(len(self.report["steps"]), 9)

    def test_screenshots_saved(self):
        for name in ("loop_planned_paths", "loop_task_panel_inspect", "loop_inspection_table",
                     "loop_inspection_map", "loop_cmm_table", "loop_task_panel_simulate"):
            path = os.path.join(self.tmp, name + ".png")
            self.assertTrue(os.path.exists(path) and os.path.getsize(path) > 5000, name)


if __name__ == "__main__":
    unittest.main()
