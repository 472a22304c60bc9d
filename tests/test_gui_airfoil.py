"""The fit selector, the console lines and the airfoil objects in a real FreeCAD GUI under
Xvfb: tests/gui_airfoil_macro.py drives it and writes its checks, asserted here. Screenshots
are copied to /tmp/bladeinspect-screens."""
import shutil
import unittest

from tests.helpers import GuiMacroChecks


@unittest.skipUnless(shutil.which("xvfb-run") and shutil.which("freecad"),
                     "xvfb-run or freecad missing: the GUI cannot be started headless")
class TestAirfoilGui(GuiMacroChecks, unittest.TestCase):
    MACRO = "gui_airfoil_macro.py"
    TIMEOUT_S = 400
    MIN_CHECKS = 16
    LOG_NAME = "freecad-airfoil.log"

    def test_every_step_ran(self):
        self.assertIsNotNone(self.report)
        for name, info in self.report["steps"].items():
            self.assertEqual(info["status"], "ran", (name, info))
        self.assertEqual(len(self.report["steps"]), 4)


if __name__ == "__main__":
    unittest.main()
