"""The input panels as a user meets them, clicked through in a real FreeCAD GUI under Xvfb at
the default Combo View width (tests/gui_inputs_macro.py): Register names and uses the selected
CAD with a second one in the document, OK checks the inputs before the panel closes, nothing
clipped, the preferences grouped, the Help entry; asserted here. Also the weights' reason for a
file that has an snr column but no beam (no FreeCAD needed). Screenshots are copied to
/tmp/bladeinspect-screens."""
import shutil
import unittest

import numpy as np

from tests.helpers import GuiMacroChecks


class NoBeamReason(unittest.TestCase):
    """The default weights' reason names what the readings lack, not what they have."""

    def reason(self, snr, columns):
        from BladeInspect.core.pointio import PointSet
        from BladeInspect.inspection.weighting import weight_model_for
        xyz = np.zeros((4, 3))
        _, record = weight_model_for(PointSet(xyz=xyz, snr=snr, columns=columns))
        return record["chosen_by"]

    def test_an_snr_column_is_not_called_missing(self):
        why = self.reason(np.ones(4), {})
        self.assertIn("no angle_deg column", why)
        self.assertNotIn("no snr", why)

    def test_an_angle_column_without_snr(self):
        why = self.reason(None, {"angle_deg": np.zeros(4)})
        self.assertIn("no snr column", why)
        self.assertNotIn("no angle_deg", why)

    def test_neither(self):
        self.assertIn("no snr and no angle_deg column", self.reason(None, {}))

    def test_an_angle_missing_in_a_row(self):
        why = self.reason(np.ones(4), {"angle_deg": np.array([0.0, np.nan, 0.0, 0.0])})
        self.assertIn("not finite", why)
        self.assertNotIn("no snr", why)

    def test_a_beam_known(self):
        self.assertIn("carry snr and angle_deg",
                      self.reason(np.ones(4), {"angle_deg": np.zeros(4)}))


@unittest.skipUnless(shutil.which("xvfb-run") and shutil.which("freecad"),
                     "xvfb-run or freecad missing: the GUI cannot be started headless")
class TestInputPanels(GuiMacroChecks, unittest.TestCase):
    MACRO = "gui_inputs_macro.py"
    TIMEOUT_S = 600   # a bound for a hung GUI on a loaded machine, not a speed requirement
    MIN_CHECKS = 30
    LOG_NAME = "freecad-inputs.log"
    CHECKS_NAME = "checks-inputs.json"

    def test_every_step_ran(self):
        self.assertIsNotNone(self.report)
        for name, info in self.report["steps"].items():
            self.assertEqual(info["status"], "ran", (name, info))
        self.assertEqual(len(self.report["steps"]), 8)


if __name__ == "__main__":
    unittest.main()
