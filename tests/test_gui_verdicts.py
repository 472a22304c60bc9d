"""One inspection, one verdict, shown first (issue 36, findings 2, 3 and 6): Inspect clicked
through in a real FreeCAD GUI under Xvfb at FreeCAD's default Combo View width, then Section
analysis, Report, the registration's panel and Airfoil analysis on the same inspection
(tests/gui_verdicts_macro.py): the same sections, named by the planned heights, the same
verdict, on top and large; U and TUR per section; a withheld airfoil value not judged.
Screenshots are copied to /tmp/bladeinspect-screens."""
import shutil
import unittest

from tests.helpers import GuiMacroChecks


@unittest.skipUnless(shutil.which("xvfb-run") and shutil.which("freecad"),
                     "xvfb-run or freecad missing: the GUI cannot be started headless")
class TestOneVerdictFirst(GuiMacroChecks, unittest.TestCase):
    MACRO = "gui_verdicts_macro.py"
    TIMEOUT_S = 900   # a bound for a hung GUI on a loaded machine, not a speed requirement
    MIN_CHECKS = 30
    LOG_NAME = "freecad-verdicts.log"
    CHECKS_NAME = "checks-verdicts.json"

    def test_every_step_ran(self):
        self.assertIsNotNone(self.report)
        for name, info in self.report["steps"].items():
            self.assertEqual(info["status"], "ran", (name, info))
        self.assertEqual(len(self.report["steps"]), 6)


if __name__ == "__main__":
    unittest.main()
