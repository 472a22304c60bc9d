"""Long stages, Cancel and resume, and the out-of-tolerance points, in a real FreeCAD GUI under
Xvfb: tests/gui_responsive_macro.py clicks Inspect and Airfoil analysis while a 100 ms timer
measures how late the event loop answers, clicks the status bar's Cancel during the report,
resumes from the Inspect panel and reads the deviation map's Coin nodes; asserted here.
Screenshots are copied to /tmp/bladeinspect-screens."""
import shutil
import unittest

from tests.helpers import GuiMacroChecks


@unittest.skipUnless(shutil.which("xvfb-run") and shutil.which("freecad"),
                     "xvfb-run or freecad missing: the GUI cannot be started headless")
class TestResponsiveGui(GuiMacroChecks, unittest.TestCase):
    MACRO = "gui_responsive_macro.py"
    TIMEOUT_S = 900   # a bound for a hung GUI on a loaded machine, not a speed requirement
    MIN_CHECKS = 12
    LOG_NAME = "freecad-responsive.log"
    CHECKS_NAME = "checks-responsive.json"

    def test_every_step_ran(self):
        self.assertIsNotNone(self.report)
        for name, info in self.report["steps"].items():
            if isinstance(info, dict) and "status" in info:
                self.assertEqual(info["status"], "ran", (name, info))


if __name__ == "__main__":
    unittest.main()
