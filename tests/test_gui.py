"""The workbench in a real FreeCAD GUI under Xvfb: tests/gui_macro.py drives it (commands, task
panels, colours, legend, save and reopen) in a subprocess and writes its checks as JSON, which
this test asserts. Screenshots go to a temporary folder and are copied to
/tmp/bladeinspect-screens for people to look at."""
import json
import os
import shutil
import tempfile
import unittest

from tests.helpers import REPO, run_freecad_gui

SCREENS = "/tmp/bladeinspect-screens"
TIMEOUT_S = 300   # the scenario takes about 1.5 min on two busy cores


@unittest.skipUnless(shutil.which("xvfb-run") and shutil.which("freecad"),
                     "xvfb-run or freecad missing: the GUI cannot be started headless")
class TestWorkbenchGui(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="bi-gui-")
        run_freecad_gui(os.path.join(REPO, "tests", "gui_macro.py"), cls.tmp, TIMEOUT_S)
        path = os.path.join(cls.tmp, "checks.json")
        cls.report = json.load(open(path)) if os.path.exists(path) else None
        os.makedirs(SCREENS, exist_ok=True)
        shutil.copy(os.path.join(cls.tmp, "freecad.log"), SCREENS)
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
        self.assertGreater(len(self.report["checks"]), 15)

    def test_scenario_steps_ran_or_say_why_not(self):
        self.assertIsNotNone(self.report)
        steps = self.report["steps"]
        for name, info in steps.items():
            print("  gui step %-80s %s" % (name, info))
        for must in ("demo blade through its task panel",
                     "deviation map of a known result, legend, save and reopen",
                     "cancel leaves the document as it was"):
            self.assertEqual(steps[must]["status"], "ran", steps[must])

    def test_screenshots_saved(self):
        for name in ("demo_blade", "task_panel_demo_blade", "deviation_map_known",
                     "deviation_map_reopened", "task_panel_registration_known"):
            path = os.path.join(self.tmp, name + ".png")
            self.assertTrue(os.path.exists(path) and os.path.getsize(path) > 5000, name)


if __name__ == "__main__":
    unittest.main()
