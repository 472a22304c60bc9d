"""The closed-loop commands in a real FreeCAD GUI under Xvfb: tests/gui_loop_macro.py runs the
simulation test bed, Inspect (planned paths drawn before they run), Add CMM file and Calibrate
on the demo blade with the simulated rig and writes its checks as JSON, asserted here.
Screenshots are copied to /tmp/bladeinspect-screens for people to look at."""
import json
import os
import shutil
import tempfile
import unittest

from tests.helpers import REPO, run_freecad_gui

SCREENS = "/tmp/bladeinspect-screens"
TIMEOUT_S = 240   # about a minute on two busy cores


@unittest.skipUnless(shutil.which("xvfb-run") and shutil.which("freecad"),
                     "xvfb-run or freecad missing: the GUI cannot be started headless")
class TestLoopCommandsGui(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="bi-gui-loop-")
        run_freecad_gui(os.path.join(REPO, "tests", "gui_loop_macro.py"), cls.tmp, TIMEOUT_S)
        path = os.path.join(cls.tmp, "checks.json")
        cls.report = json.load(open(path)) if os.path.exists(path) else None
        os.makedirs(SCREENS, exist_ok=True)
        shutil.copy(os.path.join(cls.tmp, "freecad.log"), os.path.join(SCREENS, "loop.log"))
        if cls.report is not None:
            shutil.copy(path, os.path.join(SCREENS, "loop_checks.json"))
        for name in os.listdir(cls.tmp):
            if name.endswith(".png"):
                shutil.copy(os.path.join(cls.tmp, name), SCREENS)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_macro_ran_to_the_end(self):
        log = open(os.path.join(self.tmp, "freecad.log")).read()[-3000:]
        self.assertIsNotNone(self.report, "the GUI macro wrote no checks; log tail:\n" + log)

    def test_every_check_passed(self):
        self.assertIsNotNone(self.report)
        failed = [c for c in self.report["checks"] if not c["ok"]]
        self.assertEqual(failed, [], json.dumps(failed, indent=1))
        self.assertGreater(len(self.report["checks"]), 30)

    def test_every_step_ran(self):
        self.assertIsNotNone(self.report)
        for name, info in self.report["steps"].items():
            print("  gui loop step %-70s %s" % (name, info))
            self.assertEqual(info["status"], "ran", (name, info))
        self.assertEqual(len(self.report["steps"]), 8)

    def test_screenshots_saved(self):
        for name in ("loop_planned_paths", "loop_task_panel_inspect", "loop_inspection_table",
                     "loop_inspection_map", "loop_cmm_table", "loop_task_panel_simulate"):
            path = os.path.join(self.tmp, name + ".png")
            self.assertTrue(os.path.exists(path) and os.path.getsize(path) > 5000, name)


if __name__ == "__main__":
    unittest.main()
