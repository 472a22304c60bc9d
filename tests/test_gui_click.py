"""Register, Airfoil analysis and Inspect clicked through in a real FreeCAD GUI under Xvfb:
tests/gui_click_macro.py clicks each input panel's OK and checks the result panel opens with no
traceback in the Report view; asserted here. Screenshots are copied to
/tmp/bladeinspect-screens."""
import shutil
import unittest

from tests.helpers import GuiMacroChecks


@unittest.skipUnless(shutil.which("xvfb-run") and shutil.which("freecad"),
                     "xvfb-run or freecad missing: the GUI cannot be started headless")
class TestClickedResultPanels(GuiMacroChecks, unittest.TestCase):
    MACRO = "gui_click_macro.py"
    TIMEOUT_S = 900   # a bound for a hung GUI on a loaded machine, not a speed requirement
    MIN_CHECKS = 13
    LOG_NAME = "freecad-click.log"
    CHECKS_NAME = "checks-click.json"

    def test_every_step_ran(self):
        self.assertIsNotNone(self.report)
        for name, info in self.report["steps"].items():
            self.assertEqual(info["status"], "ran", (name, info))
        self.assertEqual(len(self.report["steps"]), 3)


if __name__ == "__main__":
    unittest.main()
