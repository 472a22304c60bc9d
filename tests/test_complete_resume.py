"""`inspect --complete` over the serial driver, interrupted inside the raster and resumed: the
demo blade on the simulated rig served on a pty, a hard-limit alarm after three of the raster's
passes, then a resume on a fresh device. The folder keeps the blind rows and the three finished
passes (no result); the resumed run ends with exactly the files of one uninterrupted run in
process: the same points.csv rows and the same pose. A coarse 2 mm pitch keeps it fast."""
import json
import os
import shutil
import tempfile
import unittest

import numpy as np

from BladeInspect.core.errors import DeviceError
from BladeInspect.core.pointio import read_points
from BladeInspect.inspection.run_options import RunOptions
from tests.helpers import demo_nominal, first_difference, read_json, read_lines
from tests.test_inspect_resume import HEIGHTS, RESULT_FILES, SCAN_OPTIONS, SEED, simulated_rig

PITCH = 2.0
PASSES_BEFORE_FAULT = 3


def inspect_complete(nominal, out, rig, progress=None, resume=False):
    from BladeInspect.inspection.closed_loop import run_inspect
    return run_inspect(None, out,
                       RunOptions.of(seed=SEED, complete=True, pitch=PITCH,
                                     section_heights=HEIGHTS, scan_options=dict(SCAN_OPTIONS),
                                     resume=resume), rig=rig, nominal=nominal, document=False,
                       progress=progress)


class TestCompleteResume(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        from BladeInspect.rig.serial_rig import SerialRig
        from BladeInspect.rig.simrig_device import Fault, SimRigDevice
        cls.nominal = demo_nominal()
        cls.tmp = tempfile.mkdtemp(prefix="bi-complete-resume-")
        reference_out = os.path.join(cls.tmp, "reference")
        rig = simulated_rig(cls.nominal)
        pass_start = []

        def progress(fraction, message):
            if message.startswith("complete scan: pass"):
                pass_start.append(rig.pass_index)
        cls.reference = inspect_complete(cls.nominal, reference_out, rig, progress)
        cls.pass_start = pass_start
        cls.reference_lines = read_lines(os.path.join(reference_out, "points.csv"))
        cls.reference_points = read_points(os.path.join(reference_out, "points.csv"))
        cls.reference_result = read_json(os.path.join(reference_out, "result.json"))
        cls.reference_scan = read_json(os.path.join(reference_out, "scan.json"))

        cls.out = os.path.join(cls.tmp, "serial")
        fault = Fault("alarm", after_passes=pass_start[PASSES_BEFORE_FAULT])
        cls.error = None
        with SimRigDevice(simulated_rig(cls.nominal), fault=fault) as device:
            serial = SerialRig(device.port_url, timeout_s=5)
            try:
                inspect_complete(cls.nominal, cls.out, serial)
            except DeviceError as exc:
                cls.error = str(exc)
            finally:
                serial.close()
        cls.kept = sorted(os.listdir(cls.out))
        cls.checkpoint = read_json(os.path.join(cls.out, "scan.json"))
        cls.kept_points = read_points(os.path.join(cls.out, "points.csv"))
        with SimRigDevice(simulated_rig(cls.nominal)) as device:
            serial = SerialRig(device.port_url, timeout_s=5)
            try:
                cls.summary = inspect_complete(cls.nominal, cls.out, serial, resume=True)
            finally:
                serial.close()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_the_raster_has_passes_to_interrupt(self):
        self.assertGreater(len(self.reference["plan"].passes), PASSES_BEFORE_FAULT)

    def test_alarm_keeps_the_finished_passes(self):
        self.assertRegex(self.error, r"^serial:\S+: hard limit: controller raised ALARM:1")
        self.assertEqual(self.kept, ["plan.json", "points.csv", "scan.json"])
        for name in RESULT_FILES:
            self.assertNotIn(name, self.kept)
        self.assertFalse(self.checkpoint["complete"])
        state = self.checkpoint["inspection"]
        self.assertEqual((state["phase"], state["passes_done"]), ("complete", PASSES_BEFORE_FAULT))
        self.assertEqual(state["pass_index"], self.pass_start[PASSES_BEFORE_FAULT])
        # The blind rows and those of the first passes, as the reference measured them.
        ref = self.reference_points
        n_kept = len(self.kept_points.xyz)
        self.assertEqual(n_kept, int(np.count_nonzero(ref.columns["phase"] == "blind"))
                         + sum(p["readings"] for p in state["passes"]))
        np.testing.assert_allclose(self.kept_points.xyz, ref.xyz[:n_kept], rtol=0, atol=6e-7)
        np.testing.assert_array_equal(self.kept_points.columns["phase"],
                                      ref.columns["phase"][:n_kept])

    def test_resumed_run_equals_the_uninterrupted_one(self):
        self.assertIsNone(first_difference(read_lines(os.path.join(self.out, "points.csv")),
                                           self.reference_lines))
        result = read_json(os.path.join(self.out, "result.json"))
        np.testing.assert_allclose(result["measured_to_cad"],
                                   self.reference_result["measured_to_cad"], rtol=0, atol=1e-9)
        record = read_json(os.path.join(self.out, "scan.json"))
        self.assertTrue(record["complete"])
        self.assertNotIn("inspection", record)
        passes = record["phases"]["complete"]["passes"]
        self.assertEqual([(p["readings"], p["pass_index"]) for p in passes],
                         [(p["readings"], p["pass_index"])
                          for p in self.reference_scan["phases"]["complete"]["passes"]])
        with open(os.path.join(self.out, "plan.json")) as fh:
            self.assertEqual(json.load(fh), json.loads(self.reference["plan"].to_json()))


if __name__ == "__main__":
    unittest.main()
